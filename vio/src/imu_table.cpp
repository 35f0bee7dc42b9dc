#include "gvins/vio/imu_table.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <optional>
#include <stdexcept>

#include <Eigen/Geometry>

#include "csv_fields.hpp"
#include "gvins/base/parse_error.hpp"

namespace gvins::vio {

namespace {
constexpr std::int64_t kGpsEpochUnixNs = 315964800LL * 1'000'000'000LL;
// The same physical limits as the EuRoC reader (euroc_csv.cpp): far beyond navigation IMUs.
constexpr double kMaxAngularRate = 200.0;     // rad/s
constexpr double kMaxSpecificForce = 2000.0;  // m/s^2

struct TableLine {
  std::string_view text;
  std::uint64_t end = 0;   // byte offset just past the line terminator (or the text end)
  std::int64_t number = 0;
  bool terminated = false;
};

std::vector<TableLine> splitLines(std::string_view text) {
  std::vector<TableLine> out;
  std::size_t pos = 0;
  std::int64_t number = 0;
  while (pos < text.size()) {
    const std::size_t nl = text.find('\n', pos);
    const bool terminated = nl != std::string_view::npos;
    const std::size_t stop = terminated ? nl : text.size();
    std::string_view l = text.substr(pos, stop - pos);
    if (!l.empty() && l.back() == '\r') l.remove_suffix(1);
    out.push_back({l, terminated ? nl + 1 : text.size(), ++number, terminated});
    pos = stop + 1;
  }
  return out;
}

struct ColumnIndex {
  int time = -1;
  int accel[3] = {-1, -1, -1};
  int gyro[3] = {-1, -1, -1};
  std::size_t needed = 0;
};

ColumnIndex indexColumns(const std::vector<ImuColumn>& cols) {
  ColumnIndex ix;
  auto set = [](int& slot, int k, const char* what) {
    if (slot >= 0) throw std::invalid_argument(std::string("IMU column '") + what + "' given twice");
    slot = k;
  };
  for (std::size_t k = 0; k < cols.size(); ++k) {
    const int i = static_cast<int>(k);
    switch (cols[k]) {
      case ImuColumn::Time: set(ix.time, i, "t"); break;
      case ImuColumn::Ax: set(ix.accel[0], i, "ax"); break;
      case ImuColumn::Ay: set(ix.accel[1], i, "ay"); break;
      case ImuColumn::Az: set(ix.accel[2], i, "az"); break;
      case ImuColumn::Gx: set(ix.gyro[0], i, "gx"); break;
      case ImuColumn::Gy: set(ix.gyro[1], i, "gy"); break;
      case ImuColumn::Gz: set(ix.gyro[2], i, "gz"); break;
      case ImuColumn::Ignore: break;
    }
  }
  const char* names[7] = {"t", "ax", "ay", "az", "gx", "gy", "gz"};
  const int slots[7] = {ix.time, ix.accel[0], ix.accel[1], ix.accel[2], ix.gyro[0], ix.gyro[1], ix.gyro[2]};
  for (int k = 0; k < 7; ++k) {
    if (slots[k] < 0) throw std::invalid_argument(std::string("IMU columns lack '") + names[k] + "'");
    ix.needed = std::max(ix.needed, static_cast<std::size_t>(slots[k]) + 1);
  }
  return ix;
}

/// Time of one line: ns for the GPST kinds, the counter in ms for CounterMs.
struct LineTime {
  std::int64_t ns = 0;
  double counter_ms = 0.0;
};

LineTime parseTime(std::string_view f, ImuTimeKind kind, const TextLocation& where) {
  LineTime t;
  switch (kind) {
    case ImuTimeKind::GpstNanoseconds: t.ns = detail::parseNanoseconds(f, where, "t"); break;
    case ImuTimeKind::GpstSeconds: t.ns = detail::parseSecondsToNanoseconds(f, where, "t"); break;
    case ImuTimeKind::GpstUnixSeconds:
      t.ns = detail::parseSecondsToNanoseconds(f, where, "t") - kGpsEpochUnixNs;
      if (t.ns < 0) throwParseError(where, "t", "GPST (Unix-style count) before 1980-01-06");
      break;
    case ImuTimeKind::CounterMs: t.counter_ms = parseFiniteDouble(f, where, "t"); break;
  }
  return t;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const std::size_t m = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(m), v.end());
  return v[m];
}

/// Places counter samples on GPST with the tags (see ImuTableReport): a least-squares line
/// through (counter, tag time), moved down to the earliest tag, since a tag only ever lags the
/// sample it covers (USB and disk buffering).
void placeCounterOnTags(std::vector<ImuSample>& samples, const std::vector<double>& counter_ms,
                        const std::vector<std::int64_t>& tag_ns, ImuTableReport& rep) {
  const std::size_t n = samples.size();
  if (n < 2) {
    for (std::size_t i = 0; i < n; ++i) samples[i].t_ns = tag_ns[i];
    return;
  }
  double mx = 0.0, my = 0.0;
  std::vector<double> x(n), y(n);
  for (std::size_t i = 0; i < n; ++i) {
    x[i] = (counter_ms[i] - counter_ms[0]) * 1e-3;
    y[i] = static_cast<double>(tag_ns[i] - tag_ns[0]) * 1e-9;
    mx += x[i];
    my += y[i];
  }
  mx /= static_cast<double>(n);
  my /= static_cast<double>(n);
  double sxx = 0.0, sxy = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    sxx += (x[i] - mx) * (x[i] - mx);
    sxy += (x[i] - mx) * (y[i] - my);
  }
  const double b = sxx > 0.0 ? sxy / sxx : 1.0;
  const double a = my - b * mx;
  std::vector<double> r(n);
  for (std::size_t i = 0; i < n; ++i) r[i] = y[i] - (a + b * x[i]);
  const double rmin = *std::min_element(r.begin(), r.end());
  std::vector<double> lag(n);
  double lagMax = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    samples[i].t_ns = tag_ns[0] + static_cast<std::int64_t>(std::llround((a + rmin + b * x[i]) * 1e9));
    lag[i] = (r[i] - rmin) * 1e3;
    lagMax = std::max(lagMax, lag[i]);
  }
  rep.counterFit = true;
  rep.counterDrift_ppm = (b - 1.0) * 1e6;
  rep.tagLatencyMedian_ms = median(lag);
  rep.tagLatencyMax_ms = lagMax;
}
}  // namespace

