// Feature-only camera simulation: 3-D landmarks scattered over the ground (deterministic from
// the seed and their position, so any region can be queried in any order) and, per image, the
// noisy pixel observations of those the camera sees: what a feature tracker hands a filter,
// without rendering. Observations keep the landmark id across images (tracks), are limited to
// the `maxPerImage` landmarks of highest fixed random priority (stable tracks, like a tracker
// that keeps its features), carry white pixel noise and optional outliers (wrong matches).
// Projection uses vio::CameraModel with the camera's distortion, the pose T_WC = T_WB T_BS at
// the image stamp (rolling shutter: at the row's time, solved by fixed-point iteration).
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "gvins/sim/trajectory.hpp"
#include "gvins/vio/camera_model.hpp"
#include "gvins/vio/sensor_yaml.hpp"

namespace gvins::sim {

class UrbanStructure;

struct Landmark {
  std::uint64_t id = 0;
  Eigen::Vector3d p_W = Eigen::Vector3d::Zero();
  double priority = 0.0;  ///< uniform in [0, 1), fixed per landmark
};

/// Landmarks on the ground plane z = 0 (optionally raised by |N(0, heightSigma)|, e.g. clutter
/// and vegetation) with a uniform density. Each square cell of side `cell` holds
/// floor(density cell^2 + u) landmarks (u uniform from the cell's hash).
class LandmarkField {
 public:
  /// Throws std::invalid_argument for density outside (0, 1000] per m^2 or a negative sigma.
  LandmarkField(double densityPerM2, double heightSigma, std::uint64_t seed);
  /// Appends the landmarks inside [x0, x1] x [y0, y1] (at most ~1e7; larger regions throw).
  void query(double x0, double y0, double x1, double y1, std::vector<Landmark>& out) const;
  double cellSize() const { return cell_; }
  double density() const { return density_; }

 private:
  double density_, heightSigma_, cell_;
  std::uint64_t seed_;
};

struct FeatureSimConfig {
  int maxPerImage = 150;           ///< observations per image at most
  double landmarksPerImage = 400;  ///< density target: landmarks in the view at the typical height
  double densityPerM2 = 0.0;       ///< > 0 overrides landmarksPerImage
  double heightSigma = 0.0;        ///< m
  double pixelNoise = 0.5;         ///< px, 1-sigma per axis
  double outlierRate = 0.0;        ///< fraction of observations displaced by a wrong match
  double outlierOffset = 20.0;     ///< px, maximum displacement of an outlier
  double border = 2.0;             ///< px kept free at the image edges
  double maxRange = 300.0;         ///< m, landmarks farther than this are not observed

  void validate() const;  ///< std::invalid_argument for out-of-range values
};

struct FeatureObservation {
  std::uint64_t landmark = 0;
  Eigen::Vector3d p_W = Eigen::Vector3d::Zero();         ///< the landmark
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();      ///< observed (noisy) distorted pixel
  Eigen::Vector2d truePixel = Eigen::Vector2d::Zero();  ///< noise-free projection
  bool outlier = false;
};

class FeatureSimulator {
 public:
  FeatureSimulator(const vio::CameraCalibration& camera, const FeatureSimConfig& config, const LandmarkField& field,
                   double lineTime = 0.0);
  /// Landmarks of a 3-D structure (must outlive the simulator) instead of the ground plane.
  FeatureSimulator(const vio::CameraCalibration& camera, const FeatureSimConfig& config, const UrbanStructure& world,
                   double lineTime = 0.0);

  /// Observations in the image stamped at flight time t; noise from `noiseSeed`.
  std::vector<FeatureObservation> observe(const Trajectory& trajectory, double t, std::uint64_t noiseSeed) const;
  /// Noise-free projection of a world point at the image stamped t (rolling shutter handled);
  /// false if behind the camera.
  bool project(const Trajectory& trajectory, double t, const Eigen::Vector3d& p_W, Eigen::Vector2d& pixel) const;

  const vio::CameraModel& model() const { return model_; }

 private:
  /// Landmarks of the structure in the frustum's horizontal footprint, and the buildings there.
  void structureCandidates(const Eigen::Matrix3d& R_WC, const Eigen::Vector3d& p_WC, std::vector<Landmark>& lms,
                           std::vector<int>& buildings) const;

  vio::CameraCalibration calib_;
  vio::CameraModel model_;
  FeatureSimConfig cfg_;
  const LandmarkField* field_ = nullptr;
  const UrbanStructure* world_ = nullptr;
  double lineTime_;
  Eigen::Matrix3d R_BC_;
  Eigen::Vector3d p_BC_;
};

/// Landmark density giving `landmarksPerImage` in the view of a camera looking straight down
/// from `height` metres: n / (w h height^2 / (fx fy)).
double autoLandmarkDensity(const vio::CameraIntrinsics& k, double height, double landmarksPerImage);

}  // namespace gvins::sim
