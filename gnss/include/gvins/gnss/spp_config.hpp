// Options of single point positioning and their YAML form.
#pragma once

#include "gvins/base/yaml_reader.hpp"  // parseSystemLetters

#include <array>
#include <string>
#include <string_view>

#include "gvins/base/constants.hpp"
#include "gvins/base/enum_names.hpp"
#include "gvins/base/satellite.hpp"
#include "gvins/ephemeris/ephemeris_store.hpp"
#include "gvins/gnss/fault_exclusion.hpp"
#include "gvins/gnss/measurement_weighting.hpp"

namespace gvins {

enum class IonosphereOption {
  Off,
  Broadcast,      ///< Klobuchar (GPS/QZSS parameters; BeiDou's for BeiDou), scaled per frequency
  DualFrequency,  ///< ionosphere-free pseudoranges where two bands exist, Broadcast otherwise
};

inline constexpr EnumName<IonosphereOption> kIonosphereOptionNames[] = {
    {IonosphereOption::Off, "off"}, {IonosphereOption::Broadcast, "broadcast"}, {IonosphereOption::DualFrequency, "dual-frequency"}};

enum class TroposphereOption { Off, Saastamoinen };
inline constexpr EnumName<TroposphereOption> kTroposphereOptionNames[] = {{TroposphereOption::Off, "off"},
                                                                          {TroposphereOption::Saastamoinen, "saastamoinen"}};

/// Robust re-weighting of pseudoranges after fault exclusion (IGG-III equivalent weights).
struct RobustEstimation {
  bool enabled = true;
  double k0 = 2.0;          ///< standardised residual (in robust scales) that keeps full weight
  double k1 = 5.0;          ///< beyond it the weight is ~0
  /// k0 and k1 of the epochs whose residual test still fails after fault exclusion (urban
  /// multipath and NLOS: several biased pseudoranges that exclusion could not isolate), where
  /// harder down-weighting pays. Chosen on the simulated urban drive (bench/spp/urban_spp.yaml)
  /// and checked on the real recordings with injected faults (bench/spp/fault_injection.py,
  /// docs/spp.md); epochs that pass the test keep k0 and k1.
  double k0Failed = 1.5;
  double k1Failed = 3.0;
  double minScale = 0.5;    ///< floor of the robust scale (units of the a-priori sigmas)
  int maxIterations = 3;
};

/// Scaling of the reported covariance (position, clocks) by the a-posteriori variance factor of
/// the fit when the residuals say the a-priori weights are optimistic:
///   k = max(1, (chi2 + nu0) / (dof + nu0)),
/// the posterior of the unit variance with a prior of nu0 degrees of freedom at 1 (with few
/// degrees of freedom chi2/dof alone is too noisy to scale by; cf. Koch 1999, Parameter
/// Estimation and Hypothesis Testing in Linear Models, ch. 3). Never below 1: on open-sky data the
/// a-priori covariance is already conservative while the residuals are far smaller than the
/// weights say, so a factor below 1 would shrink it where the errors common to all satellites
/// (which residuals cannot show) dominate. Only the reported covariance changes, never the
/// solution. Measured on real and simulated data: bench/spp/sigma_calibration.py, docs/spp.md.
struct CovarianceScaling {
  bool enabled = true;
  double priorDof = 2.0;
};

/// Error model of the reported covariance (position, clocks), separate from the weights: the
/// weights (`weighting` and the per-satellite error budgets below) decide the solution and the
/// residual test and stay as they are; the reported covariance is that of the weighted solution
/// x = G y (G = (H^T W H)^-1 H^T W, with the prior rows) under an error covariance R in which the
/// errors common to many satellites are correlated, as they are:
///   - broadcast ionosphere: a smooth field of vertical errors of sigma `ionosphereModelError`
///     times the model's zenith delay at the receiver (the Klobuchar model removes about 50 % of
///     the RMS delay: IS-GPS-200N 20.3.3.5.2.5), seen through each line's obliquity, correlated
///     between two lines of sight as exp(-d^2 / (2 L^2)), d the distance of their pierce points on
///     a 350 km shell and L = `ionosphereCorrelationLength` (the one scale chosen on the real
///     recordings, leave-one-site-out: bench/spp/sigma_fit.py); without broadcast parameters the
///     whole delay, 5 m vertical;
///   - troposphere residual: `troposphereZenithError` at the zenith, one value for all lines of
///     sight (mapped);
///   - independent per satellite: code noise and multipath (`weighting`, times `noiseScale`) and
///     the broadcast orbit/clock error (`ephemerisError`).
/// The independent part is scaled by the variance factor of the residuals,
///   k = max(minVarianceFactor, (chi2 - E_common + nu0) / (E_independent + nu0)),
/// chi2 the weighted residuals of the fit before robust re-weighting (measurements and the
/// ionosphere prior) and E their expectations under the two parts of R (nu0 =
/// CovarianceScaling::priorDof; no scaling when CovarianceScaling is disabled): residuals larger
/// than the model says (multipath, NLOS) widen the sigma. After fault exclusion k is at least the
/// median estimate over all satellites, the excluded ones included (the kept residuals are the
/// smallest: their chi2 understates the noise when the exclusions took its tail). Residuals
/// smaller than the noise model could narrow its share down to `minVarianceFactor`; the default
/// 1 does not let them: one epoch's residuals have few degrees of freedom and errors correlated
/// over many epochs, and below 1 the ionosphere-free sigma (nothing correlated left to carry it)
/// was optimistic on the real walk (docs/spp.md). The correlated part is never scaled down:
/// residuals do not show it. The excess k > 1 over the noise model is taken as correlated
/// between satellites by `excessCorrelation` rho, R_exc = (1 - rho) D + rho s s^T (D the
/// independent variances, s their square roots): non-line-of-sight delays are never negative,
/// and their common mean goes into the clock and the height unseen by the residuals; its scale is
/// (k - 1) E_ind / E_exc, the same excess of the residuals' expectation. 0.5: the squared mean
/// of an exponentially distributed delay is half its second moment. Calibration: bench/spp/sigma_calibration.py,
/// docs/results/spp_sigma.md. Disabled: the a-priori covariance (H^T W H)^-1 scaled by the
/// variance factor of the weights (all errors independent), conservative by large factors on
/// open sky.
struct ReportedErrorModel {
  bool enabled = true;
  double noiseScale = 1.0;
  double ionosphereCorrelationLength = 2000e3;  ///< m
  double minVarianceFactor = 1.0;
  double excessCorrelation = 0.5;
};

/// A common correction to the broadcast ionosphere model's zenith delay, estimated with the
/// position from the elevation dependence of the residuals (partial: the model's obliquity
/// factor), constrained by a prior of `priorFraction` of the modelled zenith delay.
struct IonosphereEstimation {
  bool enabled = true;
  double priorFraction = 1.0;
  double minPriorSigma = 0.3;  ///< m
};

struct SppConfig {
  /// Systems used (index systemIndex). Default: GPS, GLONASS, Galileo, BeiDou, QZSS.
  std::array<bool, kNumSystems> systems{true, true, true, true, true, false, false};
  double elevationMask = 15.0 * constants::kDegToRad;  ///< rad
  double snrMask = 0.0;                                ///< dB-Hz; 0 = off
  /// Bands per system in order of preference (RINEX band digits): the first available is the
  /// primary; with `frequencies` >= 2 the next available one forms the ionosphere-free pair.
  std::array<std::string, kNumSystems> bands{"125", "12", "157", "276", "125", "15", "59"};
  int frequencies = 1;  ///< 1, 2 or 3 bands considered per system
  IonosphereOption ionosphere = IonosphereOption::Broadcast;
  TroposphereOption troposphere = TroposphereOption::Saastamoinen;
  /// Surface meteorology of the Saastamoinen model: a latitude/season climatology (RTCA DO-229)
  /// or the standard atmosphere with `relativeHumidity`.
  bool climatologicalMeteo = false;
  double relativeHumidity = 0.5;  ///< of the standard atmosphere
  MeasurementWeighting weighting;
  /// Error budget added to the measurement variance: broadcast-ionosphere residual as a fraction
  /// of the model delay, troposphere residual at zenith (m, mapped), and the orbit/clock error.
  double ionosphereModelError = 0.5;
  double troposphereZenithError = 0.1;
  /// Satellite-specific range error (m) per system that is neither noise nor atmosphere: broadcast
  /// orbit and clock errors (signal-in-space range error) following the multi-GNSS assessment of
  /// Montenbruck, Steigenberger & Hauschild (2018, Adv. Space Res. 61(12)): GPS ~0.6 m, Galileo
  /// ~0.3 m, BeiDou ~1 m, QZSS ~0.6 m. GLONASS FDMA pseudoranges add receiver-dependent
  /// inter-frequency code biases of metres per frequency channel (e.g. Wanninger 2012, GPS
  /// Solutions 16(4)), hence 5 m. The broadcast URA/SISA is an upper bound rather than a sigma
  /// (Galileo's "3.12 m" SISA is typical) and replaces the nominal value only when it exceeds
  /// `ephemerisAlarmAccuracy` (a satellite flagged as degraded).
  std::array<double, kNumSystems> ephemerisError{0.6, 5.0, 0.3, 1.0, 0.6, 2.0, 2.0};
  double ephemerisAlarmAccuracy = 10.0;
  /// The same for satellites whose state comes from precise products (SP3/RINEX clock, see
  /// EphemerisStore::setPrecise), m: IGS final products ~2-3 cm, MGEX BeiDou/QZSS ~5-10 cm
  /// (igs.org/products; Montenbruck et al. 2017, Adv. Space Res. 59(7)), with a margin. GLONASS
  /// keeps the 5 m of the broadcast budget: it is the receiver's FDMA inter-frequency code bias,
  /// which precise products do not remove.
  std::array<double, kNumSystems> preciseEphemerisError{0.05, 5.0, 0.05, 0.1, 0.1, 0.2, 0.2};
  FaultExclusionOptions faultExclusion;
  RobustEstimation robust;
  IonosphereEstimation ionosphereEstimation;
  CovarianceScaling covarianceScaling;
  ReportedErrorModel reportedError;
  double maxGdop = 30.0;
  /// Inter-system clock biases: a prior from earlier epochs keeps systems with one or two
  /// satellites useful; sigma of the prior (m) and random-walk noise (m^2/s). 0 disables.
  double isbPriorSigma = 2.0;
  double isbRandomWalk = 0.01;
  /// QZSS pseudoranges use the GPS receiver clock (QZSST is steered to GPST; same signals)
  /// instead of a clock of their own.
  bool qzssUsesGpsClock = true;
  int maxIterations = 10;
  bool velocity = true;  ///< estimate velocity and clock drift from Doppler
  /// Carrier smoothing window (s) applied to the epochs before solving (CarrierSmoother; 0 = raw
  /// codes). SppSolver solves one epoch at a time; the caller that feeds it epochs in order (e.g.
  /// gvins-spp) owns the smoother and reads this value.
  double carrierSmoothing = 0.0;
  EphemerisSelection ephemeris;

