// Tightly-coupled GNSS fusion on the VIO backend interface (paper Sec. III). The driver calls
// processEpoch() after each camera frame for every rover epoch whose time tag is <= the newest IMU
// state's time. Per epoch:
//   1. SPP (gnss/ SppSolver) for the frame initialisation and the loosely-coupled velocity; the
//      RTK solver (gnss/ RtkSolver, LAMBDA) on rover + base for the SD code and the fixed DD phase.
//   2. Frame initialisation (stage kFrameInit): client block [ψ, p_NW] with an uninformative prior
//      added at the first SPP fix with enough speed (yaw guess from the velocity headings), updated
//      with the SPP position/velocity predicted through the IMU integration until the σ of the
//      IMU's heading in ENU (ψ + its yaw in W) < σ_θ. Without that speed yet (a vertical take-off,
//      a start at rest; frameStartAtRest) the block starts at the first fix anyway, its yaw a
//      nuisance of its wide prior that no row informs (every row's yaw column is projected out
//      with that σ) until the headings give its value (headingFromMotion); the modes with range
//      rows go tight at once. Once converged
//      (frameReanchor) the estimator re-expresses its state in ENU and the block is marginalized
//      (EstimatorBackend::reanchorWorld, an exact change of variables): as in the paper the frame
//      leaves the state, but its information moves into the poses, so the VIO's yaw and position
//      drift stay observable to the GNSS rows instead of being frozen with the first estimate.
//   3. Clocks (stage kTight): c·dt per constellation + c·ḋt initialised by RANSAC + least squares
//      (gnss_clock_init.hpp) at the current antenna estimate. In the state as the receiver clock
//      [c·dt, c·ḋt] of the first clock system (one client block, propagated at each GNSS epoch:
//      bias += drift·Δt, random walks) and the other systems' inter-system biases (one constant
//      block): the receiver has one oscillator, the ISBs are hardware delays.
//   4. Rows of the configured mode (gnss_measurement_models.hpp), each gated by a chi-square test
//      (robust to NLOS), the accepted rows stacked, whitened with Σ_m + J Σ_g Jᵀ and applied with an
//      epoch gate. No minimum satellite count once initialised. After `reacquireAfter` s without
//      an applied update, the re-acquisition gate instead (gnss_gate_recovery.hpp).
//   5. Outages: after `outageReset` s without an applied GNSS update the clocks are re-initialised
//      and the RTK ambiguities reset.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "gvins/base/geodetic.hpp"
#include "gvins/base/observation.hpp"
#include "gvins/ephemeris/ephemeris_store.hpp"
#include "gvins/fusion/gnss_ambiguity_states.hpp"
#include "gvins/fusion/gnss_base_clock.hpp"
#include "gvins/fusion/gnss_clock_states.hpp"
#include "gvins/fusion/gnss_epoch_report.hpp"
#include "gvins/fusion/gnss_fusion_config.hpp"
#include "gvins/fusion/gnss_gate_recovery.hpp"
#include "gvins/fusion/gnss_ins_alignment.hpp"
#include "gvins/fusion/gnss_lever_arm_state.hpp"
#include "gvins/fusion/gnss_measurement_models.hpp"
#include "gvins/fusion/gnss_zwd_state.hpp"
#include "gvins/gnss/carrier_smoothing.hpp"
#include "gvins/gnss/clock_jump_repair.hpp"
#include "gvins/gnss/doppler_consistency.hpp"
#include "gvins/gnss/rtk.hpp"
#include "gvins/gnss/signal_choice.hpp"
#include "gvins/gnss/spp.hpp"
#include "gvins/gnss/transmit_states.hpp"
#include "gvins/sri/chi_square.hpp"
#include "gvins/vio/world_frame_change.hpp"
#include "gvins/vio/estimator_backend.hpp"

