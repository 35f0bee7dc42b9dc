// Private: the state of the SRI-SWF estimator (sri_swf_estimator.hpp) that its units share —
// the filter, the window of pose clones, the newest IMU blocks, feature tracks and SLAM
// features, calibration blocks, first estimates — and the accessors every unit uses. The units
// (swf_propagation, zero_velocity_update, slam_update, msckf_update, window_marginalization)
// each hold one step of a frame; sri_swf_estimator.cpp runs them in order. docs/vio_estimator.md
// describes the state and the steps.
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <optional>
#include <span>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "gvins/sri/chi_square.hpp"
#include "gvins/sri/sri_filter.hpp"
#include "gvins/vio/imu_propagation.hpp"
#include "gvins/vio/sri_swf_estimator.hpp"
#include "gvins/vio/visual_inertial_initializer.hpp"
#include "gvins/vio/visual_jacobians.hpp"
#include "gvins/vio/world_frame_change.hpp"

namespace gvins::vio::detail {

/// The pose (R_WI, p_WI) of a pose block's estimate, in double.
template <typename S>
PoseEstimate poseOf(const sri::BlockEstimate<S>& e) {
  PoseEstimate p;
  p.R_WI = e.rotation.template cast<double>().normalized().toRotationMatrix();
  p.p_WI = e.vector.template cast<double>().head(3);
  return p;
}

/// A pose block's estimate from a rotation and a position.
template <typename S>
sri::BlockEstimate<S> poseEstimate(const Eigen::Matrix3d& R, const Eigen::Vector3d& p) {
  return sri::BlockEstimate<S>::fromPose(Eigen::Quaterniond(R).normalized().cast<S>(), p.cast<S>());
}

template <typename Scalar>
struct SwfState {
  using Filter = sri::SriFilter<Scalar>;
  using Meas = sri::Measurement<Scalar>;
  using MatrixS = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>;
  using VectorS = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>;

  /// One observation of a track: the clone it was made at, the camera, normalised coordinates.
  struct Obs {
    sri::BlockId clone;
    int cam = 0;
    Eigen::Vector2d z = Eigen::Vector2d::Zero();
  };
  struct Track {
    std::vector<Obs> obs;  // in time order, clones in the window only
    int frames = 0;        // frames with a cam0 observation in `obs`
  };
  struct Clone {
    sri::BlockId id;
    std::int64_t t_ns = 0;
  };
  /// A SLAM feature: its block (anchored inverse depth) and the clone it is anchored at.
  struct Slam {
    sri::BlockId block;
    sri::BlockId anchor;
    bool seen = false;  // observed in the current frame
  };
  /// Motion of a clone at its IMU time τ = t_cam + t_d (time-offset calibration): body angular
  /// rate (bias-corrected), world velocity and the t_d estimate τ was made with.
  struct CloneMotion {
    Eigen::Vector3d w = Eigen::Vector3d::Zero();
    Eigen::Vector3d v = Eigen::Vector3d::Zero();
    double td = 0.0;
  };

  /// `first_block_id`: where the filter's block ids start (after a reset: the old filter's next id).
  SwfState(const SriSwfConfig& c, std::uint64_t first_block_id);

  const SriSwfConfig& cfg;
  Filter f;
  ImuPropagator prop;
  std::vector<ImuSample> imu;
  bool initialized = false;
  std::int64_t t_newest = 0;
  ImuBlocks newest;
  std::int64_t t_bias = 0;  // when the bias block was last renewed (SriSwfConfig::imu_bias_renewal)
  std::deque<Clone> clones;
  std::vector<CameraExtrinsic> ext_fixed;  // configured (or carried over a reset) camera extrinsics
  double td_start = 0.0;  // t_d before the time-offset block exists: configured, or carried over a reset
  std::vector<sri::BlockId> ext_ids;  // calibrate_extrinsics
  sri::BlockId td_id;                 // calibrate_time_offset: t_d (1-dim)
  std::unordered_map<std::uint64_t, CloneMotion> clone_motion;
  std::vector<double> sigma_n;  // per camera: pixel noise in normalised units
  std::unordered_map<std::uint64_t, Track> tracks;
  std::unordered_map<std::uint64_t, Slam> slam;
  VisualInertialInitializer initializer;
  std::unordered_map<std::uint64_t, PoseEstimate> pose_cache;
  std::unordered_map<std::uint64_t, PoseEstimate> obs_pose_cache;  // poses at the image times
  // First estimates (first_estimate_jacobians): of every clone (its propagated pose) and of the
  // newest velocity.
  std::unordered_map<std::uint64_t, PoseEstimate> fe_pose;
  Eigen::Vector3d fe_v = Eigen::Vector3d::Zero();
  std::int64_t t_init = 0;
  double frame_td = 0.0;  // t_d the current frame was shifted by (s, exact to the ns)
  mutable sri::ChiSquareQuantiles chi2_thr;   // visual gates (cfg.chi2_probability)
  sri::ChiSquareQuantiles client_gate;         // client gates (update(m, p))
  std::function<void(const char*)> observer;  // setStepObserver (diagnostics)
  std::optional<std::int64_t> client_update_ns;  // newest applied client update (IMU time)
  std::uint64_t generation = 0;  // EstimatorBackend::generation: + 1 per initialisation and per reset
  int resets = 0;

