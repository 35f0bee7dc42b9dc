// A gvins-sim scenario: where and when, the motion, the IMU, the cameras (rendered images or
// feature tracks), the scene, the GNSS antenna lever arm and the GNSS simulation (the `gnss:`
// section, parsed by parseGnssSimConfig). One YAML file describes one scenario; every key is
// optional on top of defaultScenario() and unknown keys are errors. The format is documented in
// docs/dataset_format.md ("Scenario files") and config/*.yaml are examples.
//
// Every malformed scenario throws gvins::ParseError naming the file, the line and the key
// (e.g. "trajectory.speed_mps").
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "gvins/sim/camera_renderer.hpp"
#include "gvins/sim/feature_simulator.hpp"
#include "gvins/sim/flight_pattern.hpp"
#include "gvins/sim/gnss_sim_config.hpp"
#include "gvins/sim/ground_texture.hpp"
#include "gvins/sim/imu_simulator.hpp"
#include "gvins/sim/local_frame.hpp"
#include "gvins/sim/recorded_trajectory.hpp"
#include "gvins/sim/track_trajectory.hpp"
#include "gvins/sim/urban_structure.hpp"
#include "gvins/vio/sensor_yaml.hpp"

namespace gvins::sim {

/// Flight: simulated motion; Recorded: EuRoC-style ground truth + real IMU; Track: a GNSS
/// reference track + real IMU (track_trajectory.hpp), with the real rover GNSS files.
enum class TrajectoryKind { Flight, Recorded, Track };
enum class CameraOutput { Images, Features };

struct Scenario {
  std::string name = "default";
  std::string description;
  std::string file;          ///< where it was read from ("" for built-in)
  std::string text;          ///< the YAML text it was read from ("" for built-in)
  std::uint64_t seed = 1;    ///< default seed (gvins-sim --seed overrides)
  LocalFrame frame;          ///< origin = ground at the take-off point, start of the flight

  TrajectoryKind trajectory = TrajectoryKind::Flight;
  FlightSpec flight;
  RecordedTrajectoryConfig recorded;
  TrackTrajectoryConfig track;

  ImuSimConfig imu;
  double cameraRate = 20.0;  ///< Hz
  /// Camera-IMU time offset t_d, s (`cameras.time_offset_s`): an image taken at IMU time t is
  /// stamped t − t_d, so that t_imu = t_cam + t_d (Kalibr's timeshift_cam_imu convention).
  double cameraTimeOffset = 0.0;
  CameraOutput output = CameraOutput::Images;
  int pngCompression = 1;    ///< 0-9 (zlib level)
  std::vector<vio::CameraCalibration> cameras;
  ImagingConfig imaging;
  FeatureSimConfig features;
  GroundTextureConfig texture;  ///< texture.seed is replaced by one derived from the run's seed
  /// 3-D structure along the route (`scene.structure`): the feature tracks come from its
  /// facades, poles and ground instead of the ground plane, and it blocks and reflects the
  /// rover's GNSS signals. Feature output only (not rendered).
  std::optional<UrbanConfig> structure;

  Eigen::Vector3d leverArm = Eigen::Vector3d(0.08, 0.0, 0.18);  ///< GNSS antenna in the IMU frame, m
  std::optional<GnssSimConfig> gnss;  ///< no GNSS when absent
};

/// The built-in default: a two-minute stereo UAV survey (lawnmower, 40 m, 8 m/s) near the
/// Nagoya GNSS data of 2024-06-24 08:20 GPST, with a base station 3 km away and the bundled
/// navigation file (config/default.yaml is the same scenario as a file).
Scenario defaultScenario();

/// Reads a scenario file / text on top of defaultScenario(). Relative paths are relative to the
/// file's folder.
Scenario loadScenario(const std::string& path);
Scenario parseScenario(const std::string& text, const std::string& file);

/// The EuRoC MAV cam0/cam1 intrinsics and radial-tangential distortion (V1_01 sensor.yaml),
/// mounted looking down (image up = body forward) at `position_m` in the body frame.
vio::CameraCalibration downwardCamera(const std::string& name, const Eigen::Vector3d& position,
                                      const Eigen::Vector3d& mountRpyDeg = Eigen::Vector3d::Zero(),
                                      bool cam1Intrinsics = false);
/// Rotation R_BC of a camera looking down (image up = body x) or forward (image right = -body y),
/// followed by small mount angles (deg): R_look Rz(yaw) Ry(pitch) Rx(roll).
Eigen::Matrix3d cameraMountRotation(bool lookDown, const Eigen::Vector3d& mountRpyDeg);

/// Folder of the data installed with the library (the navigation file of the default scenario):
/// $GVINS_DATA_DIR when that environment variable is set (a source tree's tests/data will do),
/// else <folder of the running executable>/../share/sri_gvins/data, which is where an installed
/// tool (<prefix>/bin) and the build tree's tools and tests find it. Programs elsewhere set
/// GVINS_DATA_DIR or name the file (scenario `gnss.navigation`).
std::string bundledDataDirectory();
/// Path of the bundled navigation file (gnss/nagoya_static_2024/base.nav.gz of
/// bundledDataDirectory(); a copy of tests/data/gnss/nagoya_static_2024/base.nav.gz).
std::string bundledNavigationFile();

}  // namespace gvins::sim
