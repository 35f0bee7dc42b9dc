// Zero-difference (undifferenced) model terms of one receiver epoch that differencing builds on:
// the satellite state at the signal's transmit time and the geometric range with the Earth
// rotation during the signal travel.
#pragma once

#include <optional>

#include <Eigen/Core>

#include "gvins/base/gnss_time.hpp"
#include "gvins/base/satellite.hpp"
#include "gvins/ephemeris/ephemeris_store.hpp"

namespace gvins {

/// A satellite seen by a receiver at one epoch.
struct TransmitState {
  GpsTime transmitTime;  ///< GPST of transmission
  /// Position (ECEF frame of the transmit time), velocity, clock (s, with the relativistic term,
  /// without group delays) at transmitTime.
  SatelliteState state;
};

/// Satellite state at the transmit time of a signal received at `receiveTime` (receiver time
/// tag) with pseudorange `pseudorange`: t_tx = t_rx − P/c − dt_s, which does not depend on the
/// receiver clock (it is inside P). nullopt when there is no usable (healthy, valid) record or
/// the pseudorange is implausible.
std::optional<TransmitState> satelliteAtTransmit(const EphemerisStore& nav, SatId sat, const GpsTime& receiveTime,
                                                 double pseudorange, const EphemerisSelection& policy = {});

/// Geometric range |r_s − r| plus the Sagnac term for a satellite position in the ECEF frame of
/// its transmit time and a receiver position in that of the receive time. `gradient` (optional)
/// receives ∂range/∂receiver = −los + (ω_e/c)(−y_s, x_s, 0), with los the unit vector from the
/// receiver to the satellite (the Sagnac part is a few 1e-6).
double geometricRange(const Eigen::Vector3d& satellite, const Eigen::Vector3d& receiver,
                      Eigen::Vector3d* gradient = nullptr);

}  // namespace gvins