namespace gvins::fusion {

struct GnssRowSet;  // the rows of an epoch and their noise (internal)

template <typename Scalar>
class GnssFusion {
 public:
  explicit GnssFusion(GnssFusionConfig config);
  ~GnssFusion();
  GnssFusion(const GnssFusion&) = delete;
  GnssFusion& operator=(const GnssFusion&) = delete;

  /// Base antenna position (ECEF); overrides the configuration's.
  void setBasePosition(const Eigen::Vector3d& ecef);

  GnssEpochReport processEpoch(vio::EstimatorBackend<Scalar>& est, const ObsEpoch& rover, const ObsEpoch* base,
                               const EphemerisStore& nav);

  const GnssFusionConfig& config() const { return config_; }
  GnssFusionStage stage() const { return stage_; }
  bool clocksInitialized() const { return clocks_.valid(); }
  /// [ψ, p_NW] of the estimator's world frame in local ENU at the anchor: the frame block's
  /// estimate while it is a state, zero once the estimator was re-anchored in ENU
  /// (frameReanchor); nullopt before the frame initialisation.
  std::optional<Eigen::Vector4d> frame(const vio::EstimatorBackend<Scalar>& est) const;
  /// The change of the estimator's world frame made once the frame had converged (frameReanchor),
  /// while the estimator's state is that of the re-anchoring: its inverse takes the estimator's
  /// poses back to the VIO world frame they started in.
  std::optional<vio::WorldFrameChange> worldChange(const vio::EstimatorBackend<Scalar>& est) const {
    return current(est) ? worldChange_ : std::nullopt;
  }
  const GnssAnchor& anchor() const { return anchor_; }
  /// Doppler sanity of the rover epochs (verdicts, warnings, counters).
  const DopplerConsistency& roverDoppler() const { return roverDoppler_; }
  /// Whole-millisecond receiver clock jumps removed from the rover epochs.
  const ClockJumpRepair& clockJumps() const { return clockJumps_; }
  Eigen::Vector3d leverArm(const vio::EstimatorBackend<Scalar>& est) const;
  /// Clock estimate [c·dt per clock system..., c·ḋt] (the receiver clock plus each system's
  /// inter-system bias) and the systems (clock indices).
  std::optional<Eigen::VectorXd> clocks(const vio::EstimatorBackend<Scalar>& est) const;
  const std::vector<System>& clockSystems() const { return clocks_.systems(); }
  /// Antenna position/velocity (ECEF) at time t_ns from the current estimates (frame needed).
  std::optional<AntennaKinematics> antennaAt(const vio::EstimatorBackend<Scalar>& est, std::int64_t t_ns) const;
  /// Covariance (ECEF; m², m²/s, m²/s²) of the antenna position and velocity [p; v] at t_ns
  /// (e.g. GnssEpochReport::t_ns): J P Jᵀ + J_k Σ_k J_kᵀ, with P the joint marginal covariance of
  /// only the blocks they depend on (newest pose, velocity and bias; the frame and the lever arm
  /// when they are states), Σ_k the IMU integration noise from t_ns to the newest state. nullopt
  /// before the frame exists, or while one of those blocks has no information yet.
  std::optional<Eigen::Matrix<double, 6, 6>> antennaCovariance(const vio::EstimatorBackend<Scalar>& est, std::int64_t t_ns) const;
  /// Satellite models of an epoch at antenna position x (for tests and diagnostics); `states`
  /// (optional): the epoch's satellite states, shared with the single differences.
  std::vector<SatelliteModel> satelliteModels(const ObsEpoch& rover, const EphemerisStore& nav,
                                              const Eigen::Vector3d& x, TransmitStates* states = nullptr) const;
  /// Clock system index of a satellite (QZSS shares GPS's clock), or -1 if not estimated.
  int clockIndex(SatId sat) const;
  /// Zenith wet delay residual estimate (m), when estimated.
  std::optional<double> zenithWetDelay(const vio::EstimatorBackend<Scalar>& est) const;
  /// Float ambiguity estimates (m) of the satellites with an ambiguity state (vio+dopp+ppp).
  std::map<SatId, double> ambiguities(const vio::EstimatorBackend<Scalar>& est) const;

