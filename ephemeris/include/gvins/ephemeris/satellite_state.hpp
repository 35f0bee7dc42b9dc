// Satellite position, velocity, clock bias and drift from a broadcast ephemeris at a transmit time.
#pragma once

#include <Eigen/Core>

#include "gvins/base/gnss_time.hpp"
#include "gvins/base/signal.hpp"
#include "gvins/ephemeris/cnav_group_delays.hpp"
#include "gvins/ephemeris/glonass_ephemeris.hpp"
#include "gvins/ephemeris/kepler_ephemeris.hpp"

namespace gvins {

/// State of a satellite at signal transmit time t (GPST), in the ECEF frame *at time t*
/// (the caller applies the Earth-rotation/Sagnac correction for the signal travel time).
struct SatelliteState {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< m (WGS 84 / the system's ECEF frame)
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  ///< m/s, ECEF-rate (analytic)
  /// Satellite clock offset, s, including the relativistic eccentricity correction and
  /// without group delays: satellite time - system time.
  double clockBias = 0.0;
  double clockDrift = 0.0;  ///< s/s (analytic, including the relativistic term's rate)
  double accuracy = 0.0;    ///< broadcast URA/SISA/FT in m (0 = unknown)
  int iode = 0;             ///< issue of data of the record used
  bool healthy = true;
  /// From precise products (SP3/RINEX clock; gvins/ephemeris/precise_ephemeris.hpp), not from a
  /// broadcast record.
  bool precise = false;
  /// A broadcast state corrected by SSR (gvins/ephemeris/ssr_corrections.hpp).
  bool ssr = false;
};

/// Keplerian orbit (IS-GPS-200 table 20-IV; Galileo OS SIS ICD 5.1.1; BeiDou GEO rotation per
/// BDS-SIS-ICD B1I 5.2.4.12) and clock polynomial with relativistic correction.
SatelliteState keplerSatelliteState(const KeplerEphemeris& eph, const GpsTime& t);

/// GLONASS: RK4 integration of the PZ-90 equations of motion from tb to t (GLONASS ICD 5.1,
/// appendix A.3.1.2), clock -tauN + gammaN (t - tb).
SatelliteState glonassSatelliteState(const GlonassEphemeris& eph, const GpsTime& t);

/// Default longest RK4 step for GLONASS, s. With 30 s steps the integration error over +-30 min is
/// below 0.1 mm in position (halving the step changes the result by less than that).
inline constexpr double kGlonassDefaultStep = 30.0;
/// As glonassSatelliteState with a chosen longest step (equal steps of at most maxStep seconds).
SatelliteState glonassSatelliteState(const GlonassEphemeris& eph, const GpsTime& t, double maxStep);

/// Broadcast group delay to subtract from SatelliteState::clockBias for a pseudorange on `code`,
/// in seconds: GPS/QZSS L1 TGD, L2 gamma*TGD (IS-GPS-200 20.3.3.3.3.2), L5 TGD; with `cnav` (CNAV
/// message type 30 of the same satellite) L1 C/A, L2C and L5 I5/Q5 TGD − ISC of the signal
/// (IS-GPS-200 30.3.3.3.1.1, IS-GPS-705 20.3.3.3.1.2); Galileo
/// BGD(E1,E5a) for F/NAV, BGD(E1,E5b) for I/NAV scaled per band (OS SIS ICD 5.1.5); BeiDou TGD1
/// for B1I, TGD2 for B2I, 0 for B3I (BDS-SIS-ICD B1I 5.2.4.10). 0 where the record carries none.
double broadcastGroupDelay(const KeplerEphemeris& eph, ObsCode code, const CnavGroupDelays* cnav = nullptr);

/// GLONASS: 0 for G1 (tauN refers to L1), deltaTauN for G2 (GLONASS ICD 5.1, 4.4: the L2 signal
/// leaves the satellite deltaTauN after the L1 signal of the same epoch); 0 for other bands.
double broadcastGroupDelay(const GlonassEphemeris& eph, ObsCode code);

}  // namespace gvins
