// Earth rotation during signal travel (Sagnac effect) for ranges and range rates in ECEF.
#pragma once

#include <Eigen/Core>

namespace gvins {

/// Range correction (m) to add to |r_sat - r_rx| when the satellite position is given in the ECEF
/// frame of the transmit time and the receiver in that of the receive time:
/// omega_e (x_s y_r - y_s x_r) / c (e.g. IS-GPS-200N 20.3.3.4.3.4 rotation, first order).
double sagnacRangeCorrection(const Eigen::Vector3d& sat, const Eigen::Vector3d& rx);

/// Time derivative of sagnacRangeCorrection for satellite/receiver velocities (m/s):
/// omega_e (vx_s y_r + x_s vy_r - vy_s x_r - y_s vx_r) / c.
double sagnacRangeRateCorrection(const Eigen::Vector3d& sat, const Eigen::Vector3d& satVel,
                                 const Eigen::Vector3d& rx, const Eigen::Vector3d& rxVel);

/// Rotates an ECEF vector given at time t into the ECEF frame of time t + dt (Earth rotation by
/// omega_e dt about z).
Eigen::Vector3d rotateEarth(const Eigen::Vector3d& v, double dt);

}  // namespace gvins
