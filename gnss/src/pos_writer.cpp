#include "gvins/gnss/pos_writer.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <ostream>

#include "gvins/base/constants.hpp"
#include "gvins/base/geodetic.hpp"
#include "gvins/base/local_frame.hpp"

namespace gvins {

double signedSqrt(double c) { return c < 0.0 ? -std::sqrt(-c) : std::sqrt(c); }

namespace {

// printf-style fields appended to a row. std::to_chars with a precision produces exactly the
// characters of printf's %.*f (C++17 [charconv.to.chars]: "as if by printf in the C locale"),
// without printf's format parsing and multi-precision arithmetic; the padding is added here.

/// Right-aligned in `width` characters; with `zeros`, padded with '0' after the sign (printf's
/// '0' flag) instead of blanks. A blank-padded value that fills its field or is wider gets one
/// leading blank more, so that it never runs into the field before it (readers split on blanks;
/// RTKLIB's printf layout would write "0.0-1475.85308" for a ratio followed by a wide velocity).
void appendPadded(std::string& out, const char* first, const char* last, int width, bool zeros) {
  const int len = static_cast<int>(last - first);
  if (!zeros && len >= width) out += ' ';
  const int pad = std::max(width - len, 0);
  if (zeros && pad > 0 && first < last && *first == '-') {
    out += '-';
    ++first;
  }
  out.append(static_cast<std::size_t>(pad), zeros ? '0' : ' ');
  out.append(first, last);
}

/// %<width>.<precision>f (%0<width>.<precision>f with `zeros`).
void appendFixed(std::string& out, double v, int width, int precision, bool zeros = false) {
  char buf[400];  // any double in %.9f: at most 309 integer digits, sign, point, 9 decimals
  if (!std::isfinite(v)) {
    // inf/nan are spelled by the C library itself.
    const int n = std::snprintf(buf, sizeof buf, "%.*f", precision, v);
    appendPadded(out, buf, buf + std::max(n, 0), width, false);
    return;
  }
  const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::fixed, precision);
  appendPadded(out, buf, r.ptr, width, zeros);
}

/// %<width>d (%0<width>d with `zeros`).
void appendInt(std::string& out, int v, int width, bool zeros = false) {
  char buf[16];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  appendPadded(out, buf, r.ptr, width, zeros);
}

}  // namespace

PosWriter::PosWriter(std::ostream& out, PosWriterOptions options) : out_(out), opt_(std::move(options)) {
  opt_.timeDecimals = std::clamp(opt_.timeDecimals, 0, 9);
}

void PosWriter::writeHeader() {
  headerDone_ = true;
  if (!opt_.header) return;
  std::string h = "% program   : " + opt_.program + "\n";
  for (const auto& [k, v] : opt_.headerFields) {
    std::string key = k;
    if (key.size() < 10) key.resize(10, ' ');
    h += "% " + key + ": " + v + "\n";
  }
  h += "%\n";
  const bool xyz = opt_.coordinates == PosCoordinates::Xyz;
  h += xyz ? "% (x/y/z-ecef=WGS84,Q=1:fix,2:float,3:sbas,4:dgps,5:single,6:ppp,ns=# of satellites)\n"
           : "% (lat/lon/height=WGS84/ellipsoidal,Q=1:fix,2:float,3:sbas,4:dgps,5:single,6:ppp,ns=# of satellites)\n";
  // Legends of our additions (docs/pos_format.md). RTKLIB's readers take the time system and the
  // layout from header lines naming them, so these lines name neither.
  if (opt_.velocity) h += "% (velocity columns nan: no velocity in that epoch)\n";
  if (opt_.testColumn) {
    h += "% (test=residual/RAIM test of the epoch: 0:passed,1:failed after fault exclusion (solution kept, "
         "not trustworthy),2:not testable (no redundancy))\n";
  }
  for (const std::string& note : opt_.notes) h += "% (" + note + ")\n";
  // Column titles aligned with the row layout below.
  std::string t = "%  GPST";
  t.resize(static_cast<std::size_t>(19 + (opt_.timeDecimals > 0 ? opt_.timeDecimals + 1 : 0) + 2), ' ');
  char buf[512];
  if (xyz) {
    std::snprintf(buf, sizeof buf, "%15s%15s%15s%4s%4s%9s%9s%9s%9s%9s%9s%7s%7s", "x-ecef(m)", "y-ecef(m)", "z-ecef(m)",
                  "Q", "ns", "sdx(m)", "sdy(m)", "sdz(m)", "sdxy(m)", "sdyz(m)", "sdzx(m)", "age(s)", "ratio");
  } else {
    std::snprintf(buf, sizeof buf, "%15s%15s%11s%4s%4s%9s%9s%9s%9s%9s%9s%7s%7s", "latitude(deg)", "longitude(deg)",
                  "height(m)", "Q", "ns", "sdn(m)", "sde(m)", "sdu(m)", "sdne(m)", "sdeu(m)", "sdun(m)", "age(s)",
                  "ratio");
  }
  t.resize(t.size() - 2);
  t += buf;
  if (opt_.velocity) {
    if (xyz) {
      std::snprintf(buf, sizeof buf, "%11s%11s%11s %9s%9s%9s%9s%9s%9s", "vx(m/s)", "vy(m/s)", "vz(m/s)", "sdvx", "sdvy",
                    "sdvz", "sdvxy", "sdvyz", "sdvzx");
    } else {
      std::snprintf(buf, sizeof buf, "%11s%11s%11s %9s%9s%9s%9s%9s%9s", "vn(m/s)", "ve(m/s)", "vu(m/s)", "sdvn", "sdve",
                    "sdvu", "sdvne", "sdveu", "sdvun");
    }
    t += buf;
  }
  if (opt_.testColumn) t += " test";
  h += t + "\n";
  out_ << h;
}

