#include "gvins/gnss/pos_reader.hpp"

#include <array>
#include <cmath>
#include <limits>
#include <optional>

#include "gvins/base/constants.hpp"
#include "gvins/base/geodetic.hpp"
#include "gvins/base/line_reader.hpp"
#include "gvins/base/local_frame.hpp"
#include "gvins/base/text_fields.hpp"

namespace gvins {

namespace {

std::vector<std::string_view> splitBlanks(std::string_view s) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && (s[i] == ' ' || s[i] == '\t' || s[i] == '\r')) ++i;
    if (i >= s.size()) break;
    std::size_t j = i;
    while (j < s.size() && s[j] != ' ' && s[j] != '\t' && s[j] != '\r') ++j;
    out.push_back(s.substr(i, j - i));
    i = j;
  }
  return out;
}

/// "nan" or "-nan" (printf's spelling), the writer's mark of an absent velocity.
bool isNanToken(std::string_view t) {
  if (!t.empty() && (t[0] == '-' || t[0] == '+')) t.remove_prefix(1);
  return t.size() == 3 && (t[0] == 'n' || t[0] == 'N') && (t[1] == 'a' || t[1] == 'A') && (t[2] == 'n' || t[2] == 'N');
}

enum class Layout { Unknown, Ecef, Llh };
enum class TimeScale { Gpst, Utc };

// An integer column (Q, ns, test). Solution files written by scripts print every column with
// decimals ("1.0000000"; the rtklibexplorer GNSS_IMU reference tracks): an integral value in that
// form is accepted, anything else is an error naming the column.
long integerColumn(std::string_view text, const TextLocation& w, const char* name) {
  if (text.find('.') == std::string_view::npos) return parseInt(text, w, name);
  const double v = parseDouble(text, w, name);
  if (!(std::abs(v - std::round(v)) < 1e-9) || std::abs(v) > 1e9) throwParseError(w, name, "not an integer: '" + std::string(text) + "'");
  return std::lround(v);
}

