// Renders camera images of the textured ground plane (ground_texture.hpp) along a trajectory:
// per-pixel ray casting through a lookup table of undistorted rays (so any vio::CameraModel
// distortion is exact), trilinear texture filtering with a per-pixel footprint, motion blur by
// averaging sub-exposures (as many as the image motion during the exposure needs), optional
// rolling shutter, lens vignetting, a Gaussian optical PSF, per-frame exposure (gain)
// fluctuation, shot and read noise, 8-bit quantisation.
//
// Time convention: a frame stamped t is exposed over [t - exposure/2, t + exposure/2]; with a
// rolling shutter of line time L, row r is exposed around t + (r - (height - 1)/2) L.
// Geometry: pixel centres at integer coordinates (OpenCV), the camera pose is
// T_WC = T_WB(t) T_BS with T_BS the sensor.yaml extrinsics (camera in the body = IMU frame).
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

#include "gvins/sim/ground_texture.hpp"
#include "gvins/sim/trajectory.hpp"
#include "gvins/vio/camera_model.hpp"
#include "gvins/vio/sensor_yaml.hpp"

namespace gvins::sim {

struct ImagingConfig {
  double exposure = 0.003;        ///< s
  double lineTime = 0.0;          ///< s per row (rolling shutter), 0 = global shutter
  bool motionBlur = true;
  int maxBlurSamples = 12;        ///< sub-exposures at most
  double blurStepPx = 0.5;        ///< image motion (px) between consecutive sub-exposures at most
  double opticalBlurSigma = 0.5;  ///< px, Gaussian point spread function (0 = none)
  double vignetting = 0.3;        ///< relative brightness loss (1 - cos^4 theta) weight
  double gainSigma = 0.03;        ///< 1-sigma of the per-frame log gain (auto-exposure jitter)
  double gainCorrelation = 0.9;   ///< AR(1) coefficient of the log gain from frame to frame
  double readNoise = 1.0;         ///< DN, 1-sigma
  double shotNoise = 0.02;        ///< DN: variance = shotNoise * signal
  double sky = 210.0;             ///< gray level of rays that miss the ground (or beyond maxRange)
  double maxRange = 3000.0;       ///< m
  bool noise = true;              ///< false: no gain jitter, no shot/read noise

  void validate() const;  ///< std::invalid_argument for out-of-range values
};

class CameraRenderer {
 public:
  /// Precomputes the ray table of the camera (about 20 bytes per pixel).
  CameraRenderer(const vio::CameraCalibration& camera, const ImagingConfig& imaging, const GroundTexture& texture);

  /// The image stamped at flight time t. `gain` multiplies the exposure (1 = nominal), noise is
  /// drawn from `noiseSeed`. Returns CV_8UC1 of the calibrated size.
  cv::Mat render(const Trajectory& trajectory, double t, double gain, std::uint64_t noiseSeed) const;
  /// Noise-free, blur-free, vignetting-free radiance (CV_32FC1, gray levels) from a fixed pose.
  cv::Mat renderRadiance(const Eigen::Matrix3d& R_WC, const Eigen::Vector3d& p_WC) const;

  /// Number of sub-exposures render() uses at time t.
  int blurSamples(const Trajectory& trajectory, double t) const;
  /// Camera pose at a trajectory state.
  void cameraPose(const TrajectoryState& s, Eigen::Matrix3d& R_WC, Eigen::Vector3d& p_WC) const;

  /// Use the AVX2 kernel of the per-pixel loop where the CPU has it (default). Off: the scalar
  /// loop only. The pixels are the same bit for bit either way (tests/sim/test_dataset.cpp).
  void setVectorized(bool on) { vectorized_ = on; }

  const vio::CameraModel& model() const { return model_; }
  const vio::CameraCalibration& calibration() const { return calib_; }

 private:
  struct RowPose {
    Eigen::Matrix3d R;
    Eigen::Vector3d p;
  };
  void accumulate(const std::vector<RowPose>& rows, float weight, float* out) const;
  vio::CameraCalibration calib_;
  vio::CameraModel model_;
  ImagingConfig img_;
  const GroundTexture& tex_;
  int w_ = 0, h_ = 0;
  std::vector<float> rayX_, rayY_;    // undistorted normalised coordinates per pixel
  std::vector<float> rayNorm_;        // |(x, y, 1)|
  std::vector<float> pixelAngle_;     // sqrt(solid angle) of the pixel, rad
  std::vector<float> vignette_;       // brightness factor
  Eigen::Matrix3d R_BC_;
  Eigen::Vector3d p_BC_;
  bool vectorized_ = true;
};

/// Per-frame gains exp(x_k) with x an AR(1) process of stationary 1-sigma gainSigma.
std::vector<double> exposureGains(std::size_t frames, const ImagingConfig& imaging, std::uint64_t seed);

}  // namespace gvins::sim
