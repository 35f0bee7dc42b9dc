// The SRI-SWF visual-inertial estimator (paper Sec. II; Wu et al. 2015): a square-root inverse
// sliding-window filter over [IMU extra | SLAM features | IMU pose clones, oldest first |
// parameters] (the extra, velocity and bias blocks, last instead with imu_extra_first false),
// built on gvins::sri::SriFilter. docs/vio_estimator.md describes state, order and steps.
//
// Driver (one thread, time order):
//   SriSwfEstimator<double> est(config);
//   for each IMU sample: est.addImu(sample);            // IMU up to (at least) the frame time
//   for each FeatureFrame: FrameResult r = est.processFrame(frame);
//   est.newestImuState(), est.poseCovariance()         // 6×6, [δθ; δp], double
// Clients (fusion/) use the EstimatorBackend interface (estimator_backend.hpp).
//
// Per frame: propagate the newest IMU state to the frame time by appending the paper's block row
// (eq. (8), Φ and G Q Gᵀ from ImuPropagator) — the new pose block is the frame's clone and the
// previous velocity block (and, every imu_bias_renewal seconds, the bias block) is marginalized; SLAM re-observations (anchored inverse depth, gated);
// MSCKF updates of lost / window-long tracks (triangulation, null-space projection, χ² gate);
// delayed SLAM initialisation from window-long tracks; one correction; marginalization of lost
// SLAM features and of the oldest clone (SLAM features anchored there are re-anchored first).
//
// Scalar: float or double (both instantiated). Estimates handed out are double.
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>

#include "gvins/vio/estimator_backend.hpp"
#include "gvins/vio/feature_frame.hpp"
#include "gvins/vio/imu_noise.hpp"
#include "gvins/vio/imu_sample.hpp"
#include "gvins/vio/init_status.hpp"
#include "gvins/vio/sensor_yaml.hpp"

namespace gvins::vio {

struct SriSwfConfig {
  // ---- sensors
  ImuNoise imu;             ///< noise densities / random walks (Kalibr names)
  double gravity = 9.81;    ///< m/s², W is z-up: gravity (0, 0, −g)
  /// 1 (mono) or 2 (stereo) cameras; T_BS is the camera pose in the IMU frame (T_IC).
  std::vector<CameraCalibration> cameras;
  double pixel_noise = 1.0;  ///< px, 1-σ per axis (mapped to normalised coordinates by 1/f)
  /// m, 1-σ of where on the observed surface a feature is, across the ray: adds (σ_s / depth)²
  /// to the normalised-coordinate variance of every observation, so that features very close to
  /// the camera (a down-looking camera on the ground) do not get weights growing with 1/depth.
  double surface_noise = 0.003;

  // ---- window and features
  int window = 11;             ///< pose clones kept (the newest pose included)
  int max_slam_features = 50;  ///< SLAM features in the state at most
  int min_track_msckf = 3;     ///< frames a lost track needs for an MSCKF update
  double min_depth = 0.5;      ///< m, triangulated depth bounds (all observing cameras)
  double max_depth = 500.0;
  /// Minimum ratio of triangulation baseline to depth (rejects near-degenerate tracks).
  double min_baseline_ratio = 0.005;
  double chi2_probability = 0.95;  ///< χ² gate of each feature's rows (≥ 1: no gate)
  int max_msckf_per_frame = 40;    ///< MSCKF features used per frame at most (longest first)
  /// Re-anchoring noise (normalised coordinates / relative inverse depth) when the anchor clone
  /// of a SLAM feature leaves the window. 0 (default): the re-anchoring is an exact change of
  /// variables of the feature block in place (sri::SriFilter::substitute, no marginalization
  /// sweep; the ten simulated flights: same RMSE, estimator −15 %, docs/vio_estimator.md); > 0:
  /// a propagation with that noise into a new block, then the old block is marginalized.
  double reanchor_sigma = 0.0;
  /// Visual lock-out: when, over this long (s), at least 20 features reached a χ² gate and at
  /// least 90 % of them were rejected, the state is wrong (a bad initialisation, an unmodelled
  /// time offset) and the gates keep it from recovering: the estimator drops the state and
  /// initialises again (FrameResult::reset, generation()). Checked once a state is this old, and
  /// not while a client's measurements (GNSS, EstimatorBackend::update) were applied within the
  /// span: they hold the state, and the rejections are then a camera problem.
  /// Measured on EuRoC V1_02's real IMU with an ignored −12.7 ms offset (docs/vio_estimator.md).
  /// 0 disables it.
  double lockout_reset_s = 1.0;

