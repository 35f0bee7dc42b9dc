#include "gvins/base/local_frame.hpp"

#include <algorithm>
#include <cmath>

namespace gvins {

Eigen::Matrix3d ecefToEnuRotation(double lat, double lon) {
  const double sl = std::sin(lat), cl = std::cos(lat), so = std::sin(lon), co = std::cos(lon);
  Eigen::Matrix3d r;
  r << -so, co, 0.0,            //
      -sl * co, -sl * so, cl,   //
      cl * co, cl * so, sl;
  return r;
}

Eigen::Matrix3d ecefToNedRotation(double lat, double lon) {
  const Eigen::Matrix3d enu = ecefToEnuRotation(lat, lon);
  Eigen::Matrix3d ned;
  ned.row(0) = enu.row(1);
  ned.row(1) = enu.row(0);
  ned.row(2) = -enu.row(2);
  return ned;
}

Eigen::Vector3d ecefToEnu(const Eigen::Vector3d& ecef, const Eigen::Vector3d& originEcef) {
  const Geodetic g = ecefToGeodetic(originEcef);
  return ecefToEnuRotation(g.lat, g.lon) * (ecef - originEcef);
}

Eigen::Vector3d enuToEcef(const Eigen::Vector3d& enu, const Eigen::Vector3d& originEcef) {
  const Geodetic g = ecefToGeodetic(originEcef);
  return originEcef + ecefToEnuRotation(g.lat, g.lon).transpose() * enu;
}

AzEl azimuthElevation(const Eigen::Matrix3d& ecefToEnu, const Eigen::Vector3d& rcvEcef,
                      const Eigen::Vector3d& satEcef) {
  AzEl out;
  if (rcvEcef.norm() < 1000.0) {
    out.elevation = M_PI / 2.0;
    return out;
  }
  const Eigen::Vector3d los = (satEcef - rcvEcef).normalized();
  const Eigen::Vector3d enu = ecefToEnu * los;
  out.azimuth = std::atan2(enu.x(), enu.y());
  if (out.azimuth < 0.0) out.azimuth += 2.0 * M_PI;
  out.elevation = std::asin(std::clamp(enu.z(), -1.0, 1.0));
  return out;
}

AzEl azimuthElevation(const Geodetic& rcv, const Eigen::Vector3d& rcvEcef,
                      const Eigen::Vector3d& satEcef) {
  return azimuthElevation(ecefToEnuRotation(rcv.lat, rcv.lon), rcvEcef, satEcef);
}

AzEl azimuthElevation(const Eigen::Vector3d& rcvEcef, const Eigen::Vector3d& satEcef) {
  return azimuthElevation(ecefToGeodetic(rcvEcef), rcvEcef, satEcef);
}

}  // namespace gvins