PosFile parse(LineReader& in) {
  PosFile out;
  Layout layout = Layout::Unknown;
  TimeScale scale = TimeScale::Gpst;
  bool testColumn = false;  // the column titles end with "test" (our residual-test column)
  std::string line;
  while (in.next(line)) {
    const std::string_view l = trim(line);
    if (l.empty()) continue;
    const TextLocation w = in.location();
    if (l[0] == '%') {
      if (l.find("x-ecef") != std::string_view::npos) layout = Layout::Ecef;
      else if (l.find("latitude") != std::string_view::npos) layout = Layout::Llh;
      if (l.find("x-ecef") != std::string_view::npos || l.find("latitude") != std::string_view::npos) {
        if (l.find("UTC") != std::string_view::npos) scale = TimeScale::Utc;
        else if (l.find("GPST") == std::string_view::npos) {
          throwParseError(w, "time system", "only GPST or UTC solution files are supported");
        }
        if (l.find("latitude(d'\")") != std::string_view::npos) {
          throwParseError(w, "latitude", "degree-minute-second coordinates are not supported");
        }
        const auto titles = splitBlanks(l);
        testColumn = !titles.empty() && titles.back() == "test";
      }
      continue;
    }
    auto tok = splitBlanks(l);
    std::optional<ResidualTest> residualTest;
    if (testColumn && tok.size() >= 8) {
      const long t = integerColumn(tok.back(), w, "test");
      if (t < 0 || t > 2) throwParseError(w, "test", "residual test flag outside 0-2");
      residualTest = static_cast<ResidualTest>(t);
      tok.pop_back();
    }
    if (tok.size() < 7) throwParseError(w, "row", "expected at least time, 3 coordinates, Q and ns");
    PositionSolution s;
    s.residualTest = residualTest;
    // Time: "yyyy/mm/dd hh:mm:ss.sss" or "week tow".
    if (tok[0].find('/') != std::string_view::npos) {
      CalendarTime c;
      const auto d = tok[0];
      const auto t = tok[1];
      if (d.size() != 10 || d[4] != '/' || d[7] != '/') throwParseError(w, "date", "expected yyyy/mm/dd");
      if (t.size() < 8 || t[2] != ':' || t[5] != ':') throwParseError(w, "time", "expected hh:mm:ss");
      c.year = static_cast<int>(parseInt(d.substr(0, 4), w, "year"));
      c.month = static_cast<int>(parseInt(d.substr(5, 2), w, "month"));
      c.day = static_cast<int>(parseInt(d.substr(8, 2), w, "day"));
      c.hour = static_cast<int>(parseInt(t.substr(0, 2), w, "hour"));
      c.minute = static_cast<int>(parseInt(t.substr(3, 2), w, "minute"));
      c.second = parseDouble(t.substr(6), w, "second");
      if (!isValidCalendar(c) || c.year < 1980 || c.year > 2200) throwParseError(w, "time", "invalid date/time");
      s.time = scale == TimeScale::Utc ? utcToGpst(c) : GpsTime::fromCalendar(c);
    } else {
      const long week = parseInt(tok[0], w, "week");
      const double tow = parseDouble(tok[1], w, "tow");
      if (week < 0 || week > 10000 || tow < 0.0 || tow >= 604800.0) throwParseError(w, "week/tow", "out of range");
      s.time = GpsTime::fromWeekTow(static_cast<int>(week), tow);
      if (scale == TimeScale::Utc) s.time += leapSecondsAtGpst(s.time);
    }
    std::array<double, 3> p{};
    static constexpr const char* kPosNames[2][3] = {{"x-ecef", "y-ecef", "z-ecef"},
                                                   {"latitude", "longitude", "height"}};
    Layout lay = layout;
    for (int i = 0; i < 3; ++i) p[i] = parseDouble(tok[2 + i], w, kPosNames[lay == Layout::Llh ? 1 : 0][i]);
    if (lay == Layout::Unknown) lay = std::abs(p[0]) > 1000.0 || std::abs(p[1]) > 1000.0 ? Layout::Ecef : Layout::Llh;
    const long q = integerColumn(tok[5], w, "Q");
    if (q < 0 || q > 6) throwParseError(w, "Q", "quality flag outside 0-6");
    s.quality = static_cast<SolutionQuality>(q);
    const long ns = integerColumn(tok[6], w, "ns");
    if (ns < 0 || ns > 999) throwParseError(w, "ns", "number of satellites out of range");
    s.numSatellites = static_cast<int>(ns);
    auto val = [&](std::size_t i, const char* name) { return parseDouble(tok[i], w, name); };
    // Velocity columns may be nan (no velocity in that epoch).
    auto velVal = [&](std::size_t i, const char* name) {
      return isNanToken(tok[i]) ? std::numeric_limits<double>::quiet_NaN() : parseDouble(tok[i], w, name);
    };
    Eigen::Matrix3d P = Eigen::Matrix3d::Zero();
    if (tok.size() >= 13) {
      const double sd[3] = {val(7, "sd1"), val(8, "sd2"), val(9, "sd3")};
      const double cr[3] = {val(10, "sd12"), val(11, "sd23"), val(12, "sd31")};
      for (int i = 0; i < 3; ++i) P(i, i) = sd[i] * sd[i];
      auto sq = [](double v) { return v < 0 ? -v * v : v * v; };
      P(0, 1) = P(1, 0) = sq(cr[0]);
      P(1, 2) = P(2, 1) = sq(cr[1]);
      P(2, 0) = P(0, 2) = sq(cr[2]);
    }
    if (tok.size() >= 15) {
      s.age = val(13, "age");
      s.ratio = val(14, "ratio");
    }
    Eigen::Matrix3d V = Eigen::Matrix3d::Zero();
    Eigen::Vector3d vel = Eigen::Vector3d::Zero();
    bool hasVel = false;
    if (tok.size() >= 18) {
      vel = {velVal(15, "v1"), velVal(16, "v2"), velVal(17, "v3")};
      hasVel = true;
      if (tok.size() >= 24) {
        const double sd[3] = {velVal(18, "sdv1"), velVal(19, "sdv2"), velVal(20, "sdv3")};
        const double cr[3] = {velVal(21, "sdv12"), velVal(22, "sdv23"), velVal(23, "sdv31")};
        for (int i = 0; i < 3; ++i) V(i, i) = sd[i] * sd[i];
        auto sq = [](double v) { return v < 0 ? -v * v : v * v; };
        V(0, 1) = V(1, 0) = sq(cr[0]);
        V(1, 2) = V(2, 1) = sq(cr[1]);
        V(2, 0) = V(0, 2) = sq(cr[2]);
      }
    }
    // Our writer prints nan in the velocity columns of epochs without a velocity, RTKLIB zeros.
    if (hasVel && vel.array().isNaN().all() && (V.array().isNaN().all() || tok.size() < 24)) {
      hasVel = false;
      vel.setZero();
      V.setZero();
    }
    if (hasVel && vel.isZero(0.0) && V.isZero(0.0)) hasVel = false;
    if (!std::isfinite(P.sum()) || !std::isfinite(V.sum()) || !vel.allFinite()) {
      throwParseError(w, "row", "non-finite value");
    }
    if (lay == Layout::Ecef) {
      s.position = {p[0], p[1], p[2]};
      s.positionCovariance = P;
      if (hasVel) s.velocity = vel;
      s.velocityCovariance = V;
      out.ecef = true;
    } else {
      if (std::abs(p[0]) > 90.0 || std::abs(p[1]) > 360.0 || std::abs(p[2]) > 1e8) {
        throwParseError(w, "latitude/longitude/height", "out of range");
      }
      const Geodetic g = geodeticFromDegrees(p[0], p[1], p[2]);
      s.position = geodeticToEcef(g);
      // Columns are n, e, u; back to ECEF.
      Eigen::Matrix3d perm;
      perm << 0, 1, 0, 1, 0, 0, 0, 0, 1;
      const Eigen::Matrix3d rn = perm * ecefToEnuRotation(g.lat, g.lon);
      s.positionCovariance = rn.transpose() * P * rn;
      if (hasVel) s.velocity = rn.transpose() * vel;
      s.velocityCovariance = rn.transpose() * V * rn;
    }
    out.solutions.push_back(s);
  }
  return out;
}

}  // namespace

PosFile readPosFile(const std::string& path) {
  LineReader in(path);
  return parse(in);
}

PosFile parsePosText(std::string_view text, std::string_view name) {
  LineReader in(text, std::string(name));
  return parse(in);
}

}  // namespace gvins