  /// m/√s, white velocity noise added to the position rows of every IMU propagation (σ² Δt).
  /// Stands for what the IMU model leaves out (discrete integration, vibration) and keeps the
  /// position rows of the IMU chain from becoming so stiff (weights ~1e5 per frame from the
  /// accelerometer noise alone) that float rounding turns them into information along the
  /// unobservable global position and yaw. Measured on the ten simulated UAV flights (feature
  /// tracks, docs/vio_estimator.md): 0 → float RMSE +26 % over double and position NEES 6.3;
  /// 4.5e-3 (1 mm per 20 Hz frame) → float within 2 % of double, NEES 1.8, double itself 3 %
  /// better. 0 disables it.
  double position_random_walk = 4.5e-3;
  /// rad/√s, white angular-rate noise added to the rotation rows of every IMU propagation
  /// (σ² Δt), on top of the gyroscope noise; the rotation counterpart of position_random_walk.
  /// 0 (default) disables it.
  double attitude_random_walk = 0.0;

  // ---- initialisation
  double init_window = 1.0;          ///< s of IMU used by the static test / gravity mean
  double static_max_accel_std = 0.15;  ///< m/s², per-axis std of the accelerometer at rest
  double static_max_gyro_std = 0.02;   ///< rad/s
  double static_max_parallax = 1.0;    ///< px, median feature displacement over the window
  /// Standstill from the IMU alone when fewer than 5 features are tracked over the window (a
  /// downward camera on the ground before take-off is too close to track): initialisation and
  /// zero-velocity updates then trust the IMU's rest test. false: tracks must confirm it.
  bool init_static_without_tracks = true;
  bool init_in_motion = true;          ///< linear visual-inertial alignment (stereo; mono see below)
  /// Mono rigs: also try the mono in-motion alignment (gyro bias from the window's epipolar
  /// constraints, scale/velocity/gravity, an excitation test against accelerometer errors;
  /// measured in docs/vio_estimator.md). The static test is tried first; off: a mono rig
  /// initialises at a standstill only.
  bool init_mono_in_motion = true;
  int init_motion_frames = 10;         ///< frames used by the stereo in-motion alignment
  int init_mono_motion_frames = 20;    ///< frames used by the mono in-motion alignment (≥ 5)
  /// Mono in-motion alignment: largest relative 1-σ of the metric scale that is accepted: the
  /// fit's residual σ (gravity direction free) and the scale change under init_mono_accel_error
  /// combined (root sum of squares); above it the motion lacked acceleration.
  double init_mono_max_scale_sigma = 0.05;
  /// Mono in-motion alignment: estimate the gyro bias first from the epipolar constraints of the
  /// window (its rotations come from the gyro), and start the state with it; a result above
  /// init_mono_max_gyro_bias (rad/s) is discarded as degenerate.
  bool init_mono_gyro_bias = true;
  double init_mono_max_gyro_bias = 0.1;
  /// Mono in-motion alignment, excitation: the scale change a constant accelerometer error of
  /// this size (m/s²; bias plus the tilt left by a wrong gravity direction) along the worst body
  /// axis gives is the accelerometer's part of the scale's σ (init_mono_max_scale_sigma); 0: none.
  double init_mono_accel_error = 0.1;
  /// The mono alignment is tried only when the accelerometer's excitation over its window
  /// (accelerationChange, visual_inertial_initializer.hpp) reaches this (m/s²; 0: always), ...
  double init_mono_min_accel_change = 0.3;
  /// ... and at most once per this many seconds (0: every frame).
  double init_mono_attempt_interval = 0.1;
  double init_position_sigma = 1e-3;   ///< m (gauge: the VIO frame is defined by the start)
  double init_yaw_sigma = 1e-3;        ///< rad (gauge)
  double init_tilt_sigma = 0.02;       ///< rad, roll/pitch
  double init_velocity_sigma = 0.05;   ///< m/s static (in motion: 3× this)
  double init_gyro_bias_sigma = 0.02;  ///< rad/s when not estimated from a standstill
  double init_accel_bias_sigma = 0.1;  ///< m/s²
  /// Zero-velocity update when the standstill test of the initialisation passes again (IMU spread
  /// and median parallax over init_window): v = 0 (σ) and no displacement since the previous
  /// clone (σ · frame interval).
  bool zero_velocity_update = true;
  double zero_velocity_sigma = 0.005;  ///< m/s

