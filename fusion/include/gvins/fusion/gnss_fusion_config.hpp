// Configuration of the GNSS fusion (GnssFusion) and its YAML form.
//
//   gnss_fusion:
//     mode: vio+dopp+psr        # vio | vio+gpsvel | vio+dopp | vio+dopp+psr | vio+dopp+dpsr |
//                               # vio+dopp+ddcp | vio+dopp+psr-nointegration | vio+dopp+ppp
//     lever_arm: [0.0, 0.0, 0.1]          # ^I p_r, m (initial value)
//     calibrate_lever_arm: true
//     lever_arm_sigma: 0.2                # m, prior 1-sigma per axis when calibrated
//     min_rotation_rate: 0.3              # rad/s: lever-arm Jacobian used by Doppler rows above it
//     systems: GREJ                       # RINEX letters of the constellations used
//     elevation_mask_deg: 15              # deg (RTKLIB's and gvins-spp's default too)
//     ionosphere: dual-frequency          # psr rows: ionosphere-free code where a second band
//                                         # exists (else broadcast), or broadcast (Klobuchar)
//     bands: {G: "125"}                   # per system: bands tried in order for the second signal of
//                                         # the ionosphere-free pair (the primary band is skipped,
//                                         # GPS/QZSS L2 P(Y) after the others; default: the SPP's,
//                                         # QZSS "152")
//     ephemeris_error_m: {G: 0.6, R: 5}   # per system: broadcast orbit/clock error (SISRE) added to
//                                         # the psr variance (default: the SPP's ephemeris_error_m)
//     precise_ephemeris_error_m: {G: 0.05} # the same for satellites from precise products (SP3/clock;
//                                         # default: the SPP's precise_ephemeris_error_m)
//     code_sigma: 0.6                     # m at zenith; variance (a² + a²/sin²(el)) style
//     carrier_smoothing: 100              # s, Hatch window of the psr/dpsr/ddcp codes (default; 0 = raw;
//                                         # vio+dopp+ppp and ddcp's RTK module use raw codes)
//     smoothed_code_factor: 1.0           # floor of the smoothed code's sigma / code_sigma
//     phase_sigma: 0.003                  # m at zenith, one band (vio+dopp+ppp; ×2.6–3 for the pair)
//     ambiguity_sigma: 30                 # m, prior 1-sigma of a new float ambiguity (vio+dopp+ppp)
//     ambiguity_reset_rejections: 3       # consecutive gated-out phase rows that restart an ambiguity
//     max_ambiguities: 0                  # ambiguity states at most, highest satellites first (0: all)
//     phase_windup: true                  # correct the phases for wind-up (vio+dopp+ppp)
//     rtk_hold_fix: true                  # vio+dopp+ddcp: once fixed, the RTK module runs at the base
//                                         # epochs only and its fix is held in between (false: every epoch)
//     rtk_revalidate_interval: 10         # s; held and no new DD phase: the module runs only this often
//     broadcast_ambiguity_random_walk: 0.005  # m/√s on ambiguities of broadcast-orbit satellites
//     broadcast_record_changes: true      # carry the modelled-range jump of a new broadcast record over
//     estimate_zwd: true                  # zenith wet delay residual as a state (default: vio+dopp+ppp only)
//     zwd_sigma: 0.05                     # m, its prior 1-sigma (about the model's zenith wet delay)
//     zwd_random_walk: 0.0002             # m/√s
//     doppler_sigma: 0.1                  # m/s at zenith
//     clock_bias_random_walk: 0.1         # m/√s, the receiver clock
//     isb_random_walk: 0.001              # m/√s, the inter-system biases (0: constant)
//     isb_renewal_interval: 30            # s between the inter-system biases' random-walk steps
//     clock_drift_random_walk: 0.5        # m/s/√s
//     row_gate: 0.999                     # chi-square probability per measurement row
//     epoch_gate: 0.99999                 # chi-square probability of the stacked rows
//     frame_yaw_sigma_deg: 3              # convergence threshold σ_θ
//     frame_min_speed: 1.0                # m/s before the yaw guess from velocity headings
//     frame_start_at_rest: true           # start the frame below frame_min_speed, the yaw a nuisance
//     ins_start: true                     # start the estimator from GNSS/INS when vision has not
//     ins_start_window: 5                 # s of SPP/Doppler epochs the alignment uses at most
//     ins_start_yaw_sigma_deg: 10         # accepted below this yaw σ, the filter's prior (gnss_ins_alignment.hpp)
//     frame_reanchor: true                # once converged re-express the VIO state in ENU and
//                                         # marginalize the frame block (false: keep it as a state)
//     frame_reanchor_position_sigma: 0.5  # m, ... once the IMU's ENU position σ is below this
//     frame_reanchor_yaw_sigma_deg: 0.3   # ... and, after a start at rest, the heading σ below this
//     outage_reset: 60                    # s without GNSS update: clocks/ambiguities reset
//     reacquire_after: 2                  # s with every row gated out, or without update: re-acquisition (0: never)
//     reacquire_acceleration: 0.3         # m/s², unmodelled acceleration that widens its gate with time
//     late_system_min_satellites: 2       # satellites of a system first seen after the clocks started
//     clock_ransac_threshold: 5.0         # m (pseudorange) for the clock RANSAC
//     base_position: [x, y, z]            # ECEF of the base antenna (dpsr/ddcp)
//     max_base_age: 2.0                   # s
// Every key is optional. Errors are gvins::ParseError with file, line and field.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <string_view>

