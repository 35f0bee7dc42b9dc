// Temporal feature tracking in one camera: image pyramids, pyramidal Lucas-Kanade optical flow
// (Bouguet, "Pyramidal implementation of the Lucas Kanade feature tracker", 2000, as implemented
// by OpenCV) with a forward-backward consistency check, fundamental-matrix RANSAC on undistorted
// points (Hartley & Zisserman, ch. 11) and grid detection of new corners; features carry ids and
// track lengths.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>
#include <opencv2/core/types.hpp>

#include "gvins/vio/affine_patch.hpp"
#include "gvins/vio/camera_model.hpp"
#include "gvins/vio/feature_detector.hpp"
#include "gvins/vio/feature_frame.hpp"

namespace gvins::vio {

struct KltParams {
  int window = 21;                    ///< square window side, pixels
  int levels = 3;                     ///< pyramid levels above the full image
  int iterations = 30;
  double epsilon = 0.01;              ///< pixels
  double maxForwardBackward = 0.5;    ///< pixels between the start and the back-tracked point
  int border = 5;                     ///< tracked points closer to the edge are dropped
};

/// An image with its Lucas-Kanade pyramid (levels with precomputed derivatives). The object
/// shares `gray` (no copy) and keeps its own level buffers.
class ImagePyramid {
 public:
  ImagePyramid() = default;
  ImagePyramid(const cv::Mat& gray, const KltParams& params);
  /// Rebuilds the pyramid for a new image of the same size in place: level buffers that no copy
  /// of this object shares any more are reused instead of allocated (a 752x480 pyramid with
  /// derivatives is ~3 MB; fresh pages cost page faults every frame).
  void build(const cv::Mat& gray, const KltParams& params);
  const cv::Mat& image() const { return image_; }
  const std::vector<cv::Mat>& levels() const { return levels_; }
  bool empty() const { return image_.empty(); }

 private:
  cv::Mat image_;
  std::vector<cv::Mat> levels_;
};

/// Lucas-Kanade from `from` to `to` for `pts`. If `useGuess`, `out` holds initial positions in
/// `to` (same size as pts); otherwise it is overwritten. status[i] = 1 if tracked forward, back
/// to within maxForwardBackward of pts[i], and inside the border of `to`. With `backward`
/// (same size as pts), only points with backward[i] != 0 get the backward check (the others are
/// verified by the caller, e.g. against their template).
void trackKlt(const ImagePyramid& from, const ImagePyramid& to, const std::vector<cv::Point2f>& pts,
              std::vector<cv::Point2f>& out, std::vector<unsigned char>& status, const KltParams& p,
              bool useGuess = false, const std::vector<unsigned char>* backward = nullptr);

struct FeatureTrackerConfig {
  GridDetectorConfig grid;
  KltParams klt;
  /// Tracks that have a prediction (the gyro rotation if given; else the feature's own image
  /// step in the last frame, and for new features the median step of the others) are first
  /// tracked with `predictedLevels` pyramid levels above the image, and kept if they moved at
  /// most `predictedMaxCorrection` px from the prediction. All other tracks, and those that fail
  /// there, are tracked from the unpredicted start (previous position, or the rotation
  /// prediction) with all `klt.levels`: a wrong prediction costs time, not tracks. Negative
  /// `predictedLevels`: one pass with all levels for every track.
  int predictedLevels = 1;
  double predictedMaxCorrection = 4.0;  ///< px
  bool ransac = true;
  double ransacThreshold = 1.0;    ///< pixels at the camera's focal length, on undistorted points
  /// Tracks are ended once their image path since detection (the sum of the frame-to-frame
  /// steps) exceeds maxTrackTravel px, or after maxTrackLength images (0: no limit); the
  /// detector then fills the cell again. Frame-to-frame KLT is sub-pixel, but a translation-only
  /// window chained over a patch that rotates and changes scale as the camera moves drifts by
  /// ~0.01-0.03 px per image (docs/vio_frontend.md), while on a still camera it does not: old,
  /// far-travelled tracks stop following one scene point, and the estimator, which takes every
  /// observation of a feature as the same point with white noise, turns that into a biased,
  /// overconfident state (tests RenderedDrift.*).
  double maxTrackTravel = 50.0;  ///< px (0: no limit)
  /// Every tracked position is refined by aligning the track's template (its patch in the
  /// detection image) with the image under an affine warp with gain and bias (affine_patch.hpp):
  /// the position then no longer accumulates the chained KLT's drift. Tracks whose alignment
  /// fails, or lands more than templateMaxCorrection px from the KLT position, are ended. Tracks
  /// whose template could not be taken (untextured in some direction of the affine warp) stay
  /// plain KLT tracks.
  bool alignTemplates = true;
  PatchAlignParams patch;
  /// σ (px) of the Gaussian that smooths the images for the templates and their alignment (0:
  /// none); see affine_patch.hpp.
  double patchSmoothing = 1.0;
  double templateMaxCorrection = 2.0;  ///< px
  /// Tracks with a template skip the KLT forward-backward check: the template alignment
  /// (correlation >= patch.minCorrelation, within templateMaxCorrection of the KLT result)
  /// verifies them instead, at half the KLT cost.
  bool templatesReplaceBackwardCheck = true;
  /// Travel limit (as maxTrackTravel) for tracks refined against their template; 0: no limit.
  double templateMaxTrackTravel = 0.0;
  /// Tracks younger than this many images are not ended by their travel (a fast rotation can
  /// move every feature by > maxTrackTravel in one step; such tracks keep the observations the
  /// estimator needs before they are cut).
  int travelMinTrackLength = 10;
  int maxTrackLength = 0;       ///< images (0: no limit)
  double ransacConfidence = 0.99;
};

/// Tracks the features of one camera from image to image.
class FeatureTracker {
 public:
  FeatureTracker(const CameraModel& camera, const FeatureTrackerConfig& config);

