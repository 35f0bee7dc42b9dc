// Real-time kinematic / static relative positioning with integer ambiguity resolution.
//
// Per rover epoch:
//   1. single point positioning of the rover (fallback solution, Doppler velocity, sanity check);
//   2. rover cycle-slip detection; base data aligned to the rover time (BaseStation);
//   3. time update of the float filter (static: none; kinematic: random walk predicted with the
//      Doppler velocity, or constant velocity with white-noise acceleration);
//   4. single and double differences (DoubleDifferenceBuilder);
//   5. single-difference ambiguity states are added for new arcs, re-initialised after slips
//      (a slipped ambiguity is never kept) and marginalised when their satellite has been gone for
//      `ambiguityOutage`;
//   6. measurement update of the square-root information filter (gvins::sri) with the DD phase and
//      code of each group, whitened with their exact correlation (shared reference); post-fit
//      outliers re-initialise the ambiguity (phase) or drop the code, and the update is redone;
//   7. ambiguity resolution (rtk_ambiguity.cpp): the float DD ambiguities of the eligible signals
//      (system enabled for AR, above the AR mask, locked long enough, no half-cycle flag) and their
//      covariance, taken from the square-root factor, go to LAMBDA with the fixed-failure-rate
//      ratio test and partial fixing (resolveAmbiguities); the fixed position is the float one
//      conditioned on the fixed integer combinations. It is a fix only if it passes every check
//      of the fixed solution: its 3-D sigma is at most `maxFixedSigma` (a partial fix must
//      determine the position), it agrees with the float position in the float covariance
//      (χ²(3) test), every DD phase of the AR set and every DD code fits it; a marginal fix is
//      confirmed by another validated fix of the same integers on the same arcs (an earlier one,
//      else it waits for the next epoch's). In fix-and-hold mode only such
//      validated, confirmed fixes are fed back as constraints.
//
// Epochs may be processed backward in time (setTimeDirection: the backward pass of the combined
// forward + backward post-processing solution, rtk_combination.hpp): base buffer, slip detectors,
// Doppler checks, ambiguity outages and the process noise of the time update then measure time in
// processing order (time_direction.hpp); the dynamics models are the same in reverse time.
//
// The float state is [SD ambiguities (cycles)..., position (, velocity)] in ECEF; ambiguities sit in
// front so the position block stays at the back, where the filter updates and reads it cheaply.
#pragma once

#include <cstdint>
#include <optional>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include <Eigen/Core>

#include "gvins/base/observation.hpp"
#include "gvins/ephemeris/ephemeris_store.hpp"
#include "gvins/gnss/base_station.hpp"
#include "gvins/gnss/cycle_slip_detector.hpp"
#include "gvins/gnss/double_difference.hpp"
#include "gvins/gnss/doppler_consistency.hpp"
#include "gvins/gnss/position_solution.hpp"
#include "gvins/gnss/rtk_config.hpp"
#include "gvins/gnss/spp.hpp"
#include "gvins/gnss/spp_config.hpp"
#include "gvins/gnss/time_direction.hpp"
#include "gvins/sri/sri_filter.hpp"