std::vector<ImuColumn> parseImuColumns(std::string_view spec) {
  std::vector<ImuColumn> out;
  std::size_t pos = 0;
  while (pos <= spec.size()) {
    const std::size_t comma = spec.find(',', pos);
    const std::string_view s = trim(spec.substr(pos, comma == std::string_view::npos ? spec.npos : comma - pos));
    if (s == "t") out.push_back(ImuColumn::Time);
    else if (s == "ax") out.push_back(ImuColumn::Ax);
    else if (s == "ay") out.push_back(ImuColumn::Ay);
    else if (s == "az") out.push_back(ImuColumn::Az);
    else if (s == "gx") out.push_back(ImuColumn::Gx);
    else if (s == "gy") out.push_back(ImuColumn::Gy);
    else if (s == "gz") out.push_back(ImuColumn::Gz);
    else if (s == "-") out.push_back(ImuColumn::Ignore);
    else throw std::invalid_argument("IMU column '" + std::string(s) + "' is none of t, ax, ay, az, gx, gy, gz, -");
    if (comma == std::string_view::npos) break;
    pos = comma + 1;
  }
  indexColumns(out);  // each of t, ax..gz exactly once
  return out;
}

ImuTimeKind parseImuTimeKind(std::string_view name) {
  if (name == "gpst-ns") return ImuTimeKind::GpstNanoseconds;
  if (name == "gpst-s") return ImuTimeKind::GpstSeconds;
  if (name == "gpst-unix-s") return ImuTimeKind::GpstUnixSeconds;
  if (name == "counter-ms") return ImuTimeKind::CounterMs;
  throw std::invalid_argument("IMU time '" + std::string(name) + "' is none of gpst-ns, gpst-s, gpst-unix-s, counter-ms");
}