 private:
  struct Epoch;  // one processEpoch call (internal)
  /// The Doppler check of the rover epoch, its carrier-smoothed codes and the ambiguity arcs
  /// (every epoch, also before the VIO is ready); returns the epoch the rows use.
  const ObsEpoch& prepareRover(const ObsEpoch& roverInput, const EphemerisStore& nav, GnssEpochReport& rep);
  /// The SPP and RTK solvers on `nav` (new ones when it changes).
  void useNavigation(const EphemerisStore& nav);
  /// The epoch's SPP solution, solved at the first use.
  const SppSolution& sppOf(Epoch& e);
  /// A new base epoch into the RTK module, and the module's run where due.
  void feedRtk(Epoch& e, const ObsEpoch* base);
  void runRtk(Epoch& e);
  /// After an outage: clocks, zenith wet delay and ambiguities start again.
  void resetAfterOutage(vio::EstimatorBackend<Scalar>& est, GnssEpochReport& rep);
  /// The measurement time of the epoch (tag minus receiver clock) into e.tMeas and e.t_ns; false
  /// if it is beyond the newest state.
  bool measurementTime(const vio::EstimatorBackend<Scalar>& est, Epoch& e);
  /// Stage kFrameInit: SPP position and velocity rows; kTight once the frame's yaw converged.
  /// False without an SPP fix.
  bool frameUpdate(vio::EstimatorBackend<Scalar>& est, Epoch& e, const AntennaKinematics& k);
  /// After the first frame update (the block had no information, so the rows are fitted exactly
  /// to first order): the rows again at the corrected state. When their χ² (SPP covariance)
  /// exceeds the epoch gate the linearisation failed (an IMU state far off, e.g. after a long
  /// stretch without aiding, and a yaw correction of tens of degrees about a distant W origin):
  /// the estimator is restarted (restartFrame) and false returned.
  bool linearStart(vio::EstimatorBackend<Scalar>& est, Epoch& e, const GnssRowSet& rows);
  /// Drops the estimator's state (EstimatorBackend::restart) and the fusion's, with the warning
  /// `why` and what follows; false if the backend cannot (the warning says so too).
  bool restartFrame(vio::EstimatorBackend<Scalar>& est, Epoch& e, const std::string& why);
  /// The four nuisance columns of the frame's pending yaw for `rows` (apply): the ENU offset a
  /// uniform yaw gives the antenna's horizontal displacement and velocity, σ yawSpread_, through
  /// each row's dh_dpv.
  Eigen::MatrixXd yawNuisanceColumns(const std::vector<GnssRow>& rows) const;
  /// Stage kTight: the rows of the configured mode (gnss_fusion_rows.cpp); false if the clocks
  /// could not be initialised.
  bool tightUpdate(vio::EstimatorBackend<Scalar>& est, Epoch& e, const GnssStateValues& s, const AntennaKinematics& k);
  /// The clock (initialised at the first use) and zenith wet delay states at the epoch; the
  /// models' clock indices and wet delays follow. False if the clocks could not be initialised.
  bool prepareStates(vio::EstimatorBackend<Scalar>& est, Epoch& e, std::vector<SatelliteModel>& models,
                     const AntennaKinematics& k);
  /// vio+dopp+ppp: ionosphere-free phase rows, one float ambiguity state per satellite arc.
  void addPhaseRows(vio::EstimatorBackend<Scalar>& est, Epoch& e, const std::vector<SatelliteModel>& models,
                    const AntennaKinematics& k, const Eigen::VectorXd& clk, GnssRowSet& rows);
  /// A new ambiguity state for the carrier arc of m's satellite that started at `arcStart`.
  GnssAmbiguityArc& newAmbiguity(vio::EstimatorBackend<Scalar>& est, const SatelliteModel& m, const GpsTime& arcStart);
  /// Dpsr and ddcp rows from the RTK module's differences.
  void addDifferenceRows(Epoch& e, const AntennaKinematics& k, const Eigen::VectorXd& clk, GnssRowSet& rows);
  /// The SD code rows of the differences `dd` (dpsr and ddcp alike), with the base clock per
  /// system; C/N0-masked ones are counted in the report.
  void addSdCodeRows(Epoch& e, const DdEpoch& dd, const AntennaKinematics& k, const Eigen::VectorXd& clk,
                     GnssRowSet& rows);
  /// Applies the tight stage's rows; counts them and restarts ambiguities rejected too often.
  /// `accepted`: per row, whether the gate kept it.
  void applyRows(vio::EstimatorBackend<Scalar>& est, GnssEpochReport& rep, const AntennaKinematics& k,
                 GnssRowSet& rows, std::vector<bool>& accepted);
  bool buildState(const vio::EstimatorBackend<Scalar>& est, std::int64_t t_ns, GnssStateValues& s) const;
  bool startFrame(vio::EstimatorBackend<Scalar>& est, const SppSolution& spp, std::int64_t t_ns);
  /// While the frame's yaw is a nuisance (yawPending_): once the SPP and the IMU velocities both
  /// move horizontally at frameMinSpeed, the yaw gets the difference of their headings as its
  /// value, with the same wide prior (the rows had not informed it), p_NW moved so that the
  /// antenna's ENU position stays, and the rows estimate it from then on (gnss_frame_heading.cpp).
  void headingFromMotion(vio::EstimatorBackend<Scalar>& est, Epoch& e);
  /// Not initialised: feeds the epoch to the GNSS/INS alignment and, once it has a state, starts
  /// the estimator from it in ENU (gnss_fusion_ins_start.cpp); the tight stage follows at once.
  void startFromGnss(vio::EstimatorBackend<Scalar>& est, const ObsEpoch& rover, GnssEpochReport& rep);
  /// Whether the converged frame may be folded into the state: its yaw σ < σ_θ and the σ of the
  /// IMU's ENU position p_N = p_NW + Rz(ψ) p_W below frameReanchorPositionSigma on every axis.
  bool frameKnownInEnu(const vio::EstimatorBackend<Scalar>& est) const;
  bool initClocks(vio::EstimatorBackend<Scalar>& est, const std::vector<SatelliteModel>& models,
                  const AntennaKinematics& k, const GpsTime& t);
  /// Systems seen in `models` without a clock (ephemerides arrived after initClocks): each with
  /// at least lateSystemMinSatellites satellites joins the ISB block, with a notice.
  void addLateClockSystems(vio::EstimatorBackend<Scalar>& est, const std::vector<SatelliteModel>& models,
                           const AntennaKinematics& k, const GpsTime& t);
  /// Moves the notices of the signal choice, clock jumps, late clocks and gate recovery not yet
  /// reported into the epoch's warnings.
  void reportNotices(GnssEpochReport& rep);
  /// Gates rows one by one, stacks the accepted ones and applies them; returns the update.
  /// `ambiguities`: the blocks that rows' `ambiguity` indices refer to. `reacquisition`: the
  /// epoch goes through the re-acquisition gate instead (gnss_gate_recovery.hpp).
  vio::BackendUpdate<Scalar> apply(vio::EstimatorBackend<Scalar>& est, std::vector<GnssRow>& rows,
                                   const Eigen::MatrixXd& noise, const Eigen::Matrix<double, 9, 9>& intCov,
                                   std::vector<bool>& accepted, bool gate,
                                   const std::vector<sri::BlockId>& ambiguities = {},
                                   ReacquisitionEpoch* reacquisition = nullptr);
  /// Whether the ids held belong to the estimator's current state (EstimatorBackend::generation).
  bool current(const vio::EstimatorBackend<Scalar>& est) const { return est.generation() == generation_; }
  /// Forgets every id of the estimator's state and goes back to waiting for the VIO. A calibrated
  /// lever arm within 3 prior σ (per axis) of the configured one becomes the next state's start
  /// value (GnssLeverArmState::forget); one further out (a state that ran away) does not.
  void forgetState();

