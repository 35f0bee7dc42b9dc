// SP3-c / SP3-d reader and writer.
//
// Column layouts from "The Extended Standard Product 3 Orbit Format (SP3-d)", S. Hilla, IGS,
// 21 Feb 2016 (and SP3-c, S. Hilla, 2010), all positions 0-based here:
//   line 1  "#d" version, [2] P/V flag, [3,7) year, [8,10) month, [11,13) day, [14,16) hour,
//           [17,19) minute, [20,31) second, [32,39) number of epochs, [40,45) data used,
//           [46,51) coordinate system, [52,55) orbit type, [56,60) agency
//   line 2  "##" [3,7) GPS week, [8,23) seconds of week, [24,38) epoch interval, [39,44) MJD,
//           [45,60) fractional day
//   "+ "    [3,6) number of satellites (SP3-c: I2 in [4,6)), ids in 17 fields of 3 from [9,60)
//   "++"    accuracy exponents, 17 fields of I3 from [9,60): accuracy = 2^exp mm (0 = unknown)
//   "%c"    [3,5) file type, [9,12) time system
//   "*  "   epoch yyyy mm dd hh mm ss.ssssssss
//   P/V     [1,4) satellite, [4,18) [18,32) [32,46) x y z (km; dm/s), [46,60) clock (us; 1e-4 us/s)
// Missing values: 0.000000 positions, 999999.999999 clocks (SP3-d section 3, "bad or absent").
#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <limits>
#include <ostream>
#include <set>
#include <string>

#include "gvins/base/line_reader.hpp"
#include "gvins/base/text_fields.hpp"
#include "gvins/ephemeris/sp3.hpp"
#include "product_time_scale.hpp"

namespace gvins {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kMissingClock = 999999.0;  // |clock| at or above this (us, 1e-4 us/s) = absent
constexpr int kSatsPerLine = 17;
constexpr int kMaxSatellites = 999;         // I3 field of SP3-d
constexpr std::size_t kMaxReserve = 4096;   // never pre-allocate more than this from a header count

bool startsWith(std::string_view s, std::string_view p) { return s.substr(0, p.size()) == p; }

int intField(std::string_view text, const TextLocation& where, std::string_view field, long lo, long hi) {
  const long v = parseInt(trim(text), where, field);
  if (v < lo || v > hi) {
    throwParseError(where, field, "value " + std::to_string(v) + " out of range [" + std::to_string(lo) + ", " +
                                      std::to_string(hi) + "]");
  }
  return static_cast<int>(v);
}

// "yyyy mm dd hh mm ss.ssssssss" separated by blanks (the SP3 I4,1X,I2,... layout).
CalendarTime parseCalendar(std::string_view text, const TextLocation& where, std::string_view field) {
  std::string_view tok[6];
  std::size_t n = 0, i = 0;
  while (n < 6) {
    while (i < text.size() && text[i] == ' ') ++i;
    if (i >= text.size()) break;
    const std::size_t start = i;
    while (i < text.size() && text[i] != ' ') ++i;
    tok[n++] = text.substr(start, i - start);
  }
  if (n < 6) throwParseError(where, field, "incomplete epoch '" + std::string(trim(text)) + "'");
  CalendarTime c;
  c.year = intField(tok[0], where, field, 1980, 2200);
  c.month = intField(tok[1], where, field, 1, 12);
  c.day = intField(tok[2], where, field, 1, 31);
  c.hour = intField(tok[3], where, field, 0, 23);
  c.minute = intField(tok[4], where, field, 0, 59);
  // F11.8 seconds: anything finer than the field's 1e-8 s is rounded away, so that the epochs
  // compared and written are the ones the format can hold.
  c.second = std::round(parseFiniteDouble(tok[5], where, field) * 1e8) * 1e-8;
  if (!isValidCalendar(c)) throwParseError(where, field, "invalid date/time '" + std::string(trim(text)) + "'");
  return c;
}

bool isPadding(std::string_view id) {
  id = trim(id);
  return id.empty() || id == "0" || id == "00" || id == "000";
}

class Sp3Reader {
 public:
  explicit Sp3Reader(LineReader& in) : in_(in) {}
  Sp3Data run();