  // ---- linearisation
  /// First-estimate Jacobians (Huang et al. 2008; Li & Mourikis 2013, "High-precision, consistent
  /// EKF-based visual-inertial odometry"): every Jacobian involving a pose clone uses the clone's
  /// first estimate (its propagated value), and the IMU transition uses the first estimates of
  /// the previous state, so that the linearised system keeps the four unobservable directions
  /// (global position and yaw) of VIO; residuals use the current estimates. Without it the filter
  /// gains spurious information along them and becomes overconfident over long flights.
  bool first_estimate_jacobians = true;
  /// s after initialisation before clones get first estimates (until then Jacobians use the
  /// current estimates): the first estimates of the initialisation transient, when the
  /// corrections are large, would linearise the whole window badly (measured on the simulated
  /// circle: RMSE +30 % with 0 s, unchanged with 2 s; docs/vio_estimator.md).
  double first_estimate_delay = 2.0;

  // ---- online calibration
  /// Camera-IMU extrinsics T_IC per camera as 6-dim pose blocks with the priors below. Measured
  /// (tests/fusion/test_replay_extrinsics.cpp, docs/vio_estimator.md "Extrinsic calibration"):
  /// the rotation converges from 1 deg off to 0.014 deg with first-estimate Jacobians; the
  /// translation converges (to about 1 cm) only with first_estimate_jacobians off: with them it
  /// degrades the trajectory (0.164 vs 0.054 m on the 45 s figure-eight, 3.3 m on the 60 m
  /// lawnmower). Calibrate the translation with extrinsic_translation_sigma ~0 (held) or with
  /// first_estimate_jacobians: false.
  bool calibrate_extrinsics = false;
  double extrinsic_rotation_sigma = 0.01;     ///< rad
  double extrinsic_translation_sigma = 0.01;  ///< m
  /// Camera-IMU time offset t_d, s: a frame stamped t_cam was taken at IMU time t_cam + t_d
  /// (Kalibr's timeshift_cam_imu convention). The value used when calibrate_time_offset is off
  /// and the start value when it is on.
  double time_offset = 0.0;
  /// Online time-offset calibration (Li & Mourikis 2014, "Online temporal calibration for
  /// camera-IMU systems: theory and algorithms", IJRR 33(7)): t_d is a 1-dim parameter block; a
  /// clone made at IMU time τ = t_cam + t̂_d (the estimate then) stands for the image taken at
  /// τ + (t_d − t̂_d), predicted from the clone with its angular rate and velocity at τ, so every
  /// visual row gets ∂z/∂t_d = ∂z/∂[δθ; δp] · [ω; v].
  bool calibrate_time_offset = false;
  double time_offset_sigma = 0.005;  ///< s, prior 1-σ of t_d around time_offset