void PosWriter::write(const PositionSolution& s) {
  if (!headerDone_) writeHeader();
  // Time rounded to the printed resolution first, so that seconds never read 60.
  const double scale = std::pow(10.0, opt_.timeDecimals);
  const double frac = std::round(s.time.fraction() * scale) / scale;
  const CalendarTime c = GpsTime::fromSeconds(s.time.wholeSeconds(), frac).toCalendar();
  const double sec = std::floor(c.second * scale + 0.5) / scale;
  // "%04d/%02d/%02d %02d:%02d:%0*.*f"
  buf_.clear();
  appendInt(buf_, c.year, 4, true);
  buf_ += '/';
  appendInt(buf_, c.month, 2, true);
  buf_ += '/';
  appendInt(buf_, c.day, 2, true);
  buf_ += ' ';
  appendInt(buf_, c.hour, 2, true);
  buf_ += ':';
  appendInt(buf_, c.minute, 2, true);
  buf_ += ':';
  appendFixed(buf_, sec, opt_.timeDecimals > 0 ? opt_.timeDecimals + 3 : 2, opt_.timeDecimals, true);
  const bool xyz = opt_.coordinates == PosCoordinates::Xyz;
  Eigen::Matrix3d P = s.positionCovariance;
  Eigen::Matrix3d V = s.velocityCovariance;
  // An epoch without velocity gets nan in the velocity columns (RTKLIB writes zeros there, which
  // read as a measured standstill with zero uncertainty).
  constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
  Eigen::Vector3d vel = s.velocity.value_or(Eigen::Vector3d::Constant(kNan));
  if (xyz) {
    // "%15.4f%15.4f%15.4f"
    for (int i = 0; i < 3; ++i) appendFixed(buf_, s.position[i], 15, 4);
  } else {
    const Geodetic g = ecefToGeodetic(s.position);
    const Eigen::Matrix3d r = ecefToEnuRotation(g.lat, g.lon);
    // ENU -> NEU ordering as in RTKLIB's geodetic layout (n, e, u).
    Eigen::Matrix3d perm;
    perm << 0, 1, 0, 1, 0, 0, 0, 0, 1;
    const Eigen::Matrix3d rn = perm * r;
    P = rn * P * rn.transpose();
    V = rn * V * rn.transpose();
    vel = rn * vel;
    // "%15.9f%15.9f%11.4f"
    appendFixed(buf_, g.lat * constants::kRadToDeg, 15, 9);
    appendFixed(buf_, g.lon * constants::kRadToDeg, 15, 9);
    appendFixed(buf_, g.height, 11, 4);
  }
  // "%4d%4d%9.4f%9.4f%9.4f%9.4f%9.4f%9.4f%7.2f%7.1f"
  appendInt(buf_, static_cast<int>(s.quality), 4);
  appendInt(buf_, s.numSatellites, 4);
  for (int i = 0; i < 3; ++i) appendFixed(buf_, std::sqrt(std::max(P(i, i), 0.0)), 9, 4);
  appendFixed(buf_, signedSqrt(P(0, 1)), 9, 4);
  appendFixed(buf_, signedSqrt(P(1, 2)), 9, 4);
  appendFixed(buf_, signedSqrt(P(2, 0)), 9, 4);
  appendFixed(buf_, s.age, 7, 2);
  appendFixed(buf_, s.ratio, 7, 1);
  if (opt_.velocity) {
    if (!s.velocity) V.setConstant(kNan);
    // "%11.5f%11.5f%11.5f %9.5f%9.5f%9.5f%9.5f%9.5f%9.5f"
    for (int i = 0; i < 3; ++i) appendFixed(buf_, vel[i], 11, 5);
    buf_ += ' ';
    for (int i = 0; i < 3; ++i) appendFixed(buf_, std::sqrt(std::max(V(i, i), 0.0)), 9, 5);
    appendFixed(buf_, signedSqrt(V(0, 1)), 9, 5);
    appendFixed(buf_, signedSqrt(V(1, 2)), 9, 5);
    appendFixed(buf_, signedSqrt(V(2, 0)), 9, 5);
  }
  if (opt_.testColumn) appendInt(buf_, static_cast<int>(s.residualTest.value_or(ResidualTest::Untestable)), 5);
  buf_ += '\n';
  out_ << buf_;
}

void PosWriter::finish() {
  if (!headerDone_) writeHeader();
  out_.flush();
}

}  // namespace gvins
