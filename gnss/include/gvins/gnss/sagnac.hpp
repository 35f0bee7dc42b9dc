// Range corrections of signal travel in ECEF: Earth rotation (Sagnac effect) for ranges and range
// rates, and the relativistic (Shapiro) delay in the Earth's gravity field.
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

/// Relativistic signal delay (m) of the Earth's gravity field (Shapiro effect):
/// 2 GM/c² ln((r_s + r_r + ρ) / (r_s + r_r − ρ)) with ρ = |r_s − r_r| (IERS Conventions 2010,
/// eq. 11.17, Earth term only): 1.3 cm at zenith to 1.9 cm at the horizon for MEO satellites.
double shapiroDelay(const Eigen::Vector3d& sat, const Eigen::Vector3d& rx);

}  // namespace gvins