 private:
  LineReader& in_;
  Sp3Data d_;
  std::string_view line_;
  bool velocityFlag_ = false;
  long declaredEpochs_ = 0;
  GpsTime firstEpoch_;

  TextLocation here() const { return in_.location(); }
  bool next() {
    if (!in_.next(line_)) return false;
    if (!line_.empty() && line_.back() == '\r') line_.remove_suffix(1);
    return true;
  }
  void need(std::string_view what) {
    if (!next()) throwParseError(here(), what, "unexpected end of file (missing " + std::string(what) + " line)");
  }
  void readHeader();
  void readSatelliteLines();
  void readBody();
  SatId recordSatellite(std::string_view id, const std::vector<SatId>& sorted) const;
};

SatId Sp3Reader::recordSatellite(std::string_view id, const std::vector<SatId>& sorted) const {
  const auto sat = SatId::parse(id);
  if (!sat) throwParseError(here(), "satellite", "unknown satellite '" + std::string(id) + "'");
  if (!std::binary_search(sorted.begin(), sorted.end(), *sat)) {
    throwParseError(here(), "satellite", "satellite " + sat->str() + " is not in the header list");
  }
  return *sat;
}

void Sp3Reader::readHeader() {
  if (!next()) throwParseError(here(), "#c/#d line", "empty file");
  if (line_.size() < 2 || line_[0] != '#') throwParseError(here(), "#c/#d line", "not an SP3 file");
  const char v = line_[1];
  if (v != 'c' && v != 'd') {
    throwParseError(here(), "version", std::string("unsupported SP3 version '") + v + "' (only c and d)");
  }
  d_.version = v;
  const char flag = line_.size() > 2 ? line_[2] : ' ';
  if (flag != 'P' && flag != 'V') throwParseError(here(), "position/velocity flag", "expected P or V");
  velocityFlag_ = flag == 'V';
  const CalendarTime first = parseCalendar(column(line_, 3, 28), here(), "first epoch");
  declaredEpochs_ = intField(column(line_, 32, 7), here(), "number of epochs", 0, 9999999);
  d_.dataUsed = std::string(trimmedColumn(line_, 40, 5));
  d_.coordinateSystem = std::string(trimmedColumn(line_, 46, 5));
  d_.orbitType = std::string(trimmedColumn(line_, 52, 3));
  d_.agency = std::string(trimmedColumn(line_, 56, 4));

  need("##");
  if (!startsWith(line_, "##")) throwParseError(here(), "##", "expected the '##' line");
  intField(column(line_, 3, 4), here(), "GPS week", 0, 99999);
  const double sow = parseFiniteDouble(column(line_, 8, 15), here(), "seconds of week");
  if (sow < 0.0 || sow >= kSecondsPerWeek) throwParseError(here(), "seconds of week", "out of range");
  d_.interval = parseFiniteDouble(column(line_, 24, 14), here(), "epoch interval");
  if (!(d_.interval > 0.0 && d_.interval < 1e5)) throwParseError(here(), "epoch interval", "must be in (0, 1e5) s (F14.8)");
  intField(column(line_, 39, 5), here(), "MJD", 0, 999999);

  readSatelliteLines();

  // %c, %f, %i and /* lines, then the first epoch.
  bool haveTimeSystem = false;
  while (true) {
    need("epoch");
    if (startsWith(line_, "%c")) {
      if (!haveTimeSystem) {
        std::string ts(trimmedColumn(line_, 9, 3));
        if (ts == "ccc" || ts.empty()) ts = "GPS";  // SP3-c files before the time-system field
        if (!isProductTimeSystem(ts)) throwParseError(here(), "time system", "unknown time system '" + ts + "'");
        d_.timeSystem = ts;
        haveTimeSystem = true;
      }
    } else if (startsWith(line_, "%f") || startsWith(line_, "%i")) {
      // Floating/integer bases for the per-record standard deviations: not used.
    } else if (startsWith(line_, "/*")) {
      std::string_view c = line_.substr(2);
      if (!c.empty() && c.front() == ' ') c.remove_prefix(1);
      d_.comments.emplace_back(c);
    } else if (startsWith(line_, "*") || startsWith(line_, "EOF")) {
      if (!haveTimeSystem) throwParseError(here(), "%c", "missing '%c' line (time system) before the first epoch");
      in_.unread();
      break;
    } else {
      throwParseError(here(), "header", "unexpected header line '" + std::string(line_.substr(0, 20)) + "'");
    }
  }
  firstEpoch_ = productTimeToGpst(first, d_.timeSystem);
}

void Sp3Reader::readSatelliteLines() {
  need("+");
  if (!startsWith(line_, "+ ")) throwParseError(here(), "+", "expected the '+' satellite list line");
  const int count = intField(column(line_, 3, 3), here(), "number of satellites", 0, kMaxSatellites);
  int plusLines = 0;
  std::set<SatId> seen;
  while (startsWith(line_, "+ ")) {
    ++plusLines;
    for (int k = 0; k < kSatsPerLine; ++k) {
      const std::string_view id = column(line_, 9 + 3 * static_cast<std::size_t>(k), 3);
      if (isPadding(id)) continue;
      const auto sat = SatId::parse(id);
      if (!sat) throwParseError(here(), "satellite list", "unknown satellite '" + std::string(id) + "'");
      if (!seen.insert(*sat).second) throwParseError(here(), "satellite list", "duplicate satellite " + sat->str());
      if (static_cast<int>(d_.satellites.size()) >= count) {
        throwParseError(here(), "number of satellites", "more satellites listed than the " + std::to_string(count) + " declared");
      }
      d_.satellites.push_back(*sat);
    }
    need("++");
  }
  if (static_cast<int>(d_.satellites.size()) != count) {
    throwParseError(here(), "number of satellites",
                    std::to_string(count) + " declared but " + std::to_string(d_.satellites.size()) + " listed");
  }
  if (d_.version == 'c' && plusLines != 5) {
    throwParseError(here(), "+", "SP3-c needs exactly 5 '+' lines, found " + std::to_string(plusLines));
  }
  d_.accuracyExponent.assign(d_.satellites.size(), 0);
  int accLines = 0;
  std::size_t idx = 0;
  while (startsWith(line_, "++")) {
    ++accLines;
    if (accLines > plusLines) throwParseError(here(), "++", "more '++' lines than '+' lines");
    for (int k = 0; k < kSatsPerLine; ++k, ++idx) {
      const std::string_view f = trimmedColumn(line_, 9 + 3 * static_cast<std::size_t>(k), 3);
      if (idx < d_.satellites.size() && !f.empty()) {
        d_.accuracyExponent[idx] = intField(f, here(), "accuracy exponent", -99, 99);
      }
    }
    need("%c");
  }
  if (accLines != plusLines) {
    throwParseError(here(), "++", std::to_string(plusLines) + " '+' lines but " + std::to_string(accLines) + " '++' lines");
  }
  in_.unread();
}

void Sp3Reader::readBody() {
  std::vector<SatId> sorted = d_.satellites;
  std::sort(sorted.begin(), sorted.end());
  d_.epochs.reserve(static_cast<std::size_t>(std::min<long>(declaredEpochs_, static_cast<long>(kMaxReserve))));
  Sp3Epoch* epoch = nullptr;
  std::vector<SatId> inEpoch;  // satellites of the current epoch, for duplicates
  bool sawEof = false;
  Sp3Record* last = nullptr;   // last P record, for its V/EP/EV lines
  bool lastHasV = false;
  while (next()) {
    if (line_.empty()) continue;
    if (startsWith(line_, "EOF")) {
      sawEof = true;
      break;
    }
    const char type = line_[0];
    if (type == '*') {
      const GpsTime t = productTimeToGpst(parseCalendar(line_.substr(1), here(), "epoch"), d_.timeSystem);
      if (t < firstEpoch_) {
        throwParseError(here(), "epoch", "epoch " + t.toString(3) + " before the header's first epoch " + firstEpoch_.toString(3));
      }
      if (!d_.epochs.empty() && !(d_.epochs.back().time < t)) {
        throwParseError(here(), "epoch", d_.epochs.back().time == t ? "duplicate epoch " + t.toString(3)
                                                                    : "epochs out of order at " + t.toString(3));
      }
      if (static_cast<long>(d_.epochs.size()) >= declaredEpochs_) {
        throwParseError(here(), "number of epochs", "more epochs than the " + std::to_string(declaredEpochs_) + " declared");
      }
      d_.epochs.push_back({t, {}});
      epoch = &d_.epochs.back();
      epoch->records.reserve(std::min(sorted.size(), kMaxReserve));
      inEpoch.clear();
      last = nullptr;
      continue;
    }
    if (type == 'P') {
      if (!epoch) throwParseError(here(), "P record", "position record before the first epoch line");
      const SatId sat = recordSatellite(column(line_, 1, 3), sorted);
      if (std::find(inEpoch.begin(), inEpoch.end(), sat) != inEpoch.end()) {
        throwParseError(here(), "satellite", "satellite " + sat.str() + " twice in one epoch");
      }
      inEpoch.push_back(sat);
      Sp3Record r;
      r.sat = sat;
      const double x = parseFiniteDouble(column(line_, 4, 14), here(), "x");
      const double y = parseFiniteDouble(column(line_, 18, 14), here(), "y");
      const double z = parseFiniteDouble(column(line_, 32, 14), here(), "z");
      if (!(x == 0.0 && y == 0.0 && z == 0.0)) r.position = Eigen::Vector3d(x, y, z) * 1000.0;
      const auto clk = parseOptionalDouble(trimmedColumn(line_, 46, 14), here(), "clock");
      if (clk && !std::isfinite(*clk)) throwParseError(here(), "clock", "not a finite number");
      r.clock = clk && std::fabs(*clk) < kMissingClock ? *clk * 1e-6 : kNaN;
      epoch->records.push_back(r);
      last = &epoch->records.back();
      lastHasV = false;
      continue;
    }
    if (type == 'V') {
      if (!velocityFlag_) throwParseError(here(), "V record", "velocity record in a file flagged 'P' (positions only)");
      if (!last) throwParseError(here(), "V record", "velocity record without a preceding position record");
      const SatId sat = recordSatellite(column(line_, 1, 3), sorted);
      if (!(sat == last->sat) || lastHasV) {
        throwParseError(here(), "V record", "velocity record of " + sat.str() + " does not follow its position record");
      }
      const double vx = parseFiniteDouble(column(line_, 4, 14), here(), "vx");
      const double vy = parseFiniteDouble(column(line_, 18, 14), here(), "vy");
      const double vz = parseFiniteDouble(column(line_, 32, 14), here(), "vz");
      last->velocity = (vx == 0.0 && vy == 0.0 && vz == 0.0) ? Eigen::Vector3d(Eigen::Vector3d::Constant(kNaN))
                                                             : Eigen::Vector3d(Eigen::Vector3d(vx, vy, vz) * 0.1);  // dm/s
      const auto rate = parseOptionalDouble(trimmedColumn(line_, 46, 14), here(), "clock rate");
      if (rate && !std::isfinite(*rate)) throwParseError(here(), "clock rate", "not a finite number");
      last->clockRate = rate && std::fabs(*rate) < kMissingClock ? *rate * 1e-10 : kNaN;  // 1e-4 us/s
      lastHasV = true;
      continue;
    }
    if (startsWith(line_, "EP") || startsWith(line_, "EV")) {
      if (!last) throwParseError(here(), "correlation record", "EP/EV record without a preceding position record");
      continue;  // standard deviations and correlations: not used
    }
    if (trim(line_).empty()) continue;
    throwParseError(here(), "record type", "unexpected line '" + std::string(line_.substr(0, 20)) + "'");
  }
  if (!sawEof) throwParseError(here(), "EOF", "missing 'EOF' line (truncated file)");
  if (static_cast<long>(d_.epochs.size()) != declaredEpochs_) {
    throwParseError(here(), "number of epochs",
                    std::to_string(declaredEpochs_) + " declared but " + std::to_string(d_.epochs.size()) + " found");
  }
}

Sp3Data Sp3Reader::run() {
  readHeader();
  readBody();
  return std::move(d_);
}

// ---- writer ----------------------------------------------------------------------------------

void putLine(std::ostream& out, const char* fmt, ...) __attribute__((format(printf, 2, 3)));
void putLine(std::ostream& out, const char* fmt, ...) {
  char buf[256];
  va_list ap;
  va_start(ap, fmt);
  std::vsnprintf(buf, sizeof buf, fmt, ap);
  va_end(ap);
  out << buf << '\n';
}

// A vector in km (or dm/s) with 6 decimals in 14 columns; absent (or too large for the field) as
// 0.000000 in all three, which is how SP3 marks a missing value.
Eigen::Vector3d fitOrZero(const Eigen::Vector3d& v) {
  return v.allFinite() && v.cwiseAbs().maxCoeff() < 999999.0 ? v : Eigen::Vector3d::Zero();
}
double clockOrMissing(double v) { return std::isfinite(v) && std::fabs(v) < kMissingClock ? v : 999999.999999; }

}  // namespace

