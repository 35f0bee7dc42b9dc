// The per-satellite observation model that SPP, the double differences (RTK), the base station
// and the fusion share: the receiver-dependent parts computed once per receiver position and
// epoch (geodetic position, local frame, zenith tropospheric delays and mapping coefficients),
// and one function, SatelliteObservationModel::terms, that gives a satellite's azimuth/elevation,
// slant troposphere, broadcast ionosphere, Shapiro delay and phase wind-up, each only when the caller asks for
// it. The choice of the code signals of the ionosphere-free pair is here as well, so that every
// user pairs bands the same way (the coefficients: ionosphere_free.hpp).
//
// The satellite side (transmit time, state from broadcast, precise or SSR sources) is
// satelliteAtTransmit (zero_difference.hpp); the weights stay with each user, whose options
// (SPP's weighting scheme, RTK's phase sigmas, the fusion's code sigma) differ by design.
#pragma once

#include <cstddef>
#include <optional>
#include <string>

#include <Eigen/Core>

#include "gvins/base/geodetic.hpp"
#include "gvins/base/gnss_time.hpp"
#include "gvins/base/local_frame.hpp"
#include "gvins/base/observation.hpp"
#include "gvins/base/satellite.hpp"
#include "gvins/ephemeris/ionosphere_parameters.hpp"
#include "gvins/gnss/ionosphere_free.hpp"
#include "gvins/gnss/troposphere.hpp"

namespace gvins {

/// Which terms a user wants, with their options.
struct ObservationModelOptions {
  TroposphereMeteo troposphere = TroposphereMeteo::StandardAtmosphere;
  double relativeHumidity = 0.5;    ///< StandardAtmosphere
  bool broadcastIonosphere = false;  ///< the broadcast (Klobuchar) model of the nav data
  bool shapiro = false;             ///< relativistic delay (sagnac.hpp shapiroDelay)
};

/// Broadcast ionospheric group delay of one line of sight on one frequency.
struct IonosphereDelay {
  double slant = 0.0;  ///< m (0 when no model applies)
  /// Partial of the slant delay with respect to a zenith L1 delay: the GPS obliquity factor
  /// scaled to the frequency (SPP's zenith ionosphere unknown).
  double mapL1 = 0.0;
};

/// The broadcast ionosphere model for a satellite of `system` seen on `frequency` (Hz):
/// BeiDou with BeiDou parameters uses BeiDou's own model (BDS-SIS-ICD-B1I 3.0, 5.2.4.7, on B1I);
/// every other line of sight uses the GPS Klobuchar algorithm (IS-GPS-200N 20.3.3.5.2.5, on L1)
/// with one parameter set for all satellites: GPS's when broadcast, else QZSS's. The QZSS
/// L1C/A parameters are the same algorithm's coefficients fitted to the region around Japan
/// (IS-QZSS-PNT); they describe the ionosphere along the receiver's lines of sight, not a
/// property of the transmitting satellite, so a QZSS satellite is not given another parameter
/// set than the GPS satellite beside it.
IonosphereDelay broadcastIonosphereDelay(const IonosphereParameters& parameters, System system,
                                         const Geodetic& receiver, const AzEl& azel, const GpsTime& t,
                                         double frequency);

/// Model terms of one satellite.
struct SatelliteModelTerms {
  AzEl azel{0.0, 0.0};
  TroposphereDelay troposphere;  ///< slant 0 unless asked for and valid
  IonosphereDelay ionosphere;    ///< slant 0 unless asked for
  double shapiro = 0.0;          ///< m, when asked for
};

/// The receiver-dependent part of the model for one receiver position and epoch, and the one
/// per-satellite function every user calls.
class SatelliteObservationModel {
 public:
  /// `receiver`: ECEF (m). `ionosphere` must outlive this object when broadcastIonosphere is set.
  SatelliteObservationModel(const Eigen::Vector3d& receiver, const GpsTime& t, const ObservationModelOptions& options,
                            const IonosphereParameters* ionosphere = nullptr);