Eigen::Matrix3d rotationFromRollPitchYaw(double rollDeg, double pitchDeg, double yawDeg) {
  const double d = M_PI / 180.0;
  return (Eigen::AngleAxisd(yawDeg * d, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(pitchDeg * d, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(rollDeg * d, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

std::vector<ImuSample> readImuTable(const std::string& path, const ImuTableFormat& format, const RtklibTimeTag* tag,
                                    ImuTableReport* report) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ParseError(path, 0, "file", "cannot open the IMU file");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return parseImuTable(text, path, format, tag, report);
}

std::vector<ImuSample> parseImuTable(std::string_view text, const std::string& name, const ImuTableFormat& format,
                                     const RtklibTimeTag* tag, ImuTableReport* report) {
  ColumnIndex ix;
  try {
    ix = indexColumns(format.columns);
  } catch (const std::invalid_argument& e) {
    throw ParseError(name, 0, "columns", e.what());
  }
  const bool counter = format.time == ImuTimeKind::CounterMs;
  if (counter && tag == nullptr) {
    throw ParseError(name, 0, "t", "a device-counter time column needs the log's time-tag file");
  }
  ImuTableReport rep;
  std::vector<TableLine> lines = splitLines(text);
  // Logs copied between systems lose their CR: the tags then count one byte per line more than
  // the file has (each line end was "\r\n" when the logger wrote it). Told apart by which line
  // ends the tagged offsets fall on more often (a logger writes whole lines more often than not).
  if (counter && text.find('\r') == std::string_view::npos) {
    std::vector<std::uint64_t> lf, crlf;
    std::uint64_t crs = 0;
    for (const TableLine& l : lines) {
      if (!l.terminated) continue;
      lf.push_back(l.end);
      crlf.push_back(l.end + ++crs);
    }
    std::size_t onLf = 0, onCrLf = 0;
    for (const TimeTagRecord& r : tag->records()) {
      onLf += std::binary_search(lf.begin(), lf.end(), r.offset) ? 1 : 0;
      onCrLf += std::binary_search(crlf.begin(), crlf.end(), r.offset) ? 1 : 0;
    }
    if (onCrLf > onLf) {
      rep.tagOffsetsCountCrLf = true;
      crs = 0;
      for (TableLine& l : lines) {
        if (l.terminated) ++crs;
        l.end += crs;
      }
    }
  }
  std::vector<ImuSample> samples;
  std::vector<double> counterMs;
  std::vector<std::int64_t> tagNs;
  std::vector<std::string_view> fields;
  std::size_t firstData = lines.size(), lastData = 0;
  for (std::size_t k = 0; k < lines.size(); ++k) {
    if (detail::isCommentOrBlank(lines[k].text)) continue;
    firstData = std::min(firstData, k);
    lastData = k;
  }
  for (std::size_t k = firstData; k < lines.size(); ++k) {
    const TableLine& l = lines[k];
    if (detail::isCommentOrBlank(l.text)) continue;
    ++rep.lines;
    const TextLocation where{name, l.number};
    detail::splitFields(l.text, l.text.find(',') == std::string_view::npos, fields);
    if (fields.size() < ix.needed) {
      // A log started or stopped mid-line keeps a cut-off first or last line.
      if (k == firstData || (k == lastData && (!l.terminated || k + 1 == lines.size()))) {
        ++rep.truncatedSkipped;
        continue;
      }
      throwParseError(where, "line", "expected at least " + std::to_string(ix.needed) + " fields, found " +
                                         std::to_string(fields.size()));
    }
    const LineTime t = parseTime(fields[static_cast<std::size_t>(ix.time)], format.time, where);
    ImuSample s;
    static constexpr const char* kAccel[3] = {"ax", "ay", "az"};
    static constexpr const char* kGyro[3] = {"gx", "gy", "gz"};
    for (int a = 0; a < 3; ++a) {
      s.accel[a] = parseFiniteDouble(fields[static_cast<std::size_t>(ix.accel[a])], where, kAccel[a]) * format.accelScale;
      s.gyro[a] = parseFiniteDouble(fields[static_cast<std::size_t>(ix.gyro[a])], where, kGyro[a]) * format.gyroScale;
    }
    if (s.gyro.cwiseAbs().maxCoeff() > kMaxAngularRate) {
      throwParseError(where, "gyro", "angular rate beyond " + std::to_string(kMaxAngularRate) + " rad/s");
    }
    if (s.accel.cwiseAbs().maxCoeff() > kMaxSpecificForce) {
      throwParseError(where, "accel", "specific force beyond " + std::to_string(kMaxSpecificForce) + " m/s^2");
    }
    s.accel = format.rotation * s.accel;
    s.gyro = format.rotation * s.gyro;
    if (counter) {
      if (!counterMs.empty() && !(t.counter_ms > counterMs.back())) {
        throwParseError(where, "t", "counter does not increase (previous " + std::to_string(counterMs.back()) + ")");
      }
      const std::optional<std::int64_t> by = tag->writtenBy(l.end);
      if (!by) {
        ++rep.untaggedSkipped;
        continue;
      }
      counterMs.push_back(t.counter_ms);
      tagNs.push_back(*by);
    } else {
      s.t_ns = t.ns;
      if (!samples.empty() && s.t_ns <= samples.back().t_ns) {
        throwParseError(where, "t", "time " + std::to_string(s.t_ns) + " ns not after the previous " +
                                        std::to_string(samples.back().t_ns));
      }
    }
    samples.push_back(s);
  }
  if (counter) placeCounterOnTags(samples, counterMs, tagNs, rep);
  rep.samples = samples.size();
  std::vector<double> dt;
  dt.reserve(samples.size());
  for (std::size_t i = 1; i < samples.size(); ++i) dt.push_back(static_cast<double>(samples[i].t_ns - samples[i - 1].t_ns) * 1e-9);
  rep.medianPeriod_s = median(std::move(dt));
  if (report) *report = rep;
  return samples;
}

}  // namespace gvins::vio