#include <Eigen/Core>

#include "gvins/base/satellite.hpp"
#include "gvins/gnss/spp_config.hpp"

namespace gvins::fusion {

enum class GnssFusionMode : std::uint8_t {
  kVio,           ///< no GNSS
  kGpsVel,        ///< loosely-coupled SPP Doppler velocity
  kDopp,          ///< Doppler
  kDoppPsr,       ///< Doppler + pseudorange
  kDoppDpsr,      ///< Doppler + single-differenced pseudorange
  kDoppDdcp,      ///< Doppler + SD pseudorange + double-differenced carrier phase (fixed)
  kDoppPsrNoInt,  ///< as kDoppPsr without IMU integration to the measurement time (ablation)
  /// Doppler + raw ionosphere-free pseudorange + undifferenced ionosphere-free carrier phase with
  /// one float ambiguity state per satellite arc: float PPP with precise products or SSR.
  kDoppPpp,
};
const char* toString(GnssFusionMode m);
std::optional<GnssFusionMode> gnssFusionModeFromString(std::string_view s);

/// Ionosphere of the undifferenced pseudorange rows.
enum class GnssIonosphere : std::uint8_t {
  kBroadcast,      ///< Klobuchar (GPS; BeiDou's own for BeiDou) on the primary band
  kDualFrequency,  ///< ionosphere-free pair where a second band exists, else kBroadcast
};

/// Weighting of the code rows (psr, dpsr).
enum class GnssCodeWeighting : std::uint8_t {
  kElevation,     ///< sigma^2 = code_sigma^2 (0.5 + 0.5 / sin^2 el)
  /// The elevation + C/N0 model of gvins/gnss/measurement_weighting.hpp (ElevationSnr): the
  /// elevation-independent half scaled by 10^((45 - C/N0) / 10); without C/N0, kElevation.
  kElevationCn0,
};

struct GnssFusionConfig {
  GnssFusionMode mode = GnssFusionMode::kDoppPsr;
  Eigen::Vector3d leverArm = Eigen::Vector3d::Zero();
  bool leverArmGiven = false;  ///< set by the parser when the file has `lever_arm`
  bool calibrateLeverArm = false;
  double leverArmSigma = 0.2;
  double minRotationRate = 0.3;
  std::array<bool, kNumSystems> systems{true, true, true, true, true, false, false};
  double elevationMaskDeg = 15.0;
  GnssIonosphere ionosphere = GnssIonosphere::kDualFrequency;
  /// Band order per system (index systemIndex): the ionosphere-free pair takes the first tracked
  /// band of this list other than the primary band (secondCode: GPS/QZSS L2 P(Y) after the other
  /// bands). Default: the SPP's (GPS L2C, then L5, then L2 P(Y): why in
  /// satellite_observation_model.hpp), except QZSS L5 before L2: its L5 offsets without CNAV's
  /// ISC are not measured on a real receiver here, and on the simulated flights (no ISC modelled)
  /// L1/L2C only adds noise against L1/L5 (the simulated L5 code is the wideband, quieter one).
  std::array<std::string, kNumSystems> bands = defaultBands();
  static std::array<std::string, kNumSystems> defaultBands() {
    std::array<std::string, kNumSystems> b = SppConfig{}.bands;
    b[static_cast<std::size_t>(systemIndex(System::Qzss))] = "152";
    return b;
  }
  /// Broadcast orbit/clock error per system, m, added in quadrature to the psr sigma. Default:
  /// the SPP's error budget (SppConfig::ephemerisError: GPS 0.6, GLONASS 5 with its FDMA code
  /// biases, Galileo 0.3, BeiDou 1.0, QZSS 0.6 m).
  std::array<double, kNumSystems> ephemerisError = SppConfig{}.ephemerisError;
  /// The same for satellites whose orbit and clock come from precise products or SSR corrections
  /// (SppConfig::preciseEphemerisError: GPS/Galileo 5 cm; GLONASS 5 m for its FDMA code biases).
  std::array<double, kNumSystems> preciseEphemerisError = SppConfig{}.preciseEphemerisError;

