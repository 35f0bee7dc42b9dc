// Sensor calibration files: EuRoC/ASL `sensor.yaml` (camera and IMU) and Kalibr `camchain.yaml`
// / `imu.yaml` (Kalibr wiki, "Yaml formats"). All malformed input is a gvins::ParseError naming
// the file, the line and the key.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "gvins/vio/camera_model.hpp"
#include "gvins/vio/imu_noise.hpp"

namespace gvins::vio {

struct CameraCalibration {
  std::string name;  ///< "cam0", ...
  CameraIntrinsics intrinsics;
  /// Pose of the camera in the body frame (EuRoC T_BS: p_B = T_BS p_S). For EuRoC the body
  /// frame is the IMU frame.
  Eigen::Matrix4d T_BS = Eigen::Matrix4d::Identity();
  double rate_hz = 0.0;  ///< 0 if not given
  /// Camera-IMU time offset, s: t_imu = t_cam + time_offset (Kalibr camchain timeshift_cam_imu;
  /// 0 if not given).
  double time_offset = 0.0;
};

struct ImuCalibration {
  ImuNoise noise;
  Eigen::Matrix4d T_BS = Eigen::Matrix4d::Identity();  ///< IMU in the body frame
};

/// EuRoC camera sensor.yaml: camera_model (pinhole), intrinsics [fu fv cu cv], resolution
/// [w h], distortion_model (radial-tangential | radtan | plumb_bob | equidistant | fisheye),
/// distortion_coefficients (4 numbers; a 5th k3 must be 0), T_BS {rows: 4, cols: 4, data: 16},
/// rate_hz (optional).
CameraCalibration readCameraSensorYaml(const std::string& path);
CameraCalibration parseCameraSensorYaml(std::string_view text, const std::string& name);

/// EuRoC IMU sensor.yaml: gyroscope_noise_density, gyroscope_random_walk,
/// accelerometer_noise_density, accelerometer_random_walk, rate_hz, T_BS (optional, identity).
/// Also reads Kalibr's imu.yaml (same noise keys, `update_rate` instead of rate_hz).
ImuCalibration readImuSensorYaml(const std::string& path);
ImuCalibration parseImuSensorYaml(std::string_view text, const std::string& name);

/// Kalibr camchain.yaml: cam0, cam1, ... each with camera_model, intrinsics, distortion_model,
/// distortion_coeffs, resolution and T_cam_imu (4x4 nested list); T_BS = T_cam_imu^-1 with the
/// body frame = IMU frame.
std::vector<CameraCalibration> readKalibrCamchain(const std::string& path);
std::vector<CameraCalibration> parseKalibrCamchain(std::string_view text, const std::string& name);

}  // namespace gvins::vio
