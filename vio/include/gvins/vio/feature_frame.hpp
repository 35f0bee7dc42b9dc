// Output of the visual front end for one camera time step: for every tracked feature its id,
// track length, cam0 pixel and undistorted normalised coordinates, and the cam1 ones when the
// stereo match succeeded.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace gvins::vio {

struct FeatureObservation {
  std::uint64_t id = 0;
  /// Number of frames the feature has been observed in cam0, this one included (1 = new).
  int trackLength = 1;
  Eigen::Vector2d pixel0 = Eigen::Vector2d::Zero();       ///< distorted cam0 pixel
  Eigen::Vector2d normalized0 = Eigen::Vector2d::Zero();  ///< undistorted (x/z, y/z) in cam0
  bool stereo = false;                                    ///< cam1 fields valid
  Eigen::Vector2d pixel1 = Eigen::Vector2d::Zero();
  Eigen::Vector2d normalized1 = Eigen::Vector2d::Zero();
};

/// Wall-clock milliseconds spent in each stage for this frame, and the CPU time of the whole
/// frame (on a shared machine the wall times include waiting for a core).
struct FrontendTiming {
  double pyramid = 0.0;    ///< image pyramids (both cameras)
  double tracking = 0.0;   ///< temporal KLT with forward-backward check
  double ransac = 0.0;     ///< fundamental-matrix RANSAC on undistorted points
  double detection = 0.0;  ///< new corners in empty grid cells
  double stereo = 0.0;     ///< left-right KLT and epipolar check
  double total = 0.0;
  double cpu = 0.0;        ///< CPU time of the processing thread for the whole frame, ms
};

struct FeatureFrame {
  std::int64_t t_ns = 0;
  std::uint64_t index = 0;  ///< 0, 1, 2, ... in processing order
  std::vector<FeatureObservation> features;
  FrontendTiming timing;
};

}  // namespace gvins::vio
