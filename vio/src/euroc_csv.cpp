#include "gvins/vio/euroc_csv.hpp"

#include <cmath>
#include <string>

#include <Eigen/Geometry>

#include "csv_fields.hpp"

namespace gvins::vio {

namespace {
constexpr const char* kImuFields[7] = {"timestamp", "w_x", "w_y", "w_z", "a_x", "a_y", "a_z"};
constexpr const char* kGtFields[17] = {"timestamp", "p_x", "p_y", "p_z", "q_w", "q_x", "q_y", "q_z", "v_x",
                                       "v_y", "v_z", "bg_x", "bg_y", "bg_z", "ba_x", "ba_y", "ba_z"};

std::int64_t periodFromRate(double rateHz) {
  if (!(rateHz > 0.0) || !std::isfinite(rateHz)) return 0;
  return static_cast<std::int64_t>(std::llround(1e9 / rateHz));
}

constexpr double kMaxAngularRate = 200.0;     // rad/s
constexpr double kMaxSpecificForce = 2000.0;  // m/s^2, about 200 g

void checkIncreasing(std::int64_t t, std::int64_t last, const TextLocation& where) {
  if (last < 0) return;
  if (t == last) throwParseError(where, "timestamp", "duplicate time stamp " + std::to_string(t));
  if (t < last) {
    throwParseError(where, "timestamp",
                    "time stamp " + std::to_string(t) + " before the previous one " + std::to_string(last));
  }
}
}  // namespace

// ---------------------------------------------------------------------------------------- IMU

ImuCsvReader::ImuCsvReader(const std::string& path, double nominalRateHz) : reader_(path) {
  gaps_.nominalPeriod_ns = periodFromRate(nominalRateHz);
}

ImuCsvReader::ImuCsvReader(std::string_view text, std::string name, double nominalRateHz)
    : reader_(text, std::move(name)) {
  gaps_.nominalPeriod_ns = periodFromRate(nominalRateHz);
}

bool ImuCsvReader::next(ImuSample& s) {
  while (reader_.next(line_)) {
    if (detail::isCommentOrBlank(line_)) continue;
    const TextLocation where = reader_.location();
    detail::splitFields(line_, false, fields_);
    if (fields_.size() != 7) {
      throwParseError(where, fields_.size() < 7 ? kImuFields[std::min<std::size_t>(fields_.size(), 6)] : "line",
                      "expected 7 comma-separated fields (t, w_xyz, a_xyz), found " +
                          std::to_string(fields_.size()));
    }
    s.t_ns = detail::parseNanoseconds(fields_[0], where, "timestamp");
    for (int k = 0; k < 3; ++k) {
      s.gyro[k] = parseFiniteDouble(fields_[1 + k], where, kImuFields[1 + k]);
      s.accel[k] = parseFiniteDouble(fields_[4 + k], where, kImuFields[4 + k]);
      // Physical limits well beyond the full scale of navigation IMUs (MEMS data sheets give
      // +-2000 deg/s = 35 rad/s and +-16 g; shock-rated parts +-200 g): anything larger is a
      // corrupt value that would only surface later as a numerical failure of the filter.
      if (std::abs(s.gyro[k]) > kMaxAngularRate)
        throwParseError(where, kImuFields[1 + k], "angular rate " + std::string(fields_[1 + k]) + " rad/s beyond +-" +
                                                      std::to_string(static_cast<int>(kMaxAngularRate)) + " rad/s");
      if (std::abs(s.accel[k]) > kMaxSpecificForce)
        throwParseError(where, kImuFields[4 + k], "specific force " + std::string(fields_[4 + k]) + " m/s^2 beyond +-" +
                                                      std::to_string(static_cast<int>(kMaxSpecificForce)) + " m/s^2");
    }
    checkIncreasing(s.t_ns, last_, where);
    if (last_ >= 0 && gaps_.nominalPeriod_ns > 0) {
      const std::int64_t dt = s.t_ns - last_;
      if (2 * dt > 3 * gaps_.nominalPeriod_ns) {
        ++gaps_.gaps;
        gaps_.missingSamples += static_cast<std::size_t>(
            std::llround(static_cast<double>(dt) / static_cast<double>(gaps_.nominalPeriod_ns)) - 1);
        if (dt > gaps_.largestGap_ns) {
          gaps_.largestGap_ns = dt;
          gaps_.largestGapStart_ns = last_;
        }
      }
    }
    last_ = s.t_ns;
    ++gaps_.samples;
    return true;
  }
  return false;
}

std::vector<ImuSample> readImuCsv(const std::string& path, double nominalRateHz, ImuGapReport* gaps) {
  ImuCsvReader r(path, nominalRateHz);
  std::vector<ImuSample> out;
  ImuSample s;
  while (r.next(s)) out.push_back(s);
  if (gaps) *gaps = r.gaps();
  return out;
}

// ------------------------------------------------------------------------------------- camera

namespace {
std::vector<CameraCsvEntry> parseCameraLines(LineReader& reader) {
  std::vector<CameraCsvEntry> out;
  std::string line;
  std::vector<std::string_view> f;
  std::int64_t last = -1;
  while (reader.next(line)) {
    if (detail::isCommentOrBlank(line)) continue;
    const TextLocation where = reader.location();
    detail::splitFields(line, false, f);
    if (f.size() != 2) {
      throwParseError(where, f.size() < 2 ? "filename" : "line",
                      "expected 2 comma-separated fields (t, filename), found " + std::to_string(f.size()));
    }
    CameraCsvEntry e;
    e.t_ns = detail::parseNanoseconds(f[0], where, "timestamp");
    const std::string_view name = f[1];
    if (name.empty()) throwParseError(where, "filename", "empty file name");
    if (name.find('/') != std::string_view::npos || name.find('\\') != std::string_view::npos ||
        name == "." || name == "..") {
      throwParseError(where, "filename", "file name must not contain a path: '" + std::string(name) + "'");
    }
    for (const char c : name) {
      if (static_cast<unsigned char>(c) < 0x20) throwParseError(where, "filename", "control character in file name");
    }
    checkIncreasing(e.t_ns, last, where);
    last = e.t_ns;
    e.filename = std::string(name);
    e.line = where.line;
    out.push_back(std::move(e));
  }
  return out;
}
}  // namespace

std::vector<CameraCsvEntry> readCameraCsv(const std::string& path) {
  LineReader r(path);
  return parseCameraLines(r);
}

std::vector<CameraCsvEntry> parseCameraCsv(std::string_view text, const std::string& name) {
  LineReader r(text, name);
  return parseCameraLines(r);
}

// -------------------------------------------------------------------------------- ground truth

GroundTruthCsvReader::GroundTruthCsvReader(const std::string& path) : reader_(path) {}
GroundTruthCsvReader::GroundTruthCsvReader(std::string_view text, std::string name)
    : reader_(text, std::move(name)) {}

bool GroundTruthCsvReader::next(GroundTruthSample& s) {
  while (reader_.next(line_)) {
    if (detail::isCommentOrBlank(line_)) continue;
    const TextLocation where = reader_.location();
    detail::splitFields(line_, false, fields_);
    if (columns_ == 0) {
      if (fields_.size() != 17 && fields_.size() != 8) {
        throwParseError(where, "line",
                        "expected 17 (t, p, q_wxyz, v, bg, ba) or 8 (t, p, q_wxyz) comma-separated fields, found " +
                            std::to_string(fields_.size()));
      }
      columns_ = fields_.size();
    } else if (fields_.size() != columns_) {
      throwParseError(where, "line", "expected " + std::to_string(columns_) + " fields like the first row, found " +
                                         std::to_string(fields_.size()));
    }
    double v[17];
    s.state.t_ns = detail::parseNanoseconds(fields_[0], where, "timestamp");
    for (std::size_t k = 1; k < columns_; ++k) v[k] = parseDouble(fields_[k], where, kGtFields[k]);
    Eigen::Quaterniond q(v[4], v[5], v[6], v[7]);
    const double n = q.norm();
    if (std::abs(n - 1.0) > 1e-3) {
      throwParseError(where, "q_w", "quaternion norm " + std::to_string(n) + " is not 1");
    }
    q.coeffs() /= n;
    s.state.R_WI = q.toRotationMatrix();
    s.state.p_WI = {v[1], v[2], v[3]};
    s.hasVelocityAndBiases = columns_ == 17;
    if (s.hasVelocityAndBiases) {
      s.state.v_WI = {v[8], v[9], v[10]};
      s.state.bg = {v[11], v[12], v[13]};
      s.state.ba = {v[14], v[15], v[16]};
    } else {
      s.state.v_WI.setZero();
      s.state.bg.setZero();
      s.state.ba.setZero();
    }
    checkIncreasing(s.state.t_ns, last_, where);
    last_ = s.state.t_ns;
    return true;
  }
  return false;
}

std::vector<GroundTruthSample> readGroundTruthCsv(const std::string& path) {
  GroundTruthCsvReader r(path);
  std::vector<GroundTruthSample> out;
  GroundTruthSample s;
  while (r.next(s)) out.push_back(s);
  return out;
}

}  // namespace gvins::vio