Sp3Data parseSp3(std::string_view text, const std::string& name) {
  LineReader in(text, name);
  return Sp3Reader(in).run();
}

Sp3Data readSp3(const std::string& path) {
  LineReader in(path);
  return Sp3Reader(in).run();
}

void writeSp3(std::ostream& out, const Sp3Data& data) {
  // Satellites: the header list plus any satellite of the records missing from it.
  std::vector<SatId> sats = data.satellites;
  std::vector<int> acc(sats.size(), 0);
  for (std::size_t i = 0; i < sats.size() && i < data.accuracyExponent.size(); ++i) acc[i] = data.accuracyExponent[i];
  for (const auto& e : data.epochs) {
    for (const auto& r : e.records) {
      if (std::find(sats.begin(), sats.end(), r.sat) == sats.end()) {
        sats.push_back(r.sat);
        acc.push_back(0);
      }
    }
  }
  const char version = data.version == 'c' && sats.size() <= 85 ? 'c' : 'd';
  bool velocity = false;
  for (const auto& e : data.epochs) {
    for (const auto& r : e.records) velocity = velocity || r.velocity.has_value() || r.clockRate.has_value();
  }
  const std::string ts = isProductTimeSystem(data.timeSystem) ? data.timeSystem : "GPS";
  auto fileTime = [&](const GpsTime& t) {
    // Round to the 1e-8 s resolution of the epoch field before splitting into calendar fields.
    const double frac = t.fraction();
    const GpsTime r = t + (std::round(frac * 1e8) * 1e-8 - frac);
    return gpstToProductTime(r, ts);
  };
  const CalendarTime first = data.epochs.empty() ? GpsTime{}.toCalendar() : fileTime(data.epochs.front().time);
  auto text = [](const std::string& s, std::size_t n) { return s.substr(0, n); };
  putLine(out, "#%c%c%4d %2d %2d %2d %2d %11.8f %7zu %-5s %-5s %-3s %-4s", version, velocity ? 'V' : 'P',
          first.year, first.month, first.day, first.hour, first.minute, first.second, data.epochs.size(),
          text(data.dataUsed.empty() ? "ORBIT" : data.dataUsed, 5).c_str(), text(data.coordinateSystem, 5).c_str(),
          text(data.orbitType, 3).c_str(), text(data.agency, 4).c_str());
  const GpsTime firstAsGps = GpsTime::fromCalendar(first);  // week/sow in the file's own scale
  const double mjd = modifiedJulianDate(first);
  const double interval = data.interval > 0.0 && data.interval < 1e5 ? data.interval : 0.0;
  putLine(out, "## %4d %15.8f %14.8f %5d %15.13f", std::clamp(firstAsGps.week(), 0, 9999), firstAsGps.tow(), interval,
          static_cast<int>(std::floor(mjd)), mjd - std::floor(mjd));

  const std::size_t nLines =
      version == 'c' ? 5 : std::max<std::size_t>(5, (sats.size() + kSatsPerLine - 1) / kSatsPerLine);
  for (std::size_t l = 0; l < nLines; ++l) {
    std::string s = l == 0 ? (version == 'c' ? "+   " : "+  ") : "+        ";
    if (l == 0) {
      char n[8];
      std::snprintf(n, sizeof n, version == 'c' ? "%2zu   " : "%3zu   ", sats.size());
      s += n;
    }
    for (std::size_t k = 0; k < kSatsPerLine; ++k) {
      const std::size_t i = l * kSatsPerLine + k;
      s += i < sats.size() ? sats[i].str() : "  0";
    }
    out << s << '\n';
  }
  for (std::size_t l = 0; l < nLines; ++l) {
    std::string s = "++       ";
    for (std::size_t k = 0; k < kSatsPerLine; ++k) {
      const std::size_t i = l * kSatsPerLine + k;
      char f[8];
      std::snprintf(f, sizeof f, "%3d", i < sats.size() ? std::clamp(acc[i], -99, 99) : 0);
      s += f;
    }
    out << s << '\n';
  }
  char fileType = 'M';
  if (!sats.empty() &&
      std::all_of(sats.begin(), sats.end(), [&](SatId s) { return s.system == sats.front().system; })) {
    fileType = systemLetter(sats.front().system);
  }
  putLine(out, "%%c %c  cc %s ccc cccc cccc cccc cccc ccccc ccccc ccccc ccccc", fileType, ts.c_str());
  out << "%c cc cc ccc ccc cccc cccc cccc cccc ccccc ccccc ccccc ccccc\n";
  out << "%f  1.2500000  1.025000000  0.00000000000  0.000000000000000\n";
  out << "%f  0.0000000  0.000000000  0.00000000000  0.000000000000000\n";
  out << "%i    0    0    0    0      0      0      0      0         0\n";
  out << "%i    0    0    0    0      0      0      0      0         0\n";
  const std::size_t nComments = version == 'c' ? 4 : std::max<std::size_t>(4, data.comments.size());
  for (std::size_t i = 0; i < nComments; ++i) {
    out << "/* " << (i < data.comments.size() ? text(data.comments[i], 77) : std::string()) << '\n';
  }
  for (const auto& e : data.epochs) {
    const CalendarTime c = fileTime(e.time);
    putLine(out, "*  %4d %2d %2d %2d %2d %11.8f", c.year, c.month, c.day, c.hour, c.minute, c.second);
    for (const auto& r : e.records) {
      const std::string id = r.sat.str();
      const Eigen::Vector3d km = fitOrZero(r.position / 1000.0);
      putLine(out, "P%s%14.6f%14.6f%14.6f%14.6f", id.c_str(), km.x(), km.y(), km.z(), clockOrMissing(r.clock * 1e6));
      if (velocity && (r.velocity || r.clockRate)) {
        const Eigen::Vector3d v = r.velocity ? fitOrZero(*r.velocity * 10.0) : Eigen::Vector3d::Zero();  // dm/s
        const double rate = r.clockRate ? *r.clockRate * 1e10 : kNaN;  // 1e-4 us/s
        putLine(out, "V%s%14.6f%14.6f%14.6f%14.6f", id.c_str(), v.x(), v.y(), v.z(), clockOrMissing(rate));
      }
    }
  }
  out << "EOF\n";
}

}  // namespace gvins
