// Options of relative positioning (RTK) and their YAML form.
#pragma once

#include <array>
#include <string>
#include <string_view>

#include "gvins/base/constants.hpp"
#include "gvins/base/enum_names.hpp"
#include "gvins/base/satellite.hpp"
#include "gvins/gnss/ambiguity_resolution.hpp"
#include "gvins/gnss/cycle_slip_detector.hpp"
#include "gvins/gnss/measurement_weighting.hpp"

namespace gvins {

enum class RtkMode {
  Static,     ///< the rover does not move: one position for the whole session
  Kinematic,  ///< the rover moves: position follows `dynamics`
};

enum class RtkDynamics {
  RandomWalk,        ///< position random walk (predicted with the Doppler velocity when available)
  ConstantVelocity,  ///< position and velocity states, white-noise acceleration
};

enum class AmbiguityMode {
  Off,            ///< float solution only
  Continuous,     ///< ambiguities kept from epoch to epoch, resolved every epoch, never fed back
  Instantaneous,  ///< every epoch on its own (single-epoch RTK)
  FixAndHold,     ///< as Continuous, and validated fixes constrain the float ambiguities
};

inline constexpr EnumName<RtkMode> kRtkModeNames[] = {{RtkMode::Static, "static"}, {RtkMode::Kinematic, "kinematic"}};
inline constexpr EnumName<RtkDynamics> kRtkDynamicsNames[] = {{RtkDynamics::RandomWalk, "random-walk"},
                                                              {RtkDynamics::ConstantVelocity, "constant-velocity"}};
inline constexpr EnumName<AmbiguityMode> kAmbiguityModeNames[] = {{AmbiguityMode::Off, "off"},
                                                                  {AmbiguityMode::Continuous, "continuous"},
                                                                  {AmbiguityMode::Instantaneous, "instantaneous"},
                                                                  {AmbiguityMode::FixAndHold, "fix-and-hold"}};

/// Which rover and base signals of one band are differenced (see double_difference.hpp).
enum class SignalMatching {
  Strict,  ///< the same RINEX code at both receivers only
  Band,    ///< the same code if both have one, else another tracking mode of the same band
};
inline constexpr EnumName<SignalMatching> kSignalMatchingNames[] = {{SignalMatching::Band, "band"},
                                                                    {SignalMatching::Strict, "strict"}};

struct RtkConfig {
  RtkMode mode = RtkMode::Kinematic;
  RtkDynamics dynamics = RtkDynamics::RandomWalk;
  AmbiguityMode ambiguityMode = AmbiguityMode::Continuous;

  /// Systems used (index systemIndex). Default: GPS, GLONASS, Galileo, BeiDou, QZSS.
  std::array<bool, kNumSystems> systems{true, true, true, true, true, false, false};
  /// Bands per system in order of preference (RINEX band digits); the first `frequencies`
  /// available at both receivers are used. One double-difference group per system and band.
  std::array<std::string, kNumSystems> bands{"125", "12", "157", "276", "125", "15", "59"};
  int frequencies = 2;
  /// Rover and base signals of a band: the same code only, or any tracking mode of the band
  /// (receivers of different brands track different modes, e.g. Galileo E1 C against X).
  SignalMatching signalMatching = SignalMatching::Band;
  double elevationMask = 15.0 * constants::kDegToRad;  ///< rad, at the rover
  double snrMask = 0.0;                                ///< dB-Hz, 0 = off

