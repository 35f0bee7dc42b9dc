#include "gvins/base/geodetic.hpp"

#include <cmath>

#include "gvins/base/constants.hpp"

namespace gvins {

using constants::kWgs84A;
using constants::kWgs84E2;

Eigen::Vector3d geodeticToEcef(const Geodetic& g) {
  const double sl = std::sin(g.lat), cl = std::cos(g.lat);
  const double n = kWgs84A / std::sqrt(1.0 - kWgs84E2 * sl * sl);
  return {(n + g.height) * cl * std::cos(g.lon), (n + g.height) * cl * std::sin(g.lon),
          (n * (1.0 - kWgs84E2) + g.height) * sl};
}

Geodetic ecefToGeodetic(const Eigen::Vector3d& r) {
  // Fixed-point iteration on z (standard textbook method, e.g. Misra & Enge, 4.A).
  const double p2 = r.x() * r.x() + r.y() * r.y();
  const double p = std::sqrt(p2);
  Geodetic g;
  if (p2 + r.z() * r.z() <= 0.0) {
    g.height = -kWgs84A;
    return g;
  }
  double z = r.z(), zk = 0.0, v = kWgs84A;
  for (int i = 0; i < 20 && std::fabs(z - zk) >= 1e-9; ++i) {
    zk = z;
    const double sinp = z / std::sqrt(p2 + z * z);
    v = kWgs84A / std::sqrt(1.0 - kWgs84E2 * sinp * sinp);
    z = r.z() + v * kWgs84E2 * sinp;
  }
  g.lat = p > 1e-12 ? std::atan(z / p) : (r.z() > 0.0 ? M_PI / 2.0 : -M_PI / 2.0);
  g.lon = p > 1e-12 ? std::atan2(r.y(), r.x()) : 0.0;
  g.height = std::sqrt(p2 + z * z) - v;
  return g;
}

Geodetic geodeticFromDegrees(double latDeg, double lonDeg, double height) {
  return {latDeg * constants::kDegToRad, lonDeg * constants::kDegToRad, height};
}

}  // namespace gvins