namespace gvins {

/// Why an epoch has no RTK (float or fixed) solution.
enum class RtkIssue : std::uint8_t {
  None,
  NoBasePosition,      ///< base antenna position unknown
  NoBaseData,          ///< no base epoch yet
  BaseTooOld,          ///< base data older than maxAge (gap, missing base epochs)
  NoCommonSatellites,  ///< fewer than four satellites differenced (no common satellites/signals)
  FilterReset,         ///< the float solution left the SPP solution by more than maxSppDeviation
  Undetermined,        ///< the float position's standard deviation exceeds kMaxFloatSigma
};
const char* toString(RtkIssue i);

/// Outcome of ambiguity resolution in an epoch with a float solution.
enum class ArStatus : std::uint8_t {
  Off,                ///< AR disabled
  TooFewAmbiguities,  ///< fewer eligible DD ambiguities than `ar.minFixed`, or a fix whose DD
                      ///< integers span fewer satellites than `arMinSatellites`
  NotValidated,       ///< no (partial) integer solution passed the ratio / success-rate test
  Rejected,           ///< an accepted solution failed the residual check at the fixed position
  Imprecise,          ///< the fixed position's sigma exceeds maxFixedSigma (fix not used)
  Inconsistent,       ///< the fixed position disagrees with the float one (position-domain test)
  Unconfirmed,        ///< a marginal fix no earlier fix confirms, reported as float until the next epoch's does
  Fixed,              ///< the whole eligible set
  PartialFixed,       ///< a subset (decorrelated combinations)
};
const char* toString(ArStatus s);

struct RtkSolution {
  GpsTime time;  ///< solution time (rover time tag corrected by the SPP receiver clock when known)
  SolutionQuality quality = SolutionQuality::None;  ///< Fix, Float, Single or None
  Eigen::Vector3d position = Eigen::Vector3d::Zero();            ///< ECEF, m (of `quality`)
  Eigen::Matrix3d positionCovariance = Eigen::Matrix3d::Zero();  ///< ECEF, m²
  Eigen::Vector3d floatPosition = Eigen::Vector3d::Zero();       ///< when there is a float solution
  Eigen::Matrix3d floatCovariance = Eigen::Matrix3d::Zero();
  std::optional<Eigen::Vector3d> velocity;  ///< ECEF, m/s (Doppler, or the constant-velocity state)
  Eigen::Matrix3d velocityCovariance = Eigen::Matrix3d::Zero();
  int numSatellites = 0;   ///< satellites with DD phase (RTK) or used by SPP (single)
  std::optional<double> hdop;  ///< HDOP of the rover's SPP geometry this epoch (NMEA GGA)
  double age = 0.0;        ///< s, age of the base data
  double ratio = 0.0;      ///< ratio-test value of the accepted set, else of the full set
  double successRate = 0.0;  ///< bootstrapped success rate of the accepted (or full) set
  double criticalRatio = 0.0;  ///< ratio the accepted (or full) set had to reach (fixed-failure-rate test)
  int numAmbiguities = 0;  ///< eligible DD ambiguities
  int numFixed = 0;        ///< integer combinations fixed
  bool held = false;       ///< fix-and-hold constraints applied after this epoch
  RtkIssue issue = RtkIssue::None;
  ArStatus ar = ArStatus::Off;
  int phaseOutliers = 0;   ///< ambiguities re-initialised by the post-fit test this epoch
  int codeOutliers = 0;    ///< code DDs dropped this epoch
  int ambiguityResets = 0; ///< ambiguities (re)initialised for new arcs or slips this epoch
  SppStatus sppStatus = SppStatus::NoObservations;

