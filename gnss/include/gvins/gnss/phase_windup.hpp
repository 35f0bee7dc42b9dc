// Carrier-phase wind-up: the phase of a right-hand circularly polarised signal advances by one
// cycle per turn of the transmitting or the receiving antenna about the line of sight. Model of
// Wu, Wu, Hajj, Bertiger & Lichten (1993), "Effects of antenna orientation on GPS carrier phase",
// Manuscripta Geodaetica 18, 91-98 (also IERS Conventions 2010 and Kouba's "A guide to using IGS
// products"): with k the unit vector from the satellite to the receiver and each antenna's
// horizontal axes x, y (ECEF),
//
//   D_s = x_s − k (k·x_s) − k × y_s,   D_r = x_r − k (k·x_r) + k × y_r,
//   Δφ = sign(k · (D_s × D_r)) · arccos(D_s·D_r / (|D_s| |D_r|))   [rad],
//
// continued over the arc without jumps of whole cycles. Convention as in RTKLIB's PPP: the
// observed phase (cycles) contains +Δφ/2π, so the model adds it (on every frequency the same
// number of cycles; an ionosphere-free phase a1 λ1 φ1 + a2 λ2 φ2 gets (a1 λ1 + a2 λ2) cycles of
// it, c / (f1 + f2), 10.7 cm for GPS L1/L2).
//
// The satellite's axes: nominal yaw steering (gvins/ephemeris/satellite_antenna.hpp). A receiver
// antenna's x, y: for a vehicle the body axes with z the boresight; a static antenna e.g. north,
// west.
#pragma once

#include <optional>

#include <Eigen/Core>

namespace gvins {

/// Wind-up in cycles for the line of sight from `satellite` to `receiver` (ECEF, m), antenna axes
/// as the columns (x, y, z) of rotations antenna → ECEF. `previous`: the last value of the same
/// carrier arc, which the result continues (within half a cycle); nullopt at an arc start (result
/// in [−0.5, 0.5]).
double phaseWindupCycles(const Eigen::Vector3d& satellite, const Eigen::Vector3d& receiver,
                         const Eigen::Matrix3d& satelliteAxes, const Eigen::Matrix3d& receiverAxes,
                         std::optional<double> previous = std::nullopt);

/// A wind-up value (cycles) shifted by whole cycles to within half a cycle of `previous` (the last
/// value of the same arc); unchanged without one.
double continueWindup(double cycles, std::optional<double> previous);

/// Axes of a level antenna at geodetic latitude/longitude (rad): x north, y west, z up (the
/// receiver axes of RTKLIB's PPP wind-up; a vehicle's heading only adds a common term).
Eigen::Matrix3d levelAntennaAxes(double latitude, double longitude);

}  // namespace gvins
