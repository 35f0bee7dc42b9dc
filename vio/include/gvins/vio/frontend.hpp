// The visual front end: cam0 feature tracking (KLT, RANSAC, grid detection), stereo matching
// into cam1, undistortion through the camera models; one FeatureFrame per camera time step.
// Not thread-safe; FrontendThread runs it on its own thread.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

#include "gvins/vio/feature_frame.hpp"
#include "gvins/vio/feature_tracker.hpp"
#include "gvins/vio/sensor_yaml.hpp"
#include "gvins/vio/stereo_matcher.hpp"

namespace gvins::vio {

enum class Equalization {
  None,
  Histogram,  ///< global histogram equalisation (cv::equalizeHist), ~0.2 ms CPU per 752x480 image
  Clahe       ///< CLAHE (Zuiderveld 1994; clip 3, 8x8 tiles), ~2.5 ms per image
};

struct FrontendConfig {
  FeatureTrackerConfig tracker;
  /// Stereo matching; its KLT window and pyramid levels are always those of `tracker.klt`
  /// (the left pyramid is shared).
  StereoConfig stereo;
  bool useStereo = true;  ///< match into cam1 when a cam1 image is given
  /// Contrast equalisation of every image before tracking. Lucas-Kanade assumes equal
  /// brightness; the two EuRoC cameras differ in gain by ~10 %, and equalisation doubles the
  /// stereo matches on V1_01 (45 of 150 without, ~100 with either method).
  Equalization equalize = Equalization::Histogram;
};

class StereoFrontend {
 public:
  /// cam1 may be null (mono). Extrinsics come from the calibrations' T_BS.
  StereoFrontend(const FrontendConfig& config, const CameraCalibration& cam0, const CameraCalibration* cam1 = nullptr);
  ~StereoFrontend();
  StereoFrontend(StereoFrontend&&) noexcept;
  StereoFrontend& operator=(StereoFrontend&&) noexcept;

  /// Processes one time step. `left`/`right` are 8-bit gray images of the calibrated size
  /// (std::invalid_argument otherwise); `right` may be empty. R_cur_prev optionally rotates the
  /// previous cam0 frame into the current one (gyro prediction for the KLT start points).
  FeatureFrame process(std::int64_t t_ns, const cv::Mat& left, const cv::Mat& right = cv::Mat(),
                       const Eigen::Matrix3d* R_cur_prev = nullptr);

  const CameraModel& camera(int i) const;
  bool stereo() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace gvins::vio
