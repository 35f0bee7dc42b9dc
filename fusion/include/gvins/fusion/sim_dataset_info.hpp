// What gvins-replay takes from a gvins-sim dataset.yaml (docs/dataset_format.md): the GNSS lever
// arm (`lever_arm_m`, the truth for the lever-arm error and the default initial value) and the
// gravity model the IMU was simulated with (`gravity.model`, `gravity.magnitude_mps2`), which the
// estimator should use instead of a nominal 9.81 m/s², and the camera-IMU time offset
// (`cameras.time_offset_s`, the truth for the time-offset error). Other keys of the file are not read here.
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include <Eigen/Core>

namespace gvins::fusion {

struct SimDatasetInfo {
  std::optional<Eigen::Vector3d> leverArm;  ///< ^I p_r, m
  std::optional<double> gravity;            ///< m/s²
  std::string gravityModel;                 ///< "flat" or "rotating" (empty if absent)
  std::optional<double> cameraTimeOffset;   ///< cameras.time_offset_s: t_imu = t_cam + t_d, s
};

/// Parses the text of a dataset.yaml. Throws gvins::ParseError (file, line, dotted key) on YAML
/// errors and on malformed values of the keys above.
SimDatasetInfo parseSimDatasetInfo(std::string_view yaml, const std::string& file);
/// Reads DATASET/dataset.yaml; nullopt if the dataset has none (e.g. a EuRoC recording).
std::optional<SimDatasetInfo> readSimDatasetInfo(const std::string& datasetFolder);

}  // namespace gvins::fusion
