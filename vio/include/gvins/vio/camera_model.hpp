// Camera intrinsics and lens distortion: pinhole with radial-tangential (plumb-bob, 4
// coefficients k1 k2 p1 p2) or equidistant fisheye (k1..k4) distortion, as in the EuRoC/Kalibr
// `sensor.yaml` conventions.
#pragma once

#include <array>
#include <optional>
#include <string>

#include <Eigen/Core>

namespace gvins::vio {

enum class DistortionModel { None, RadialTangential, Equidistant };

struct CameraIntrinsics {
  int width = 0;
  int height = 0;
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;
  DistortionModel model = DistortionModel::None;
  std::array<double, 4> distortion{};  ///< radtan: k1 k2 p1 p2; equidistant: k1 k2 k3 k4
};

class CameraModel {
 public:
  CameraModel() = default;
  /// Throws std::invalid_argument for non-positive or non-finite focal lengths, non-finite
  /// centre or distortion coefficients, or a negative image size.
  explicit CameraModel(const CameraIntrinsics& intrinsics);

  const CameraIntrinsics& intrinsics() const { return k_; }

  /// Normalised image coordinates (x/z, y/z) -> distorted pixel. Optional 2x2 Jacobian
  /// d pixel / d normalised.
  Eigen::Vector2d distortAndProject(const Eigen::Vector2d& normalized,
                                    Eigen::Matrix2d* jacobian = nullptr) const;
  /// Distorted pixel -> undistorted normalised coordinates (iterative inverse, accurate to
  /// < 1e-9 in normalised units inside the image).
  Eigen::Vector2d undistort(const Eigen::Vector2d& pixel) const;

  /// 3-D point in the camera frame -> pixel; std::nullopt behind the camera (z <= 1e-6).
  /// Optional 2x3 Jacobian d pixel / d point.
  std::optional<Eigen::Vector2d> project(const Eigen::Vector3d& pointCamera,
                                         Eigen::Matrix<double, 2, 3>* jacobian = nullptr) const;

  /// True if the pixel lies in [border, width-1-border] x [border, height-1-border]
  /// (pixel centres at integer coordinates, OpenCV convention).
  bool inImage(const Eigen::Vector2d& pixel, double border = 0.0) const;

  // Additions beyond the shared declaration (used by the front end and the filter).

  /// Undistorted normalised -> distorted normalised coordinates (no focal length / centre).
  /// Optional 2x2 Jacobian d distorted / d undistorted.
  Eigen::Vector2d distort(const Eigen::Vector2d& normalized, Eigen::Matrix2d* jacobian = nullptr) const;
  /// Distorted normalised -> undistorted normalised coordinates (inverse of distort()).
  Eigen::Vector2d undistortNormalized(const Eigen::Vector2d& distorted) const;
  /// As undistort(pixel), with the 2x2 Jacobian d normalised / d pixel (inverse of the
  /// distortAndProject() Jacobian at the solution); used to map pixel noise to normalised noise.
  Eigen::Vector2d undistort(const Eigen::Vector2d& pixel, Eigen::Matrix2d* jacobian) const;
  /// Unit bearing vector in the camera frame of a distorted pixel.
  Eigen::Vector3d bearing(const Eigen::Vector2d& pixel) const;

 private:
  CameraIntrinsics k_;
};

}  // namespace gvins::vio