  const Geodetic& geodetic() const { return geodetic_; }
  const Eigen::Matrix3d& ecefToEnu() const { return enu_; }
  const StationTroposphere& troposphere() const { return troposphere_; }
  double dayOfYear() const { return doy_; }

  /// Azimuth/elevation of a satellite (ECEF position) from the receiver.
  AzEl azimuthElevation(const Eigen::Vector3d& satellite) const;

  /// The terms of a satellite at `satellite` (ECEF of its transmit time) of `system`, observed on
  /// `frequency` (Hz; only the ionosphere uses it, 0 for an ionosphere-free combination: no
  /// ionosphere term): az/el always, troposphere / broadcast ionosphere / Shapiro as the options
  /// ask. No tropospheric delay at or below the horizon.
  SatelliteModelTerms terms(const Eigen::Vector3d& satellite, System system, double frequency) const;
  /// The same for a known az/el (no recomputation).
  SatelliteModelTerms terms(const Eigen::Vector3d& satellite, const AzEl& azel, System system, double frequency) const;
  /// Carrier-phase wind-up (cycles, not continued across epochs: phase_windup.hpp continueWindup)
  /// of a yaw-steered satellite (the Sun once per model) for a level receiver antenna with x
  /// north and y west (its heading is common to all satellites).
  double phaseWindup(const Eigen::Vector3d& satellite) const;
  /// The broadcast ionosphere term alone (zero when the options do not ask for it).
  IonosphereDelay ionosphere(System system, const AzEl& azel, double frequency) const;

 private:
  ObservationModelOptions options_;
  const IonosphereParameters* ionosphere_ = nullptr;
  Eigen::Vector3d receiver_;
  GpsTime time_;
  Geodetic geodetic_;
  Eigen::Matrix3d enu_;
  double doy_ = 0.0;
  StationTroposphere troposphere_;
  mutable std::optional<Eigen::Vector3d> sun_;  // ECEF, on first use (phaseWindup)
};

/// A code signal usable for positioning: a pseudorange in 1e6..1e8 m and a known frequency.
struct CodeSignal {
  const SignalObs* signal = nullptr;
  double frequency = 0.0;  ///< Hz
};

/// Whether `code` is the GPS/QZSS L2 P(Y) code (RINEX attributes D, P, W, Y, M, N), which civil
/// receivers track semi-codelessly, unlike L2C (S, L, X).
bool semiCodelessL2(System sys, ObsCode code);

/// The best code signal on a band (SatObs::bestOnBand) when it is usable, else nullopt.
std::optional<CodeSignal> usableCode(const SatObs& so, char band, std::optional<int> glonassChannel);

/// The second band of an ionosphere-free pair: the first of `bands[0 .. count)` other than
/// `firstBand` with a usable code, except that a GPS/QZSS L2 P(Y) code (semiCodelessL2) comes
/// after the other bands of that range. SPP (whose first band is the first usable one of the same
/// list) and the fusion (whose first band is the system's primary band) pair alike through it.
///
/// Why GPS/QZSS L2 comes before L5 (the default lists "125") but L2 P(Y) after it: the LNAV
/// clock refers to the L1/L2 P(Y) ionosphere-free combination, so an L1/L2 pair (L2C shares the
/// L2 P(Y) path up to CNAV's ISC_L2C) needs no group delay, while an L1/L5 pair needs
/// T_GD − ISC_L5-terms (IS-GPS-705J 20.3.3.3.1.2.3) whose ISCs only CNAV carries: without them
/// each satellite keeps its own L5 hardware offset, metres on real satellites (the real walk of
/// docs/gnss_fusion.md: the L1/L5 minus L1/L2C pair spreads by 4 m across four satellites).
/// L2 P(Y), tracked semi-codelessly with a much higher noise, is paired only without L5.
std::optional<CodeSignal> secondCode(const SatObs& so, const std::string& bands, std::size_t count, char firstBand,
                                     std::optional<int> glonassChannel);

}  // namespace gvins
