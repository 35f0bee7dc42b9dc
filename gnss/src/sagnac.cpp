#include "gvins/gnss/sagnac.hpp"

#include <cmath>

#include "gvins/base/constants.hpp"

namespace gvins {

double sagnacRangeCorrection(const Eigen::Vector3d& s, const Eigen::Vector3d& r) {
  return constants::kWgs84OmegaE * (s.x() * r.y() - s.y() * r.x()) / constants::kSpeedOfLight;
}

double sagnacRangeRateCorrection(const Eigen::Vector3d& s, const Eigen::Vector3d& vs, const Eigen::Vector3d& r,
                                 const Eigen::Vector3d& vr) {
  return constants::kWgs84OmegaE * (vs.x() * r.y() + s.x() * vr.y() - vs.y() * r.x() - s.y() * vr.x()) /
         constants::kSpeedOfLight;
}

Eigen::Vector3d rotateEarth(const Eigen::Vector3d& v, double dt) {
  // A frame rotating with the Earth turns by omega*dt; a fixed vector's coordinates turn by -omega*dt.
  const double a = constants::kWgs84OmegaE * dt;
  const double c = std::cos(a), s = std::sin(a);
  return {c * v.x() + s * v.y(), -s * v.x() + c * v.y(), v.z()};
}

double shapiroDelay(const Eigen::Vector3d& sat, const Eigen::Vector3d& rx) {
  constexpr double kGm = 3.986004418e14;  // m³/s², IERS Conventions 2010 table 1.1
  const double rs = sat.norm(), rr = rx.norm(), rho = (sat - rx).norm();
  const double c = constants::kSpeedOfLight;
  return 2.0 * kGm / (c * c) * std::log((rs + rr + rho) / (rs + rr - rho));
}

}  // namespace gvins
