// Zero-difference (undifferenced) model terms of one receiver epoch that differencing builds on:
// the satellite state at the signal's transmit time and the geometric range with the Earth
// rotation during the signal travel.
#pragma once

#include <optional>

#include <Eigen/Core>

#include "gvins/base/gnss_time.hpp"
#include "gvins/base/satellite.hpp"
#include "gvins/ephemeris/ephemeris_cache.hpp"
#include "gvins/ephemeris/ephemeris_store.hpp"

namespace gvins {

/// A satellite seen by a receiver at one epoch.
struct TransmitState {
  GpsTime transmitTime;  ///< GPST of transmission
  /// Position (ECEF frame of the transmit time), velocity, clock (s, with the relativistic term,
  /// without group delays) at transmitTime.
  SatelliteState state;
  /// The broadcast record selected (one of the two is set): the transmit time's clock, the health
  /// and the broadcast group delays come from it also when precise or SSR states replace it.
  const KeplerEphemeris* kepler = nullptr;
  const GlonassEphemeris* glonass = nullptr;
};

/// Satellite state at the transmit time of a signal received at `receiveTime` (receiver time
/// tag) with pseudorange `pseudorange`: t_tx = t_rx − P/c − dt_s, which does not depend on the
/// receiver clock (it is inside P). The one satellite-source choice of every user:
/// - the broadcast record of the satellite at t_rx − P/c (`cache`, when given, makes the same
///   choice as the store, faster); its clock gives dt_s and the state is moved by −dt_s to first
///   order (|dt_s| < 1 ms: the orbital acceleration adds < 1 µm), or evaluated again for an
///   implausibly large clock;
/// - precise products (SP3/RINEX clock) that cover the satellite replace the orbit and clock at
///   t_tx (within a few ns, < 0.1 mm of satellite motion, of the precise clock's t_tx);
/// - else SSR corrections of the record the correction names (real-time streams); a satellite of
///   a system the stream covers but without its own correction is left out (its broadcast clock
///   is in another datum);
/// - the broadcast health applies to all three.
/// nullopt when there is no record, an unhealthy one (unless the policy allows it), an invalid
/// state or an implausible pseudorange (outside 1e6..1e8 m).
std::optional<TransmitState> satelliteAtTransmit(const EphemerisStore& nav, SatId sat, const GpsTime& receiveTime,
                                                 double pseudorange, const EphemerisSelection& policy = {},
                                                 EphemerisCache* cache = nullptr);

/// Group delay (s) of a code of the satellite of `tx`: the precise code bias (OSB) that goes with
/// precise clocks or the SSR code bias that goes with SSR clocks (EphemerisStore::preciseCodeBias),
/// else the broadcast group delay of the record of `tx` (GPS/QZSS: with the store's CNAV
/// inter-signal corrections at the transmit time, EphemerisStore::cnavGroupDelays).
double transmitGroupDelay(const EphemerisStore& nav, const TransmitState& tx, SatId sat, ObsCode code);

/// Geometric range |r_s − r| plus the Sagnac term for a satellite position in the ECEF frame of
/// its transmit time and a receiver position in that of the receive time. `gradient` (optional)
/// receives ∂range/∂receiver = −los + (ω_e/c)(−y_s, x_s, 0), with los the unit vector from the
/// receiver to the satellite (the Sagnac part is a few 1e-6).
double geometricRange(const Eigen::Vector3d& satellite, const Eigen::Vector3d& receiver,
                      Eigen::Vector3d* gradient = nullptr);

}  // namespace gvins