  double codeSigma = 0.6;
  /// `code_weighting`: elevation or elevation-cn0 (GnssCodeWeighting). An ionosphere-free pair
  /// takes the lower C/N0 of its two bands; a single difference adds the rover's and the base's
  /// variances, each with its own C/N0.
  GnssCodeWeighting codeWeighting = GnssCodeWeighting::kElevation;
  /// `cn0_mask_dbhz`: code rows (psr, dpsr) of signals with a C/N0 below this are dropped
  /// (counted as GnssTypeCount::masked); 0 = off. An ionosphere-free pair: its lower C/N0.
  double cn0MaskDbHz = 0.0;
  /// Carrier smoothing of the pseudoranges (psr modes; dpsr and ddcp: rover and base of the SD
  /// code rows; ddcp's RTK module keeps raw codes): Hatch window in s, 0 = raw codes
  /// (CarrierSmoother). 100 s as in RTCA DO-229E; the
  /// ionosphere-free pair of smoothed codes has no ionospheric divergence, a single-frequency one
  /// lags by about 2 T dI/dt.
  double carrierSmoothing = 100.0;
  /// Floor of the smoothed code's sigma relative to codeSigma: the smoothing averages white noise
  /// by up to sqrt(2T/Δt − 1), but multipath correlated over tens of seconds much less.
  double smoothedCodeFactor = 1.0;
  /// vio+dopp+ppp: carrier-phase sigma at zenith for one band (m), weighted like the code and
  /// multiplied by the ionosphere-free pair's noise factor.
  double phaseSigma = 0.003;
  /// vio+dopp+ppp: prior sigma of a new ambiguity state (m), centred on phase minus code.
  double ambiguitySigma = 30.0;
  /// vio+dopp+ppp: after this many consecutive epochs with the satellite's phase row gated out,
  /// its ambiguity is marginalized and restarted (an undetected slip, a broadcast orbit change).
  int ambiguityResetRejections = 3;
  /// vio+dopp+ppp: at most this many ambiguity states (each is a state column that every visual
  /// update also carries); satellites above the mask are taken highest first, and a satellite
  /// keeps its state while it has one. 0: no limit.
  int maxAmbiguities = 0;
  /// vio+dopp+ppp: phase wind-up correction (Wu et al. 1993; satellites in nominal yaw steering,
  /// the receiver antenna taken level with x north: a vehicle's heading turns wind every
  /// satellite up alike, which the clock absorbs, and its tilts change the differences by
  /// millimetres; tests/gnss/test_phase_windup.cpp).
  bool phaseWindup = true;
  /// vio+dopp+ddcp: while the RTK module is fixed it runs at the base epochs only (there the base
  /// is measured, not extrapolated) and the DD phases in between take the fix it held
  /// (RtkSolver::differencesWithHeldFix, same arcs only). false: the module runs every epoch.
  bool rtkHoldFix = true;
  /// With rtkHoldFix: a new base epoch less than this many seconds after the module's last run
  /// takes the held fix as well when its DD phases are that run's (same satellites, references
  /// and arcs); the module runs again when they differ or when this interval has passed (0: at
  /// every base epoch, as before 6 Dec 2026).
  double rtkRevalidateInterval = 10.0;
  /// vio+dopp+ppp: random walk (m/√s) of the ambiguity states of satellites on broadcast orbits
  /// and clocks (no products, no SSR), whose errors drift by centimetres per minute as the true
  /// orbit departs from the record; 0: constant ambiguities.
  double broadcastAmbiguityRandomWalk = 0.005;
  /// vio+dopp+ppp: when a satellite on broadcast orbits and clocks switches to another record, the
  /// jump of its modelled range ρ − c·dt_s (both records at the same transmit time;
  /// gvins/gnss/broadcast_record_change.hpp) is added to its phase, so that its ambiguity state
  /// keeps fitting instead of being off by the difference of the records' errors.
  bool broadcastRecordChanges = true;
  /// Zenith wet delay residual (about the Saastamoinen/Niell model) as a random-walk state,
  /// ∂T/∂ZWD = the wet mapping function. Unset: estimated in vio+dopp+ppp only, where the float
  /// ambiguities let an unmodelled ZWD change with the satellites' elevations map into height.
  std::optional<bool> estimateZwd;
  double zwdSigma = 0.05;
  double zwdRandomWalk = 2e-4;
  bool zwdState() const { return estimateZwd.value_or(mode == GnssFusionMode::kDoppPpp) && usesPseudorange(); }
  double dopplerSigma = 0.1;
  double clockBiasRandomWalk = 0.1;
  double clockDriftRandomWalk = 0.5;
  /// Inter-system biases (receiver hardware delays, which drift slowly with temperature): a random
  /// walk of this strength (m/√s; 0 = constant), applied as one step of the accumulated variance
  /// q²·Δt every isbRenewalInterval seconds rather than at every epoch, so that their columns are
  /// swept past the state rarely (the same variance at the step instants; between steps the block
  /// is held constant).
  double isbRandomWalk = 0.001;
  double isbRenewalInterval = 30.0;
  /// A system first seen after the clocks started (its ephemerides arrived later) joins the clock
  /// state once this many of its satellites have a model (GnssFusion::addLateClockSystems).
  int lateSystemMinSatellites = 2;
  /// Tight stage: after every epoch's rows were gated out, or no update was applied, for
  /// reacquireAfter seconds, the rows go through the re-acquisition gate (gnss_gate_recovery.hpp):
  /// the predicted innovation covariance widened as by an unmodelled acceleration
  /// reacquireAcceleration (m/s²) since the last update, and a consensus of the satellites.
  /// reacquireAfter <= 0: never.
  double reacquireAfter = 2.0;
  double reacquireAcceleration = 0.3;
  double rowGate = 0.999;
  double epochGate = 0.99999;
  double frameYawSigmaDeg = 3.0;
  double frameMinSpeed = 1.0;
  /// Start the frame at the first SPP fix with Doppler also when the antenna or the IMU moves
  /// horizontally slower than frameMinSpeed (a take-off climbing vertically, a vehicle at rest):
  /// the yaw is then a nuisance of its wide prior (σ π/√3, the circle's) that no row informs,
  /// until both speeds pass frameMinSpeed and the headings give its first value; position, clocks
  /// and the vertical start at once (docs/gnss_fusion.md "Stages"). false: the frame waits for
  /// that speed.
  bool frameStartAtRest = true;
  /// Start the estimator from a GNSS/INS alignment (gnss_ins_alignment.hpp) when it has not
  /// initialised from vision: SPP positions and Doppler velocities over at most insStartWindow
  /// s, accepted when the yaw σ is below insStartYawSigmaDeg; the estimator then runs in ENU and
  /// the tight rows start at once (no frame initialisation), the alignment's attitude covariance
  /// its prior: the filter converges the yaw from the GNSS velocity against the visual-inertial
  /// motion (10°: docs/gnss_fusion.md "Starting from GNSS/INS"). false: GNSS waits for the VIO.
  bool insStart = true;
  double insStartWindow = 5.0;
  double insStartYawSigmaDeg = 10.0;
  /// After convergence the estimator re-expresses its state in local ENU (EstimatorBackend::
  /// reanchorWorld) and the frame block is marginalized, so the GNSS rows no longer carry its 4
  /// columns; false keeps it as a state (as before 6 Dec 2026; the same estimate to first order).
  bool frameReanchor = true;
  /// ... once, in the tight stage, the σ of the IMU's ENU position (every axis, from the newest
  /// pose and the frame) is below this too (m): the raw rows first correct the SPP-level position
  /// of the initialisation.
  double frameReanchorPositionSigma = 0.5;
  /// After a start at rest (frameStartAtRest) the position is known before the heading: the move
  /// waits for the heading σ below this (deg) instead of frameYawSigmaDeg, since the local
  /// outputs keep the frame of the move and its heading error with it.
  double frameReanchorYawSigmaDeg = 0.3;
  double outageReset = 60.0;
  double clockRansacThreshold = 5.0;
  std::optional<Eigen::Vector3d> basePosition;
  double maxBaseAge = 2.0;

  bool useSystem(System s) const { return systems[static_cast<std::size_t>(systemIndex(s))]; }
  bool usesDoppler() const;
  bool usesPseudorange() const;
  bool usesDifferences() const;
  bool integration() const { return mode != GnssFusionMode::kDoppPsrNoInt; }
};

/// Reads the `gnss_fusion` mapping of a YAML document (or the top-level mapping when there is no
/// such key). `file` names the source in errors. Throws gvins::ParseError.
GnssFusionConfig parseGnssFusionConfig(std::string_view yaml, const std::string& file = "<string>");
GnssFusionConfig loadGnssFusionConfig(const std::string& path);

}  // namespace gvins::fusion