  void notify(const char* step) {
    if (observer) observer(step);
  }
  void clearCaches() {
    pose_cache.clear();
    obs_pose_cache.clear();
  }
  bool stereo() const { return cfg.cameras.size() > 1; }

  // ------------------------------------------------------------------ state access
  /// Mixed precision (sri_filter.hpp): blocks are created with values rounded to Scalar; a float
  /// filter then gets the double value it was computed as (R and r do not change).
  void setExact(sri::BlockId id, const sri::BlockEstimate<double>& v);
  CameraExtrinsic ext(int cam) const;
  const PoseEstimate& pose(sri::BlockId id);
  /// Current t_d (s): the filter's estimate when calibrating, else td_start (the configured
  /// value, or the one carried over a reset).
  double timeOffset() const;
  /// Pose of clone `id` at the time its image was taken: the clone itself unless the time offset
  /// is calibrated, then the clone moved by its angular rate and velocity over t̂_d − td(clone).
  const PoseEstimate& obsPose(sri::BlockId id);
  /// ∂p_C/∂t_d of an observation from clone `id` (cp: its CameraPoint at the Jacobian's pose).
  Eigen::Vector3d timeOffsetColumn(sri::BlockId id, const CameraPoint& cp) const;
  /// Records the motion of clone `id` (state `s`, made with t_d = td) when calibrating t_d.
  void recordCloneMotion(sri::BlockId id, const ImuState& s, double td);
  /// Linearisation point of a clone for Jacobians: its first estimate, or the current estimate.
  const PoseEstimate& poseJ(sri::BlockId id);
  /// Whether the Jacobians linearize the newest velocity at fe_v: with first estimates, once the
  /// newest pose has one (unobservableDirections() and reanchorWorld() build N and B from it).
  bool velocityHasFirstEstimate() const;
  /// The bias block's value [bg; ba] of an IMU state.
  static Eigen::Matrix<double, 6, 1> biasVector(const ImuState& s);
  ImuState newestState() const;

  // ------------------------------------------------------------------ IMU buffer
  void addImu(const ImuSample& s);
  /// Drops samples no longer needed (amortised: in chunks of 2000).
  void trimImu();
  std::span<const ImuSample> imuSpan() const { return {imu.data(), imu.size()}; }
  bool imuCovers(std::int64_t t0, std::int64_t t1) const { return vio::imuCovers(imuSpan(), t0, t1); }

  // ------------------------------------------------------------------ state creation
  /// The first state: the newest pose (the window's first clone), calibration blocks, bias and
  /// velocity, with their priors from Pimu (ImuErr order, external_initial_state.hpp; the
  /// correlations between pose, velocity and bias are dropped).
  void createState(const ImuState& s, const Matrix15d& Pimu);
  /// Before a reset: carries the calibrated extrinsics and time offset into `next` when they
  /// lie within 3 prior σ of the configuration (see SriSwfEstimator::reset).
  void carryCalibration(SwfState& next) const;

  // ------------------------------------------------------------------ placement
  /// Where the IMU extra (velocity and bias blocks) goes (SriSwfConfig::imu_extra_first).
  sri::Placement extraPlacement() const;
  /// A client's block: kFront in front of everything; parameters after the newest pose, i.e.
  /// at the back, or before the extra's blocks when they are last.
  sri::Placement clientPlacement(ClientBlockRegion region) const;

  // ------------------------------------------------------------------ visual rows
  /// Adds the frame's observations to the tracks (from the newest clone); marks SLAM features
  /// observed in it as seen.
  void addObservations(const FeatureFrame& frame);
  /// Declares the block columns of a feature's rows at once (one allocation): the feature and
  /// anchor blocks (if valid), the observing clones, the extrinsics, the time offset.
  void declareBlocks(Meas& m, sri::BlockId feature, sri::BlockId anchor, const std::vector<Obs>& obs);
  /// 1 / σ of an observation in normalised coordinates: pixel noise and surface noise at `depth`.
  double inverseSigma(int cam, double depth) const;
  /// χ² threshold of the visual gates for `dof` rows (infinite with chi2_probability ≥ 1).
  double chi2Threshold(int dof) const;
  /// The χ² gate of rows against the whole filter (SriFilter::chiSquare).
  bool gate(const Meas& m) const;

  // ------------------------------------------------------------------ gauge
  /// EstimatorBackend::reanchorWorld: every clone and the velocity change variables
  /// (world_frame_change.hpp); the first estimates and clone velocities follow.
  WorldFrameChange reanchorWorld(sri::BlockId frame);
  /// SriSwfEstimator::unobservableDirections.
  Eigen::MatrixXd unobservableDirections() const;

 private:
  std::vector<sri::BlockId> decl_ids_;  // declareBlocks' buffers (capacity kept)
  std::vector<int> decl_dims_;
};

extern template struct SwfState<float>;
extern template struct SwfState<double>;

}  // namespace gvins::vio::detail