  // ---- state order
  /// The IMU extra blocks (velocity, biases) first in the state instead of last. Every
  /// propagation marginalizes the old velocity (and at a renewal the old bias) right after
  /// appending the new one; in front, that is a sweep past the few columns of the new blocks
  /// instead of past the whole state (an information-form marginalization costs O(d n²) for a
  /// block with n columns in front of it), and the visual
  /// updates, which never touch the extra, no longer carry its columns. Rows on the first block
  /// are dense over the whole state, so a backend client whose rows touch the velocity on every
  /// epoch (GNSS Doppler, the fusion sets it) wants it last. bench_vio_estimator /50 (the target
  /// frame): float 1.05–1.08 → 1.00–1.02 ms, double 1.32–1.38 → 1.24–1.26 ms
  /// (docs/vio_estimator.md).
  bool imu_extra_first = true;
  /// Seconds between renewals of the IMU bias block (gyroscope and accelerometer biases). The
  /// newest IMU state is a velocity block (replaced at every propagation, with the white noise of
  /// the interval) and a bias block, which the propagations in between keep: their transition rows
  /// act on it and its random walk is summed until the next renewal, which adds it at once
  /// (σ_b²·T over the T since the last renewal; left out: the walk's correlation with the
  /// velocity it drives within the interval, σ_ba²·T³/3, 3 % of σ_a²·T for EuRoC's IMU at
  /// T = 0.2 s; docs/vio_estimator.md "Bias renewal"). A replaced block is
  /// marginalized, which costs O(d n²) when it is not in front (imu_extra_first false: the GNSS
  /// modes), so renewing the 6 bias columns every 0.2 s instead of every frame moves 4.5 instead
  /// of 9 columns per frame at 20 Hz. 0 renews at every propagation (the exact discrete model).
  double imu_bias_renewal = 0.2;

  /// Precision the application should instantiate (SriSwfEstimator<float> or <double>).
  bool use_float = false;
  /// Rotations of a float filter's QR steps (updates, propagation, including the GNSS rows a
  /// backend client adds): true (default) always blocked Householder; false sri's kAuto, which
  /// switches a step to Givens rotations when its rows are 10³ heavier than the lightest pivot
  /// of R they meet (sri::SriOptions::auto_givens_ratio_float). In VIO that is almost every
  /// step (the unobservable directions keep light pivots), and the Givens chains' rounding moves
  /// the float estimate away from the double one on long flights: ten simulated flights (feature
  /// tracks) float − double RMSE +1.1 % on average, up to +6.7 % with kAuto, −0.01 % and within
  /// ±0.7 % with Householder; a rendered 3 km flight +45 % vs +1.8 % (docs/vio_estimator.md).
  /// Double filters are not affected (their switch is at 10¹⁰).
  bool float_householder = true;

