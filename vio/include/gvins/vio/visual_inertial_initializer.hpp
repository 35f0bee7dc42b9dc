// Initialisation of the SRI-SWF estimator's state (docs/vio_estimator.md, "Initialisation"):
// standstill from the IMU and the feature parallax, and the in-motion visual-inertial alignments
// (stereo: stereo_inertial_alignment, mono: mono_inertial_alignment). SriSwfEstimator buffers
// its frames here until one of them gives the state to start from.
#pragma once

#include <cstdint>
#include <deque>
#include <optional>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "gvins/vio/feature_frame.hpp"
#include "gvins/vio/imu_propagation.hpp"
#include "gvins/vio/imu_sample.hpp"
#include "gvins/vio/imu_state.hpp"
#include "gvins/vio/init_status.hpp"
#include "gvins/vio/sri_swf_estimator.hpp"
#include "gvins/vio/visual_jacobians.hpp"

namespace gvins::vio {

/// Result of an in-motion alignment over frames t0..tN: gravity and velocity in the IMU frame at
/// t0, the gyro bias it used (zero when not estimated) and the relative 1-σ of its metric scale
/// (mono; 0: stereo, whose scale is the baseline's).
struct MotionAlignment {
  std::int64_t t0 = 0;
  std::int64_t tN = 0;
  Eigen::Vector3d gravity_I0 = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity_I0 = Eigen::Vector3d::Zero();
  Eigen::Vector3d gyro_bias = Eigen::Vector3d::Zero();
  double scale_sigma = 0.0;
};

/// The state an initialisation starts the filter from: the IMU state at the newest frame and its
/// prior (attitude covariance in the world frame, velocity and gyro-bias σ).
struct InitialState {
  ImuState state;
  Eigen::Matrix3d P_theta_world = Eigen::Matrix3d::Zero();
  double sigma_v = 0.0;
  double sigma_bg = 0.0;
};

/// Median of v (the upper one for an even count; 0 when empty).
double initMedian(std::vector<double> v);

/// True when the buffer holds samples at or before t0 and at or after t1.
inline bool imuCovers(std::span<const ImuSample> imu, std::int64_t t0, std::int64_t t1) {
  return !imu.empty() && imu.front().t_ns <= t0 && imu.back().t_ns >= t1;
}

/// Outcome of the standstill test.
enum class Standstill {
  kUndecided,     ///< the IMU does not cover the window yet, or no frame is half a window old
  kNo,            ///< the IMU moves
  kImuOnly,       ///< the IMU is at rest (also: mean specific force within 3 static_max_accel_std of
                  ///< gravity, mean rate within init_mono_max_gyro_bias) and no frame of the window
                  ///< has 5 features or more to confirm it
  kFeaturesMove,  ///< the IMU is at rest but the features move, or are seen and not tracked through
                  ///< the window: constant velocity
  kYes,           ///< IMU at rest and median feature displacement within static_max_parallax
};

/// Whether the IMU is at rest over [t0, t1]: at least 10 samples, per-axis std of the
/// accelerometer within static_max_accel_std and of the gyro within static_max_gyro_std; ma, mg
/// are the mean specific force and angular rate of the n samples (also when it is not at rest).
bool imuAtRest(const SriSwfConfig& cfg, std::span<const ImuSample> imu, std::int64_t t0, std::int64_t t1,
               Eigen::Vector3d& ma, Eigen::Vector3d& mg, int& n);

/// Standstill test over the last init_window: accelerometer/gyro spread (imuAtRest) and the median
/// feature displacement against the oldest frame of `frames` in the window (at least half a window
/// old). Unless kNo or kUndecided, ma, mg are the mean specific force and angular rate over the
/// window of n samples.
Standstill standstill(const SriSwfConfig& cfg, std::span<const ImuSample> imu, const FeatureFrame& frame,
                const std::deque<FeatureFrame>& frames, Eigen::Vector3d& ma, Eigen::Vector3d& mg, int& n);

/// Stereo depth of a cam0 observation: d with p_C0 = d (n0, 1), within [min_depth, max_depth].
std::optional<double> stereoDepth(const SriSwfConfig& cfg, const CameraExtrinsic& e0, const CameraExtrinsic& e1,
                                  const FeatureObservation& o);

/// Linear visual-inertial alignment over the last init_motion_frames stereo frames.
std::optional<MotionAlignment> alignStereoInMotion(const SriSwfConfig& cfg, const std::deque<FeatureFrame>& init_frames,
                                                   std::span<const ImuSample> imu, const CameraExtrinsic& e0,
                                                   const CameraExtrinsic& e1, InitStatus* why = nullptr);

/// Figures of a mono in-motion alignment that reached the scale (mono_inertial_alignment.cpp).
struct MonoAlignmentQuality {
  int frames = 0;            ///< frames aligned
  double span_s = 0.0;       ///< first to last of them
  double scale = 0.0;        ///< metres per unit of the up-to-scale structure
  double scale_sigma = 0.0;  ///< relative 1-σ of the scale from the fit's residuals (gravity direction free)
  double sensitivity = 0.0;  ///< relative scale change under init_mono_accel_error (largest over the axes)
};

/// Mono in-motion alignment over the last init_mono_motion_frames frames (mono_inertial_alignment.cpp).
/// `why` (if given) receives the reason of a failure; `imu_intervals` (if given) is increased by
/// the IMU sample intervals integrated (one pass over the window, two with a gyro bias);
/// `quality` (if given) receives the scale's figures once the fit ran (also when they reject it).
std::optional<MotionAlignment> alignMonoInMotion(const SriSwfConfig& cfg, const std::deque<FeatureFrame>& init_frames,
                                                 std::span<const ImuSample> imu, const CameraExtrinsic& e0,
                                                 InitStatus* why = nullptr, std::int64_t* imu_intervals = nullptr,
                                                 MonoAlignmentQuality* quality = nullptr);

/// The excitation of the accelerometer over [t0, t1]: the largest distance (m/s²) of a 0.1 s mean
/// of the specific force, rotated into the IMU frame at t0 by the gyro, from the mean of those
/// means. A constant acceleration (cruise, a steady climb) gives about 0; the mono alignment
/// needs it to change, since a constant one trades against gravity and velocity. nullopt: the
/// IMU does not cover the interval or it is shorter than 0.2 s.
std::optional<double> accelerationChange(std::span<const ImuSample> imu, std::int64_t t0, std::int64_t t1);

/// Work done by an initialiser since its construction (issue 43: the cost before initialisation
/// is bounded by counts, not times): frames tried, mono alignment attempts and the IMU sample
/// intervals they integrated.
struct InitWork {
  std::int64_t frames = 0;
  std::int64_t mono_attempts = 0;
  std::int64_t mono_imu_intervals = 0;
};

/// Buffers the frames before initialisation and tries, per frame, the standstill and (when
/// configured) the in-motion alignment of the rig (stereo when the configuration has two cameras).
class VisualInertialInitializer {
 public:
  explicit VisualInertialInitializer(const SriSwfConfig& cfg) : cfg_(cfg), prop_(cfg.imu, cfg.gravity) {}
  /// Adds `frame` and tries to initialise; `ext` are the cameras' extrinsics (fixed during the
  /// initialisation), `imu` the buffered samples. On success the buffer is cleared.
  std::optional<InitialState> tryInitialize(const FeatureFrame& frame, std::span<const ImuSample> imu,
                                            const std::vector<CameraExtrinsic>& ext);
  /// Stamp of the oldest buffered frame (the IMU must be kept from shortly before it).
  std::optional<std::int64_t> oldestFrameTime() const {
    if (frames_.empty()) return std::nullopt;
    return frames_.front().t_ns;
  }
  void clear() {
    frames_.clear();
    last_attempt_ns_.reset();
    attempt_interval_ = 0.0;
    status_ = InitStatus::kCollecting;
  }
  /// Why the last tryInitialize did not initialise (kInitialized after it did).
  InitStatus status() const { return status_; }
  const InitWork& work() const { return work_; }

 private:
  std::optional<InitialState> fromStandstill(const FeatureFrame& frame, std::span<const ImuSample> imu);
  InitialState fromMotion(const MotionAlignment& a, std::span<const ImuSample> imu) const;
  std::optional<MotionAlignment> tryMono(const FeatureFrame& frame, std::span<const ImuSample> imu,
                                         const CameraExtrinsic& e0);

  const SriSwfConfig& cfg_;
  ImuPropagator prop_;
  std::deque<FeatureFrame> frames_;
  std::optional<std::int64_t> last_attempt_ns_;  // the last mono alignment attempt ...
  InitStatus last_attempt_status_ = InitStatus::kCollecting;  // ... and what it found
  double attempt_interval_ = 0.0;  // s until the next attempt (back-off; 0: none yet)
  InitStatus status_ = InitStatus::kCollecting;
  Standstill standstill_ = Standstill::kUndecided;  // the standstill test's finding on the last frame
  InitWork work_;
};

}  // namespace gvins::vio
