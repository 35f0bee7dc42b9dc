#include "gvins/gnss/pos_writer.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ostream>

#include "gvins/base/constants.hpp"
#include "gvins/base/geodetic.hpp"
#include "gvins/base/local_frame.hpp"

namespace gvins {

double signedSqrt(double c) { return c < 0.0 ? -std::sqrt(-c) : std::sqrt(c); }

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
  h += t + "\n";
  out_ << h;
}

void PosWriter::write(const PositionSolution& s) {
  if (!headerDone_) writeHeader();
  char buf[512];
  // Time rounded to the printed resolution first, so that seconds never read 60.
  const double scale = std::pow(10.0, opt_.timeDecimals);
  const double frac = std::round(s.time.fraction() * scale) / scale;
  const CalendarTime c = GpsTime::fromSeconds(s.time.wholeSeconds(), frac).toCalendar();
  const double sec = std::floor(c.second * scale + 0.5) / scale;
  std::snprintf(buf, sizeof buf, "%04d/%02d/%02d %02d:%02d:%0*.*f", c.year, c.month, c.day, c.hour, c.minute,
                opt_.timeDecimals > 0 ? opt_.timeDecimals + 3 : 2, opt_.timeDecimals, sec);
  buf_ = buf;
  const bool xyz = opt_.coordinates == PosCoordinates::Xyz;
  Eigen::Matrix3d P = s.positionCovariance;
  Eigen::Matrix3d V = s.velocityCovariance;
  Eigen::Vector3d vel = s.velocity.value_or(Eigen::Vector3d::Zero());
  if (xyz) {
    std::snprintf(buf, sizeof buf, "%15.4f%15.4f%15.4f", s.position.x(), s.position.y(), s.position.z());
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
    std::snprintf(buf, sizeof buf, "%15.9f%15.9f%11.4f", g.lat * constants::kRadToDeg, g.lon * constants::kRadToDeg,
                  g.height);
  }
  buf_ += buf;
  std::snprintf(buf, sizeof buf, "%4d%4d%9.4f%9.4f%9.4f%9.4f%9.4f%9.4f%7.2f%7.1f", static_cast<int>(s.quality),
                s.numSatellites, std::sqrt(std::max(P(0, 0), 0.0)), std::sqrt(std::max(P(1, 1), 0.0)),
                std::sqrt(std::max(P(2, 2), 0.0)), signedSqrt(P(0, 1)), signedSqrt(P(1, 2)), signedSqrt(P(2, 0)),
                s.age, s.ratio);
  buf_ += buf;
  if (opt_.velocity) {
    if (!s.velocity) V.setZero();
    std::snprintf(buf, sizeof buf, "%11.5f%11.5f%11.5f %9.5f%9.5f%9.5f%9.5f%9.5f%9.5f", vel.x(), vel.y(), vel.z(),
                  std::sqrt(std::max(V(0, 0), 0.0)), std::sqrt(std::max(V(1, 1), 0.0)),
                  std::sqrt(std::max(V(2, 2), 0.0)), signedSqrt(V(0, 1)), signedSqrt(V(1, 2)), signedSqrt(V(2, 0)));
    buf_ += buf;
  }
  buf_ += '\n';
  out_ << buf_;
}

void PosWriter::finish() {
  if (!headerDone_) writeHeader();
  out_.flush();
}

}  // namespace gvins