  /// Throws std::invalid_argument naming the first bad value.
  void validate() const;
};

/// YAML configuration (all keys optional except cameras, unknown keys are errors; with `defaults`
/// the file's keys change a copy of it, and cameras may be left out when it has them, e.g. a
/// tuning file applied to a dataset's calibration):
///   imu: {gyroscope_noise_density, gyroscope_random_walk, accelerometer_noise_density,
///         accelerometer_random_walk, rate_hz}  or  imu_yaml: <EuRoC/Kalibr imu yaml path>
///   gravity, pixel_noise, surface_noise, window, max_slam_features, min_track_msckf, min_depth, max_depth,
///   min_baseline_ratio, chi2_probability, max_msckf_per_frame, reanchor_sigma, lockout_reset_s,
///   position_random_walk, attitude_random_walk,
///   init: {window, static_max_accel_std, static_max_gyro_std, static_max_parallax, static_without_tracks, in_motion,
///          motion_frames, mono_in_motion, mono_motion_frames, mono_max_scale_sigma, mono_gyro_bias, mono_max_gyro_bias, mono_accel_error, mono_min_accel_change, mono_attempt_interval, position_sigma, yaw_sigma, tilt_sigma, velocity_sigma,
///          gyro_bias_sigma, accel_bias_sigma}, zero_velocity_update, zero_velocity_sigma,
///   first_estimate_jacobians, first_estimate_delay, calibrate_extrinsics, extrinsic_rotation_sigma, extrinsic_translation_sigma,
///   time_offset, calibrate_time_offset, time_offset_sigma, imu_extra_first, imu_bias_renewal, precision: double | float,
///   float_householder,
///   cameras: [<EuRoC camera sensor.yaml path>, ...]  or  camchain: <Kalibr camchain path>
/// Relative paths are relative to the YAML file's folder. Errors: gvins::ParseError naming the
/// file, line and field.
SriSwfConfig loadSriSwfConfig(const std::string& path, const SriSwfConfig* defaults = nullptr);
SriSwfConfig parseSriSwfConfig(std::string_view text, const std::string& name,
                               const std::string& base_dir = ".", const SriSwfConfig* defaults = nullptr);

/// First-estimate IMU transition (see SriSwfConfig::first_estimate_jacobians): replaces the
/// blocks ∂δv₁/∂δθ₀ and ∂δp₁/∂δθ₀ of Φ (ImuErr order, right rotation perturbation) by
/// −[v₁ − v₀ − g Δt]× R₀ and −[p₁ − p₀ − v₀ Δt − ½ g Δt²]× R₀ with (R₀, p₀, v₀) the first estimate
/// of the state at the start and (R₁, p₁, v₁) the propagated state (g = (0, 0, −gravity)), and
/// adds to ∂δθ₁/∂δθ₀ the rank-one term that maps R₀ᵀe_z onto R₁ᵀe_z. With (R₀, p₀, v₀) equal to
/// the estimate Φ was computed at, Φ is unchanged; with any first estimate, Φ maps the yaw and
/// translation directions of the start state onto those of the propagated one (observability:
/// Φ N₀ = N₁, in θ too).
void applyFirstEstimates(Eigen::Matrix<double, 15, 15>& Phi, const Eigen::Matrix3d& R0, const Eigen::Vector3d& p0,
                         const Eigen::Vector3d& v0, const Eigen::Matrix3d& R1, const Eigen::Vector3d& p1,
                         const Eigen::Vector3d& v1, double dt, double gravity);

/// What processFrame did.
struct FrameResult {
  bool initialized = false;  ///< estimator initialised (after this frame)
  bool updated = false;      ///< at least one visual update applied this frame
  double estimator_ms = 0;   ///< wall-clock time of processFrame
  int msckf_features = 0;    ///< MSCKF features used in the update
  int slam_features = 0;     ///< SLAM features in the state after the frame
  bool zero_velocity = false;  ///< a zero-velocity update was applied (standstill detected)
  int gated_features = 0;      ///< features whose rows reached a χ² gate this frame
  int rejected_features = 0;   ///< ... of which the gate rejected
  /// The frame ended a visual lock-out (SriSwfConfig::lockout_reset_s): the state was dropped
  /// and the estimator is initialising again (initialized is false).
  bool reset = false;
  /// Before initialisation: why the estimator has not initialised yet (kInitialized once it has).
  InitStatus init_status = InitStatus::kCollecting;
};

template <typename Scalar>
class SriSwfEstimator final : public EstimatorBackend<Scalar> {
 public:
  using typename EstimatorBackend<Scalar>::Matrix;
  using typename EstimatorBackend<Scalar>::Vector;

  /// Throws std::invalid_argument for an invalid configuration.
  explicit SriSwfEstimator(const SriSwfConfig& config);
  ~SriSwfEstimator() override;
  SriSwfEstimator(const SriSwfEstimator&) = delete;
  SriSwfEstimator& operator=(const SriSwfEstimator&) = delete;