  bool valid() const { return quality != SolutionQuality::None; }
  /// For the .pos writer.
  PositionSolution toPositionSolution() const;
};

/// Totals over the session.
struct RtkCounters {
  std::int64_t ambiguitiesAdded = 0;   ///< new arcs and re-initialisations
  std::int64_t slipResets = 0;         ///< re-initialisations after a detected slip / new base or rover arc
  std::int64_t phaseOutliers = 0;      ///< re-initialisations by the post-fit test
  std::int64_t codeOutliers = 0;       ///< code DDs dropped (prefit gate or post-fit test)
  std::int64_t ambiguitiesRemoved = 0; ///< marginalised after an outage
  std::int64_t filterResets = 0;
  std::int64_t holdUpdates = 0;
  std::int64_t arAttempts = 0;
  std::int64_t partialFixes = 0;
  std::int64_t rejectedFixes = 0;       ///< by the residual checks at the fixed position
  std::int64_t impreciseFixes = 0;      ///< fixes that left the position sigma above maxFixedSigma
  std::int64_t inconsistentFixes = 0;   ///< by the position-domain test
  std::int64_t unconfirmedFixes = 0;    ///< marginal fixes without an earlier fix of the same integers
};

/// μ = (λ / λ_L1)²: the first-order ionospheric delay of a signal of wavelength λ (m) per metre of
/// delay on GPS L1 (the delay is proportional to 1/f²; IS-GPS-200N 20.3.3.3.3.2); 0 for an unknown
/// wavelength.
double ionosphereDelayFactor(double wavelength);
/// The double-differenced first-order ionospheric delay μ_s I_s − μ_r I_r (m) of a satellite's
/// signal (wavelength λ_s, m) and the reference's (λ_r), from their single-differenced slant delays
/// on L1, I_s and I_r (m): the code is delayed by it, the phase advanced.
double ddIonosphericDelay(double wavelengthS, double ionosphereS, double wavelengthR, double ionosphereR);

/// The satellites a set of DD phases of `dd` spans for the position: one more than the number of
/// independent DD directions (e_sat − e_ref), i.e. the distinct satellites of their references
/// and satellites less one for every further set joined by no DD (a reference per system). Both
/// frequencies of a satellite count once: the DDs of two satellites on two frequencies span 2.
int fixedSatelliteSpan(const DdEpoch& dd, const std::vector<DoubleDifference>& phases);

/// Whether DD phases of `dd` with validated integers make a fix: at least `cfg.ar.minFixed` of
/// them, spanning at least `cfg.arMinSatellites` satellites (fixedSatelliteSpan). The one rule of
/// RtkSolver's fixes, applicableFixedPhases and the fusion's fixed epochs.
bool isFixSet(const DdEpoch& dd, const std::vector<DoubleDifference>& phases, const RtkConfig& cfg);

/// The DD phases of `dd` (RtkSolver::measurements()) that a user of the differences may apply as
/// fixed (the fusion's Ddcp rows): those that carry the integer of a validated fix (resolve() or
/// the held fix of differencesWithHeldFix; their failure rate is bounded by the validation of
/// `cfg.ar`: fixed-failure-rate ratio test, partial subsets at `ar.partialSuccessRate`), and only
/// when they make a fix (isFixSet: at least `ar.minFixed` of them spanning at least
/// `arMinSatellites` satellites). Fewer (a partial fix
/// whose combinations leave two or three DDs integer, a held fix whose other satellites have set
/// or slipped, both frequencies of two or three satellites) are not a fix: a set that small can be
/// wrong with a high ratio, and it does not determine the 3-D position. Empty when too few.
std::vector<DoubleDifference> applicableFixedPhases(const DdEpoch& dd, const RtkConfig& cfg);

class RtkSolver {
 public:
  /// Float solutions with a larger position standard deviation (m, √trace) are not reported.
  static constexpr double kMaxFloatSigma = 30.0;

  /// `nav` must outlive the solver (it may grow, e.g. with ephemerides from an RTCM stream).
  RtkSolver(const EphemerisStore& nav, RtkConfig config = {}, SppConfig spp = {});

  /// Base antenna reference point, ECEF (m). Changing it clears the base buffer and the
  /// ambiguities.
  void setBasePosition(const Eigen::Vector3d& arp);
  const std::optional<Eigen::Vector3d>& basePosition() const { return base_.position(); }
  void setBaseGlonassChannels(const GlonassChannels& channels);
  void setRoverGlonassChannels(const GlonassChannels& channels);
  /// Whether the rover's and the base's phases refer to the reference signal of each band
  /// (phaseAlignmentOf a RINEX header, RTCM MSM: Aligned). Default Unknown: only signals with the
  /// same code at both receivers are differenced, whatever RtkConfig::signalMatching says.
  void setPhaseAlignment(const PhaseAlignments& rover, const PhaseAlignments& base);
  /// A-priori rover position for the first SPP iteration (e.g. RINEX header).
  void setRoverInitialPosition(const Eigen::Vector3d& ecef);

