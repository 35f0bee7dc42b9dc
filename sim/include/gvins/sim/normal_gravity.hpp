// WGS 84 normal gravity (gravitation plus the centrifugal acceleration of the Earth's rotation)
// at a geodetic position: Somigliana's closed formula on the ellipsoid and the second-order
// height expansion of NIMA TR8350.2 (3rd ed., 2000), eqs. (4-1) and (4-3):
//   gamma_0 = gamma_e (1 + k sin^2 phi) / sqrt(1 - e^2 sin^2 phi)
//   gamma_h = gamma_0 [1 - 2/a (1 + f + m - 2 f sin^2 phi) h + 3 h^2 / a^2]
// with gamma_e = 9.7803253359 m/s^2, k = 0.00193185265241, m = 0.00344978650684.
// The direction is along the ellipsoid normal (deflection of the vertical neglected).
#pragma once

#include <Eigen/Core>

#include "gvins/base/geodetic.hpp"

namespace gvins::sim {

/// Magnitude of normal gravity (m/s^2) at geodetic latitude/height.
double normalGravity(const Geodetic& g);
/// Normal gravity vector in ECEF (pointing down along the ellipsoid normal).
Eigen::Vector3d normalGravityEcef(const Geodetic& g);

}  // namespace gvins::sim