  GnssFusionConfig config_;
  sri::ChiSquareQuantiles rowGateQuantile_;  // χ²(1) quantile of config_.rowGate
  GnssFusionStage stage_ = GnssFusionStage::kWaitingVio;
  int frameRejections_ = 0;  // consecutive frame epochs gated out (frameUpdate)
  bool yawPending_ = false;  // the frame's yaw is a nuisance of its prior, not yet given a value (startFrame)
  bool startedAtRest_ = false;  // the frame started with its yaw pending (frameReanchorYawSigmaDeg)
  Eigen::Vector2d yawSpread_ = Eigen::Vector2d::Zero();  // |p_h| since yawCentre_, |v_h| of the antenna (apply)
  Eigen::Vector3d yawCentre_ = Eigen::Vector3d::Zero();  // the antenna in W at the frame's start
  std::uint64_t generation_ = 0;  // estimator generation the ids below belong to
  GnssAnchor anchor_;
  sri::BlockId frameBlock_;
  GnssClockStates<Scalar> clocks_;  // the receiver clock and inter-system bias blocks
  GnssLeverArmState<Scalar> lever_{config_.leverArm, config_.leverArmSigma};  // calibrateLeverArm
  GnssZwdState<Scalar> zwd_;        // zwdState()
  std::optional<vio::WorldFrameChange> worldChange_;  // set when the estimator was re-anchored in ENU
  std::optional<GpsTime> lastUpdate_;
  const EphemerisStore* nav_ = nullptr;
  std::unique_ptr<SppSolver> spp_;
  std::unique_ptr<GnssInsAlignment> insAlign_;  // insStart: before the estimator is initialised
  std::unique_ptr<RtkSolver> rtk_;
  // Ddcp with carrier smoothing: the SD code rows' differences of the smoothed codes (rtk_ runs on
  // the raw ones); dpsr's come from rtk_ itself.
  std::unique_ptr<RtkSolver> codeRtk_;
  DopplerConsistency roverDoppler_{"rover"};
  // Primary signals taken from another band than the system's usual one (signal_choice.hpp),
  // each reported once in the epoch's warnings.
  mutable SignalFallbackNotices signalNotices_;
  std::size_t signalWarned_ = 0;
  ClockJumpRepair clockJumps_{"rover"};  // before the Doppler check
  std::size_t jumpWarned_ = 0;
  std::vector<std::string> clockNotices_;  // systems that joined the clocks late
  std::size_t clockWarned_ = 0;
  GnssGateRecovery gateRecovery_{config_.reacquireAfter, config_.reacquireAcceleration};
  std::size_t gateWarned_ = 0;
  ObsEpoch checkedRover_;      // the rover epoch after the Doppler check
  std::size_t baseWarned_ = 0;  // warnings of rtk_'s base Doppler check already reported
  DopplerConsistency baseDoppler_{"base"};  // the base epochs before the base smoother (dpsr, ddcp)
  std::size_t baseCheckWarned_ = 0;        // its warnings already reported
  std::optional<GpsTime> lastBase_;
  GnssBaseClock baseClock_;  // c·dt_b per clock system of the dpsr rows (gnss_base_clock.hpp)
  std::unique_ptr<CarrierSmoother> smoother_, baseSmoother_;  // carrierSmoothing > 0: psr, dpsr, ddcp
  ObsEpoch smoothed_;
  // vio+dopp+ppp: one float ambiguity state per satellite arc; the arcs (cycle slips, gaps, signal
  // changes, code-carrier jumps) are those of a CarrierSmoother run on a copy of the rover epochs.
  std::unique_ptr<CarrierSmoother> arcs_;
  ObsEpoch arcSmoothed_;  // the rover epoch with the arcs' carrier-smoothed codes
  GnssAmbiguityStates<Scalar> ambiguities_;
};

extern template class GnssFusion<float>;
extern template class GnssFusion<double>;

}  // namespace gvins::fusion