  /// Order in which base and rover epochs are given (default forward). Set before the first
  /// epoch: it clears the base buffer, the slip histories and the float solution.
  void setTimeDirection(TimeDirection d);
  TimeDirection timeDirection() const { return direction_; }
  /// Base epochs, in time order (reverse time order backward), up to (and, for interpolation, one past) each rover epoch.
  void addBaseEpoch(const ObsEpoch& epoch);
  /// Processes one rover epoch. `states` (optional): satellite states of this epoch that the
  /// caller has computed (or wants filled) for its own use, shared with the differences.
  RtkSolution process(const ObsEpoch& rover, TransmitStates* states = nullptr);
  /// The single and double differences of the last processed epoch, with the fixed ambiguities of
  /// the DD phases when the epoch was fixed (for the fusion and for diagnostics).
  const DdEpoch& measurements() const { return dd_; }
  /// Steps 2 and 4 only (rover slips, base aligned to the rover time, single and double
  /// differences about the rover position `x`), without SPP, the float filter and ambiguity
  /// resolution: for users of the code differences alone (e.g. the fusion's SD pseudoranges).
  /// The differences go to measurements(); returns the base data's age (s), or nullopt when
  /// the base has no usable data for this epoch (measurements() is then empty). Between
  /// process() epochs it only forms differences (the float filter and its ambiguities wait for
  /// the next process(), which predicts over the whole interval).
  std::optional<double> differences(const ObsEpoch& rover, const Eigen::Vector3d& x, TransmitStates* states = nullptr);
  /// differences() with the fixed ambiguities of the last process() epoch that ended fixed, on
  /// the DD phases whose satellite and reference signals continue the arcs they had then (same
  /// rover and base arc starts: no slip, no gap since). For a caller that runs the whole module
  /// only now and then (the fusion's Ddcp at the base epochs) and holds the fix in between.
  /// Returns the base data's age as differences() does; `fixed` receives the number of DD phases
  /// that got an ambiguity.
  std::optional<double> differencesWithHeldFix(const ObsEpoch& rover, const Eigen::Vector3d& x, int& fixed,
                                               TransmitStates* states = nullptr);
  /// True when a process() epoch ended fixed since the last reset: the fix of the last such epoch
  /// is held for differencesWithHeldFix (a run that does not fix keeps it; a reset drops it).
  bool hasHeldFix() const { return !held_.empty(); }
  /// Time of the last process() epoch (nullopt before the first and after reset()).
  std::optional<GpsTime> lastProcessTime() const { return lastProcess_; }
  /// Whether the DD phases formed by the last differences()/differencesWithHeldFix() are those
  /// of the last process() epoch: the same satellite and reference signals on the same arcs (no
  /// new satellite, no slip, no other reference). Then a process() now would resolve nothing
  /// that the held fix lacks; a caller may skip it until its revalidation is due.
  bool phasePairsAsProcessed() const;
  /// Forgets the float solution and all ambiguities (base buffer and slip history stay).
  void reset();

  const RtkConfig& config() const { return cfg_; }
  const RtkCounters& counters() const { return counters_; }
  const BaseStation& base() const { return base_; }
  const DdFormationStats& differenceStats() const { return builder_.stats(); }
  const CycleSlipCounts& roverSlipCounts() const { return roverSlips_.counts(); }
  /// Doppler sanity of the rover stream (every rover epoch passes it before SPP and the slip
  /// detector; the base's is base().doppler()).
  const DopplerConsistency& roverDoppler() const { return roverDoppler_; }
  /// For a caller that runs the rover's Doppler check itself before handing epochs over (the
  /// fusion): the solver then takes them as they are, without a second check or a copy.
  void setRoverDopplerCheckedByCaller() { checkRoverDoppler_ = false; }

 private:
  struct Ambiguity {
    sri::BlockId id;
    SatId sat;
    ObsCode code;
    ObsCode baseCode;
    double wavelength = 0.0;
    GpsTime roverArc, baseArc, lastSeen;
    int lock = 0;
  };
  struct Group;  // per-epoch bookkeeping of the update (rtk.cpp)
  /// A DD ambiguity of the AR set: SD indices of the AR reference and the satellite in dd_, and
  /// their ambiguity blocks.
  struct ArPair {
    int ref, sat;
    sri::BlockId refId, satId;
  };
  /// The float solution conditioned on a (partial) integer fix.
  struct ConditionedFix {
    Eigen::VectorXd ambiguities;  ///< conditioned DD ambiguities of the AR set, cycles
    Eigen::Vector3d position;
    Eigen::Matrix3d covariance;
    std::unordered_map<int, double> ionosphere;  ///< satIndex → conditioned SD slant delay on L1, m
  };
  /// A satellite's single-differenced slant ionospheric delay on L1 (ionosphere-weighted model,
  /// RtkConfig::ionosphereSigmaPpm; rtk_ionosphere.cpp).
  struct Ionosphere {
    sri::BlockId id;
    GpsTime lastSeen;
    double elevation = 0.0;  ///< rad, at the last epoch seen
  };