  // --- Ambiguity resolution.
  /// Systems whose ambiguities are fixed. GLONASS is off: its FDMA inter-frequency phase biases
  /// differ between receiver types, which breaks the integer nature of its double differences.
  std::array<bool, kNumSystems> arSystems{true, false, true, true, true, false, false};
  double arElevationMask = 15.0 * constants::kDegToRad;  ///< rad
  int arMinLock = 0;  ///< epochs an ambiguity must have been estimated before it takes part in AR
  AmbiguityResolutionOptions ar;
  /// A fix needs DD integers that span at least this many satellites (fixedSatelliteSpan, rtk.hpp):
  /// 4 = three independent DD directions, the fewest that determine a 3-D position. Integers of
  /// fewer satellites (e.g. both frequencies of two satellites: four DDs, one direction) are no fix.
  int arMinSatellites = 4;
  int holdMinFixes = 10;           ///< consecutive fixed epochs before fix-and-hold constrains
  double holdSigmaCycles = 0.01;   ///< standard deviation of the hold constraints, cycles
  /// A fixed solution is accepted only if every double-differenced phase residual at the fixed
  /// position is within this many standard deviations (and the code within `codeOutlierSigmas`).
  double fixValidationSigmas = 4.0;
  /// ... and every DD code residual at the fixed position within this many standard deviations.
  double fixCodeValidationSigmas = 8.0;
  /// A (partial) fix is a fix only if it determines the position: 3-D standard deviation (m) of
  /// the fixed position at most this (a partial fix of combinations that leave the position
  /// float-like is reported as float).
  double maxFixedSigma = 0.10;
  /// Position-domain test of the fixed against the float solution: with correct integers
  /// x_fix − x_float ~ N(0, P_float − P_fix); rejected when its χ²(3) statistic exceeds the
  /// 1 − alpha quantile (0 = off, the default: on real data the float covariance of a filter
  /// that has run for minutes is optimistic, its error correlated in time — Nagoya, continuous
  /// AR: float 0.17 m from the correct fix with sigma 0.03 m — so the test rejects right fixes).
  double fixPositionTestAlpha = 0.0;
  /// A fix whose ratio is below this factor times its critical ratio needs another validated fix
  /// of the same DD integers on the same arcs: an earlier one (any epoch since, while the arcs
  /// continue), else it is reported as float and the next epoch's fix may confirm it.
  double confirmRatioFactor = 2.0;

  // --- Measurement model.
  /// Carrier-phase standard deviation per receiver: σ² = a² + b² / sin²(el), metres.
  double phaseSigmaA = 0.003;
  double phaseSigmaB = 0.003;
  /// Code σ = codePhaseRatio × phase σ (RTKLIB's "eratio"), per system factor on top.
  double codePhaseRatio = 100.0;
  std::array<double, kNumSystems> codeSystemFactor{1.0, 1.5, 1.0, 1.0, 1.0, 3.0, 1.5};
  /// Code variance per receiver (measurement_weighting.hpp, a = codePhaseRatio·phaseSigmaA,
  /// b = codePhaseRatio·phaseSigmaB, codeSystemFactor), each receiver with its own C/N0 and both
  /// at the rover's elevation; Elevation: the phase model times the ratio squared.
  WeightingScheme codeWeighting = WeightingScheme::Elevation;
  bool troposphere = true;  ///< Saastamoinen/Niell slant delays at both receivers
  /// Ionosphere-weighted model (Odijk 2002, "Fast precise GPS positioning in the presence of
  /// ionospheric delays", PhD thesis, TU Delft; Teunissen & Montenbruck (eds.) 2017, Springer
  /// Handbook of GNSS, ch. 23): one state per satellite for the single-differenced slant
  /// ionospheric delay I on L1 (m), which delays the code by μ I and advances the phase by μ I,
  /// μ = (λ / λ_L1)². Prior σ = ionosphereSigmaPpm · 1e-6 · baseline · F(el) (F the broadcast
  /// model's obliquity, klobuchar.hpp), random walk ionosphereRatePpm · 1e-6 · baseline · F(el)
  /// per √s. Without it the double differences take the differential ionosphere as zero, which
  /// biases the float ambiguities by tenths of a cycle on baselines of several km: on the
  /// simulated flights with the base 7.5-9.3 km away (bench/sweep family uav_base_1_10km) no
  /// epoch fixed. States only while the zenith prior σ reaches ionosphereMinSigma (m; 0: on every
  /// baseline): by default from 5 km. On shorter baselines the model costs fixes where few
  /// satellites are left (GEONET 0759-3040, 3.34 km, 35° mask: 33 instead of 55 fixed epochs of
  /// 120, tests/gnss/test_rtk.cpp RtkIntegrity), while the ionosphere-fixed model fixes them right.
  /// ionosphereSigmaPpm 0 = off (the ionosphere-fixed model on every baseline).
  double ionosphereSigmaPpm = 1.0;
  double ionosphereRatePpm = 0.05;
  double ionosphereMinSigma = 0.005;

  // --- Base station.
  double maxAge = 30.0;             ///< s, oldest base data used with a rover epoch
  bool interpolateBase = true;      ///< interpolate between base epochs that bracket the rover
  double maxInterpolationGap = 60.0;  ///< s, longest base interval interpolated over
  /// Held (older) base phases are moved to the rover time with their own rate, estimated from an
  /// earlier base epoch, minus the rate common to all signals (the base clock, which cancels).
  bool extrapolateBase = true;