  /// Tracks the current features into `image`, removes outliers, then tops up with new corners.
  /// R_cur_prev (optional) rotates previous-camera-frame vectors into the current camera frame
  /// (e.g. from the gyro); tracks then start at the rotation-predicted pixels.
  void process(const ImagePyramid& image, const Eigen::Matrix3d* R_cur_prev = nullptr,
               FrontendTiming* timing = nullptr);
  /// Optional first half of process() for the same image (8-bit gray, the pyramid's level 0):
  /// smooths it for the template alignment, so that a caller can do this on another thread
  /// while it builds other images' pyramids. process() skips the smoothing when it was prepared.
  void prepareTemplates(const cv::Mat& image);

  const std::vector<cv::Point2f>& points() const { return pts_; }
  /// Position of each feature in the previous image (new features: their current position).
  const std::vector<cv::Point2f>& previousPoints() const { return prevPts_; }
  const std::vector<std::uint64_t>& ids() const { return ids_; }
  const std::vector<int>& trackLengths() const { return lengths_; }
  /// Image path of each track since detection, px.
  const std::vector<float>& trackTravel() const { return travel_; }
  const CameraModel& camera() const { return cam_; }
  const FeatureTrackerConfig& config() const { return cfg_; }

 private:
  // The steps of process(): KLT of every track (trackPredicted: the first, predicted pass),
  // template refinement, RANSAC; keepTracks drops tracks from every per-track vector.
  void trackAll(const ImagePyramid& image, const Eigen::Matrix3d* R_cur_prev, std::vector<cv::Point2f>& cur,
                std::vector<unsigned char>& status) const;
  void trackPredicted(const ImagePyramid& image, const Eigen::Matrix3d* R_cur_prev,
                      const std::vector<cv::Point2f>& start, std::vector<cv::Point2f>& cur,
                      std::vector<unsigned char>& status) const;
  unsigned char needsBackwardCheck(std::size_t i) const;
  std::vector<unsigned char> alignTemplates(const std::vector<cv::Point2f>& before, std::vector<cv::Point2f>& cur,
                                            const Eigen::Matrix3d* R_cur_prev);
  bool epipolarInliers(const std::vector<cv::Point2f>& before, const std::vector<cv::Point2f>& cur,
                       std::vector<unsigned char>& inlier) const;
  void keepTracks(std::vector<cv::Point2f>& before, std::vector<cv::Point2f>& cur,
                  const std::vector<unsigned char>& keep);

  CameraModel cam_;
  FeatureTrackerConfig cfg_;
  GridDetector detector_;
  ImagePyramid prev_;
  std::vector<cv::Point2f> pts_, prevPts_;
  std::vector<std::uint64_t> ids_;
  std::vector<int> lengths_;
  std::vector<float> travel_;
  std::vector<AffinePatch> templates_;  // empty: no template (plain KLT track)
  std::vector<AffineWarp> warps_;
  cv::Mat smooth_;  // the current image smoothed for the templates (buffer kept between frames)
  const unsigned char* smoothOf_ = nullptr;  // pixels smooth_ was made from (prepareTemplates)
  std::uint64_t nextId_ = 0;
};

}  // namespace gvins::vio