  static std::uint32_t key(SatId s, ObsCode c) {
    return static_cast<std::uint32_t>(satIndex(s)) << 16 | static_cast<std::uint32_t>(c.band) << 8 |
           static_cast<std::uint32_t>(static_cast<unsigned char>(c.attr));
  }
  void initialize(const Eigen::Vector3d& x, double sigma, const SppSolution& spp);
  void timeUpdate(double dt, const SppSolution& spp);
  void manageAmbiguities(const Eigen::Vector3d& x0, RtkSolution& sol);
  void dropAmbiguity(std::uint32_t k);
  /// Builds and applies the measurement update to filter_; returns false if nothing was applied.
  bool measurementUpdate(const Eigen::Vector3d& x0);
  /// Post-fit test: re-initialises one phase ambiguity or drops one code; true if it changed
  /// something (the update must then be redone).
  bool rejectOutlier(RtkSolution& sol);
  /// Measurement update about x0 with post-fit outlier rejection, redone about the updated
  /// position when it moved far; returns the float position.
  Eigen::Vector3d updateWithOutlierRejection(Eigen::Vector3d x0, RtkSolution& sol);
  void resolve(RtkSolution& sol);
  // Steps of resolve() (rtk_ambiguity.cpp).
  std::vector<ArPair> arPairs(std::vector<int>& arReference) const;
  /// Float DD ambiguities `a` of the pairs, their covariance and cross-covariance with the
  /// position; false when a block has no information.
  bool arCovariance(const std::vector<ArPair>& pairs, Eigen::VectorXd& a, Eigen::MatrixXd& Qaa,
                    Eigen::MatrixXd& Qxa, std::vector<int>& ionosphereRows) const;
  /// Checks of the fixed solution (precision, position domain, phase and code residuals).
  ArStatus checkFix(const std::vector<ArPair>& pairs, const RtkSolution& sol, const ConditionedFix& f);
  /// Integer DD phases of dd_ implied by the conditioned AR ambiguities (NaN where not integer).
  std::vector<double> ddIntegers(const std::vector<ArPair>& pairs, const std::vector<int>& arReference,
                                 const ConditionedFix& f) const;
  void hold(const std::vector<ArPair>& pairs, const AmbiguityFix& fix, const Eigen::VectorXd& a);
  Eigen::Vector3d positionEstimate() const;
  double ambiguityEstimate(const SingleDifference& sd) const;
  // The ionosphere-weighted model (rtk_ionosphere.cpp).
  /// Prior σ of a satellite's SD slant delay at this baseline (m); 0 when the model is off.
  double ionosphereSigma(double elevation) const;
  /// States for the satellites of dd_'s differences (new ones with their prior), stale ones dropped.
  void manageIonosphere();
  /// Random walk of the ionosphere states over dt (s).
  void propagateIonosphere(double dt);
  /// The SD slant delay state of a satellite (0 without one) and its block (invalid without one).
  double ionosphereEstimate(SatId sat) const;
  sri::BlockId ionosphereBlock(SatId sat) const;
  /// μ_s I_s − μ_r I_r of a DD (ddIonosphericDelay; the code delay, the phase advance) at the
  /// state estimates, or, where `conditioned` (satIndex → SD delay: ConditionedFix::ionosphere)
  /// has a satellite, at its value conditioned on a fix.
  double ddIonosphere(const SingleDifference& s, const SingleDifference& r,
                      const std::unordered_map<int, double>* conditioned = nullptr) const;
  /// Jacobian of row `row` of a DD (satellite s, reference r) w.r.t. their ionosphere states:
  /// sign μ_s and −sign μ_r (code: sign +1; phase: −1).
  void ionosphereColumns(sri::Measurement<double>& m, int row, const SingleDifference& s, const SingleDifference& r,
                         double sign) const;

