// Simulated stereo feature-track datasets for the replay tests (gvins-sim's generator, no GNSS):
// the paper-like downward stereo rig at the Nagoya origin, a flight given as the scenario's
// trajectory line, and the estimator configuration a replay of it uses (gravity, IMU noise and
// cameras from the dataset, as gvins-replay takes them without --config).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

#include "gvins/fusion/sim_dataset_info.hpp"
#include "gvins/sim/dataset_generator.hpp"
#include "gvins/sim/scenario.hpp"
#include "gvins/vio/sensor_yaml.hpp"
#include "gvins/vio/sri_swf_estimator.hpp"
#include "generate_scenario.hpp"

namespace gvins::fusion::test {

/// Writes the dataset into `dir`. `trajectory` is the scenario's `trajectory: {...}` line(s),
/// `cameraExtra` more lines of the `cameras:` section (e.g. "  time_offset_s: 0.015\n").
inline void simulateStereoFeatureDataset(const std::filesystem::path& dir, const std::string& name,
                                         const std::string& trajectory, const std::string& cameraExtra,
                                         std::uint64_t seed) {
  const std::string y =
      "name: " + name + "\n"
      "origin: {latitude_deg: 35.134707705, longitude_deg: 136.977577939, height_m: 104.853}\n"
      "start_gpst: \"2024-06-24 08:20:00\"\n" + trajectory +
      "imu: {rate_hz: 250}\n"
      "cameras:\n"
      "  rate_hz: 20\n" + cameraExtra +
      "  output: features\n"
      "  list:\n"
      "    - {name: cam0, look: down, position_m: [0.06, 0.06, -0.04], mount_rpy_deg: [0.4, -0.3, 0.2]}\n"
      "    - {name: cam1, look: down, position_m: [0.06, -0.06, -0.04], mount_rpy_deg: [-0.2, 0.3, -0.4]}\n"
      "gnss: none\n";
  generateScenario(dir, y, name, seed);
}

/// Camera `k`'s calibration as the dataset states it (the simulation's truth).
inline vio::CameraCalibration datasetCamera(const std::filesystem::path& dir, int k) {
  return vio::readCameraSensorYaml((dir / "mav0" / ("cam" + std::to_string(k)) / "sensor.yaml").string());
}

/// Estimator configuration from the dataset: gravity, IMU noise, both cameras; defaults otherwise.
inline vio::SriSwfConfig datasetEstimatorConfig(const std::filesystem::path& dir) {
  vio::SriSwfConfig ec;
  ec.gravity = *readSimDatasetInfo(dir.string())->gravity;
  ec.imu = vio::readImuSensorYaml((dir / "mav0" / "imu0" / "sensor.yaml").string()).noise;
  ec.cameras = {datasetCamera(dir, 0), datasetCamera(dir, 1)};
  return ec;
}

}  // namespace gvins::fusion::test