  // ------------------------------------------------------------------ driver
  /// Buffers one IMU sample (strictly increasing stamps; older or repeated ones are ignored).
  void addImu(const ImuSample& sample);
  /// Processes one camera time step. The IMU must have been added up to the frame time (a frame
  /// not covered by the IMU buffer is skipped: nothing changes, updated = false).
  FrameResult processFrame(const FeatureFrame& frame);
  /// 6×6 marginal covariance of the newest pose, [δθ; δp] (right rotation perturbation of R_WI,
  /// imu_state.hpp). Zero before initialisation.
  Eigen::Matrix<double, 6, 6> poseCovariance() const;
  /// Covariance of the newest 15-dim ImuErr state ([δθ δp δv δbg δba]).
  Eigen::Matrix<double, 15, 15> imuCovariance() const;
  const SriSwfConfig& config() const { return config_; }
  /// Current window: clone times, oldest first (the newest = newestTime()).
  std::vector<std::int64_t> cloneTimes() const;
  /// The clones' pose blocks (kPose [δθ; δp]), in the order of cloneTimes().
  std::vector<sri::BlockId> cloneBlocks() const;
  int slamFeatureCount() const;
  /// Extrinsic pose T_IC of camera `cam` (estimated when calibrate_extrinsics).
  Eigen::Matrix4d cameraExtrinsic(int cam) const;
  /// Camera-IMU time offset t_d (s, SriSwfConfig::time_offset) and its 1-σ: the estimate when
  /// calibrate_time_offset (σ from the filter), else the configured value with σ = 0.
  struct TimeOffset {
    double value = 0.0;
    double sigma = 0.0;
  };
  TimeOffset timeOffset() const;
  /// How far past a frame's stamp the IMU must reach before processFrame (ns, ≥ 0): the
  /// configured offset plus five prior σ when calibrating. A frame whose IMU time t_cam + t̂_d is
  /// not covered by the buffer is skipped.
  std::int64_t imuLeadNs() const;
  /// The underlying filter (tests, diagnostics).
  const sri::SriFilter<Scalar>& filter() const;
  /// The four unobservable directions (columns: global yaw about the z axis through the origin,
  /// x, y, z translation) in the filter's error state (filter().dim() rows), built from the
  /// linearisation points of the Jacobians (first estimates). With exact arithmetic and
  /// first-estimate Jacobians no step adds information along them: updates keep the Gram
  /// (R N)ᵀ(R N), propagation and marginalization only reduce it (tests/vio/test_sri_swf_nullspace.cpp).
  Eigen::MatrixXd unobservableDirections() const;
  /// Diagnostics: called after each filter operation of processFrame with its name
  /// ("propagate", "zupt", "slam_update", "correct", "msckf_update", "slam_init", "reanchor",
  /// "marginalize"). Empty function: none.
  void setStepObserver(std::function<void(const char* step)> observer);
  /// Drops the whole state (clones, features, client blocks) and starts initialising again with
  /// the next frames; the buffered IMU samples are kept. Block ids of the old state are never
  /// reused; generation() changes at once and again when the new state is created. Called by processFrame
  /// after a visual lock-out; a driver may call it too (e.g. a user's restart). Calibrated
  /// extrinsics and time offset carry over as the next state's start values (with their
  /// configured prior σ) when they lie within 3 σ of the configuration; otherwise the
  /// configured values start again.
  void reset();
  /// Number of resets so far (lock-outs and reset() calls).
  int resets() const;

  // ------------------------------------------------------------------ EstimatorBackend
  bool initialized() const override;
  std::uint64_t generation() const override;
  std::int64_t newestTime() const override;
  ImuState newestImuState() const override;
  ImuBlocks newestImuBlocks() const override;
  Eigen::Vector3d gravity() const override;
  ImuNoise imuNoise() const override;
  std::optional<ImuIntegration> integrateToNewest(std::int64_t t_ns) const override;
  std::optional<Eigen::Vector3d> angularRateAt(std::int64_t t_ns) const override;
  bool initializeFrom(const ExternalInitialState& s) override;
  bool restart() override {
    reset();
    return true;
  }
  std::span<const ImuSample> bufferedImu() const override;

  sri::BlockId addBlock(const sri::BlockSpec& spec, const sri::BlockEstimate<Scalar>& estimate,
                        const sri::Prior<Scalar>& prior,
                        ClientBlockRegion region = ClientBlockRegion::kParameters) override;
  std::vector<sri::BlockId> propagate(const sri::Propagation<Scalar>& step,
                                      ClientBlockRegion region = ClientBlockRegion::kParameters) override;
  void marginalize(std::span<const sri::BlockId> ids) override;
  WorldFrameChange reanchorWorld(sri::BlockId frame) override;
  bool contains(sri::BlockId id) const override;
  const sri::BlockEstimate<Scalar>& estimate(sri::BlockId id) const override;
  Matrix covariance(std::span<const sri::BlockId> ids) const override;
  bool informed(std::span<const sri::BlockId> ids) const override { return filter().informed(ids); }
  std::optional<sri::ChiSquare<Scalar>> chiSquare(const sri::Measurement<Scalar>& m) const override;
  BackendUpdate<Scalar> update(const sri::Measurement<Scalar>& m, double gate_probability) override;

 private:
  struct Impl;
  SriSwfConfig config_;
  std::unique_ptr<Impl> impl_;
};

extern template class SriSwfEstimator<float>;
extern template class SriSwfEstimator<double>;

}  // namespace gvins::vio
