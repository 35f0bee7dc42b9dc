// Stereo matching of cam0 features into cam1: pyramidal Lucas-Kanade left -> right started at a
// depth-based prediction, forward-backward check, then the epipolar constraint of the calibrated
// pair (essential matrix E = [t]x R, Hartley & Zisserman ch. 9) on undistorted points and a
// positive-depth check of the two-ray triangulation. Works for unrectified, distorted images.
#pragma once

#include <optional>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core/types.hpp>

#include "gvins/vio/camera_model.hpp"
#include "gvins/vio/feature_tracker.hpp"

namespace gvins::vio {

struct StereoConfig {
  KltParams klt;
  double maxEpipolarError = 1.5;  ///< pixels (at cam1's focal length) from the epipolar line
  double minDepth = 0.1;          ///< m; also rejects matches with the wrong disparity sign
  double defaultDepth = 5.0;      ///< m, for predicting right pixels before any match exists
  /// Pyramid levels above the image for features whose cam1 pixel is predicted from their last
  /// match (moved by the cam0 motion): off by a fraction of a pixel, so the full image suffices.
  /// The others start from the depth prediction and use all `klt.levels`.
  int priorLevels = 0;
};

class StereoMatcher {
 public:
  /// T_C1C0 maps cam0 coordinates to cam1 coordinates (x1 = R x0 + t); from EuRoC T_BS:
  /// T_C1C0 = T_BS(cam1)^-1 * T_BS(cam0).
  StereoMatcher(const CameraModel& cam0, const CameraModel& cam1, const Eigen::Matrix4d& T_C1C0,
                const StereoConfig& config = {});

  /// Matches `left` points (cam0 pixels) into the right image. `right` holds initial guesses:
  /// entries with NaN x are predicted from `predictionDepth` (m). Writes matched cam1 pixels into
  /// `right` and status (1 = accepted).
  void match(const ImagePyramid& leftImage, const ImagePyramid& rightImage, const std::vector<cv::Point2f>& left,
             std::vector<cv::Point2f>& right, std::vector<unsigned char>& status, double predictionDepth) const;

  /// cam1 pixel of the cam0 pixel's ray at `depth` (m) along z in cam0.
  std::optional<Eigen::Vector2d> predict(const Eigen::Vector2d& pixel0, double depth) const;
  /// Distance (pixels at cam1's focal length) of n1 from the epipolar line of n0 (undistorted
  /// normalised coordinates).
  double epipolarError(const Eigen::Vector2d& n0, const Eigen::Vector2d& n1) const;
  /// Depth along cam0's z of the least-squares intersection of the two rays; nullopt for
  /// (nearly) parallel rays or a point behind either camera.
  std::optional<double> depth(const Eigen::Vector2d& n0, const Eigen::Vector2d& n1) const;

  const Eigen::Matrix3d& R() const { return R_; }
  const Eigen::Vector3d& t() const { return t_; }

 private:
  CameraModel cam0_, cam1_;
  Eigen::Matrix3d R_, E_;
  Eigen::Vector3d t_;
  StereoConfig cfg_;
};

}  // namespace gvins::vio