  const EphemerisStore& nav_;
  RtkConfig cfg_;
  TimeDirection direction_ = TimeDirection::Forward;
  SppSolver spp_;
  BaseStation base_;
  CycleSlipDetector roverSlips_;
  DopplerConsistency roverDoppler_{"rover"};
  ObsEpoch roverChecked_;  // the rover epoch with its Doppler checked (checkedRover)
  bool checkRoverDoppler_ = true;
  /// The rover's GLONASS channels, completed from the navigation records.
  GlonassChannels roverGlonassChannels() const;
  const ObsEpoch& checkedRover(const ObsEpoch& rover);
  DoubleDifferenceBuilder builder_;
  GlonassChannels roverChannels_;
  sri::SriFilter<double> filter_;
  bool initialized_ = false;
  sri::BlockId pos_, vel_;
  GpsTime lastTime_;
  std::optional<Eigen::Vector3d> lastVelocity_;
  std::unordered_map<std::uint32_t, Ambiguity> amb_;
  std::unordered_set<std::uint32_t> forced_;  // ambiguities to re-initialise (post-fit outliers)
  std::unordered_map<int, Ionosphere> iono_;  // by satIndex
  double baseline_ = 0.0;  // m, rover-base distance of the current epoch
  DdEpoch dd_;
  BaseSnapshot snapshot_;
  /// The fixed DD phases of the last process() epoch that ended fixed (differencesWithHeldFix).
  struct HeldSignal {
    SatId sat;
    ObsCode code, baseCode;
    GpsTime roverArc, baseArc;
    static HeldSignal of(const SingleDifference& sd) { return {sd.sat, sd.code, sd.baseCode, sd.roverArc, sd.baseArc}; }
    bool operator==(const HeldSignal&) const = default;
  };
  struct HeldDd {
    HeldSignal satellite, reference;
    double cycles = 0.0, meters = 0.0;
  };
  std::vector<HeldDd> held_;
  /// A DD phase of dd_ as its (satellite, reference) signals on their arcs.
  using HeldPair = std::pair<HeldSignal, HeldSignal>;
  HeldPair pairOf(const DoubleDifference& d) const;
  /// Whether either signal of a DD phase of dd_ is flagged in this epoch (slip, half cycle): its
  /// arc may not continue, so no held integer applies.
  bool flagged(const DoubleDifference& d) const;
  /// The DD phases of the last process() epoch and its time.
  std::vector<HeldPair> processedPairs_;
  std::optional<GpsTime> lastProcess_;
  /// The rover epoch the slip detector last took: differences() and process() at the same epoch
  /// must not feed it twice (a zero interval would restart every arc).
  std::optional<GpsTime> slipEpoch_;
  void detectSlips(const ObsEpoch& rover, const GlonassChannels& channels);
  RtkSolution processEpoch(const ObsEpoch& rover, TransmitStates* states);
  int consecutiveFixes_ = 0;
  /// DD integers of this process() epoch's validated fix (fixNow_), and of the latest validated
  /// fix of each DD pair formed in every process() epoch since (fixMemory_: the integer of a DD on
  /// the same arcs does not change, so any earlier validated fix of it confirms a marginal first
  /// fix). Kept across resets (the integer does not depend on the filter).
  std::vector<std::pair<HeldPair, double>> fixMemory_, fixNow_;
  /// After resolve(): fixMemory_ takes this epoch's fixNow_ and keeps the earlier integers of this
  /// epoch's other DD phases whose signals are not flagged and whose ambiguities the post-fit
  /// test did not re-initialise.
  void rememberFix();
  /// Previous resolution's DD ambiguities (SD block ids of satellite and reference) and its
  /// reduced basis: the next epoch's LAMBDA starts from it (ReductionStart) while none of these
  /// pairs has gone (new pairs enter with unit vectors).
  std::vector<std::pair<sri::BlockId, sri::BlockId>> arPairs_;
  ReductionStart arBasis_;
  RtkCounters counters_;
};

}  // namespace gvins