  // --- Cycle slips and outlier rejection.
  CycleSlipOptions slip;
  double ambiguityOutage = 60.0;  ///< s an unobserved ambiguity is kept before it is removed
  /// Prefit gate of double-differenced code (m) and post-fit outlier tests (in σ).
  double codeInnovationGate = 30.0;
  double phaseOutlierSigmas = 6.0;
  double codeOutlierSigmas = 6.0;
  int maxOutlierRounds = 3;

  // --- Filter.
  double initialPositionSigma = 30.0;   ///< m, first epoch / after a reset (around SPP)
  double ambiguityInitialSigma = 30.0;  ///< m (converted to cycles per signal)
  double randomWalkSigma = 30.0;        ///< m/√s, kinematic random walk without Doppler
  bool dopplerAided = true;             ///< predict the kinematic position with the Doppler velocity
  double dopplerAidedSigma = 0.5;       ///< m/√s, random walk on top of the Doppler prediction
  double accelerationSigmaHorizontal = 3.0;  ///< m/s²/√s, constant-velocity model
  double accelerationSigmaVertical = 1.0;
  double maxSppDeviation = 100.0;  ///< m: float farther from SPP resets the filter

  bool useSystem(System s) const { return systems[systemIndex(s)]; }
  bool fixSystem(System s) const { return arSystems[systemIndex(s)]; }
};

const char* toString(RtkMode m);
const char* toString(AmbiguityMode m);
const char* toString(RtkDynamics d);
const char* toString(SignalMatching m);

/// Reads options from the `rtk:` map of a YAML file (yaml-cpp); other top-level keys (e.g. the
/// `spp:` section used for the single-point solutions) are left to their readers. Every key under
/// `rtk:` must be known; missing keys keep `base`'s values. Errors (syntax, unknown key, wrong
/// type, value out of range) throw ParseError naming the file, the line and the key.
///
///   rtk:
///     mode: kinematic               # static | kinematic
///     dynamics: random-walk         # random-walk | constant-velocity
///     ambiguity_mode: continuous    # off | continuous | instantaneous | fix-and-hold
///     systems: GRECJ
///     frequencies: 2                # 1..3
///     bands: {G: "125", E: "157", C: "276"}
///     signal_matching: band         # band (any tracking mode of the band) | strict (same code)
///     elevation_mask_deg: 15
///     snr_mask_dbhz: 0
///     ar: {systems: GECJ, elevation_mask_deg: 15, min_lock: 0, validation: fixed-failure-rate,
///          ratio_threshold: 3, max_failure_rate: 0.001, partial: true,
///          partial_success_rate: 0.999, min_fixed: 4, min_satellites: 4,
///          hold_min_fixes: 10, hold_sigma_cycles: 0.01, validation_sigmas: 4, ffrt_samples: 4000,
///          max_fixed_sigma_m: 0.1, position_test_alpha: 0, code_validation_sigmas: 8,
///          confirm_ratio_factor: 2}   # validation: fixed-failure-rate | ratio | success-rate |
///                                     #             ratio+success-rate
///     phase_sigma_m: {a: 0.003, b: 0.003}
///     code_phase_ratio: 100
///     code_system_factor: {R: 1.5}
///     troposphere: true
///     ionosphere: {sigma_ppm: 1, rate_ppm: 0.05, min_sigma_m: 0.005}
///     base: {max_age_s: 30, interpolate: true, max_interpolation_gap_s: 60, extrapolate: true}
///     cycle_slip: {lli: true, max_gap_s: 60, geometry_free: true, geometry_free_m: 0.05,
///                  geometry_free_rate_mps: 0.0005, doppler: true, doppler_m: 0.6,
///                  doppler_jerk_mps3: 1.0}
///     ambiguity_outage_s: 60
///     outliers: {code_gate_m: 30, phase_sigmas: 6, code_sigmas: 6, max_rounds: 3}
///     filter: {initial_position_sigma_m: 30, ambiguity_sigma_m: 30, random_walk_mpsqrts: 30,
///              doppler_aided: true, doppler_aided_mpsqrts: 0.5, acceleration_h_mps2: 3,
///              acceleration_v_mps2: 1, max_spp_deviation_m: 100}
RtkConfig loadRtkConfig(const std::string& path, const RtkConfig& base = {});
RtkConfig parseRtkConfig(std::string_view yaml, std::string_view name, const RtkConfig& base = {});

}  // namespace gvins