  bool useSystem(System s) const { return systems[systemIndex(s)]; }
};


/// Reads options from YAML (yaml-cpp). The options live under a top-level `spp:` map (other
/// top-level keys are left to other tools); every key under it must be known. Missing keys keep
/// `base`'s values. Errors (syntax, unknown key, wrong type, value out of range) throw ParseError
/// naming the file, the line and the key.
///
///   spp:
///     systems: GRECJ              # letters of G R E C J S I
///     elevation_mask_deg: 15
///     snr_mask_dbhz: 0
///     frequencies: 1              # 1..3
///     bands: {G: "125", E: "157", C: "276"}
///     ionosphere: broadcast       # off | broadcast | dual-frequency
///     troposphere: saastamoinen   # off | saastamoinen
///     meteo: climatology          # climatology (RTCA DO-229 table) | standard
///     relative_humidity: 0.5      # standard atmosphere only
///     weighting: {scheme: elevation, a_m: 0.3, b_m: 0.3, snr_reference_dbhz: 45,
///                 doppler_sigma_mps: 0.05, system_factor: {R: 1.5}}
///     ionosphere_model_error: 0.5
///     troposphere_zenith_error_m: 0.1
///     ephemeris_error_m: {G: 0.6, R: 5.0, E: 0.3, C: 1.0, J: 0.6}
///     ephemeris_alarm_accuracy_m: 10
///     fault_exclusion: {enabled: true, false_alarm_probability: 0.001, max_exclusions: 6,
///                       max_candidates: 10, min_redundancy: 1}
///     robust: {enabled: true, k0: 2.0, k1: 5.0, k0_failed: 1.5, k1_failed: 3.0, min_scale: 0.5,
///              max_iterations: 3}
///     ionosphere_estimation: {enabled: true, prior_fraction: 1.0, min_prior_sigma_m: 0.3}
///     covariance_scaling: {enabled: true, prior_dof: 2}
///     reported_error: {enabled: true, noise_scale: 1, ionosphere_correlation_km: 2000,
///                      min_variance_factor: 1, excess_correlation: 0.5}
///     max_gdop: 30
///     isb_prior_sigma_m: 2
///     isb_random_walk_m2ps: 0.01
///     qzss_gps_clock: true
///     max_iterations: 10
///     velocity: true
///     carrier_smoothing_s: 0      # Hatch window of the codes, s (0 = raw; gvins-spp --smooth)
///     allow_unhealthy: false
/// Why `bands` is not a valid band preference list for system s (as in SppConfig::bands), or an
/// empty string when it is: every character a band of the system (GLONASS: also '1' and '2',
/// its FDMA G1/G2), at least one.
std::string bandListError(System s, std::string_view bands);

SppConfig loadSppConfig(const std::string& path, const SppConfig& base = {});
SppConfig parseSppConfig(std::string_view yaml, std::string_view name, const SppConfig& base = {});

}  // namespace gvins
