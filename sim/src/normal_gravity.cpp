#include "gvins/sim/normal_gravity.hpp"

#include <cmath>

#include "gvins/base/constants.hpp"

namespace gvins::sim {

double normalGravity(const Geodetic& g) {
  // NIMA TR8350.2, Table 3.4 / eqs. (4-1), (4-3).
  constexpr double kGammaE = 9.7803253359;
  constexpr double kK = 0.00193185265241;
  constexpr double kM = 0.00344978650684;
  const double s2 = std::sin(g.lat) * std::sin(g.lat);
  const double gamma0 = kGammaE * (1.0 + kK * s2) / std::sqrt(1.0 - constants::kWgs84E2 * s2);
  const double h = g.height;
  return gamma0 * (1.0 - 2.0 / constants::kWgs84A * (1.0 + constants::kWgs84F + kM - 2.0 * constants::kWgs84F * s2) * h + 3.0 * h * h / (constants::kWgs84A * constants::kWgs84A));
}

Eigen::Vector3d normalGravityEcef(const Geodetic& g) {
  const Eigen::Vector3d up(std::cos(g.lat) * std::cos(g.lon), std::cos(g.lat) * std::sin(g.lon), std::sin(g.lat));
  return -normalGravity(g) * up;
}

}  // namespace gvins::sim
