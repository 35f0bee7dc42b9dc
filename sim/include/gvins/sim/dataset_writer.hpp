// The files of a simulated dataset (docs/dataset_format.md): EuRoC/ASL CSV and sensor.yaml
// files that vio's readers (euroc_csv.hpp, sensor_yaml.hpp, euroc_dataset.hpp) read as they
// are, the ECEF ground truth, camera poses, feature tracks and landmarks. Numbers are written
// in the shortest form that reads back to the same double (std::to_chars), so a dataset keeps
// the simulator's values exactly.
#pragma once

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "gvins/sim/feature_simulator.hpp"
#include "gvins/sim/local_frame.hpp"
#include "gvins/sim/trajectory.hpp"
#include "gvins/vio/imu_noise.hpp"
#include "gvins/vio/imu_sample.hpp"
#include "gvins/vio/sensor_yaml.hpp"

namespace gvins::sim {

/// A buffered text file that throws std::runtime_error on any write error.
class TextFile {
 public:
  explicit TextFile(const std::filesystem::path& path);
  ~TextFile();
  TextFile(const TextFile&) = delete;
  TextFile& operator=(const TextFile&) = delete;
  TextFile& operator<<(const std::string& s);
  TextFile& operator<<(const char* s);
  /// Shortest round-trip decimal form of a double.
  TextFile& num(double v);
  TextFile& integer(std::int64_t v);
  TextFile& unsignedInteger(std::uint64_t v);
  /// Fixed-point with the given number of decimals (pixels, ...).
  TextFile& fixed(double v, int decimals);
  TextFile& put(char c);
  void close();

 private:
  void write(const char* p, std::size_t n);
  std::FILE* f_ = nullptr;
  std::filesystem::path path_;
};

/// Shortest round-trip decimal form of a double.
std::string formatDouble(double v);

void writeImuCsv(const std::filesystem::path& path, const std::vector<vio::ImuSample>& samples);
void writeImuSensorYaml(const std::filesystem::path& path, const vio::ImuNoise& noise, double rateHz,
                        const std::string& comment);
void writeCameraSensorYaml(const std::filesystem::path& path, const vio::CameraCalibration& camera, double rateHz,
                           const std::string& comment);
/// cam data.csv: "<stamp>,<stamp>.png" per frame.
void writeCameraCsv(const std::filesystem::path& path, const std::vector<std::int64_t>& stamps);

/// One ground-truth row: the state and the true IMU biases.
struct TruthRow {
  std::int64_t t_ns = 0;
  TrajectoryState state;
  Eigen::Vector3d bg = Eigen::Vector3d::Zero(), ba = Eigen::Vector3d::Zero();
};
/// ASL state_groundtruth_estimate0/data.csv (17 columns) in W.
void writeGroundTruthCsv(const std::filesystem::path& path, const std::vector<TruthRow>& rows);
/// truth/groundtruth_ecef.csv: IMU position, velocity and orientation in ECEF, the antenna
/// position and velocity in ECEF, and geodetic coordinates of the antenna.
void writeEcefTruthCsv(const std::filesystem::path& path, const std::vector<TruthRow>& rows, const LocalFrame& frame,
                       const Eigen::Vector3d& leverArm);
/// truth/camN_poses.csv: T_WC at each image stamp (mid-exposure of the centre row).
void writeCameraPosesCsv(const std::filesystem::path& path, const std::vector<std::int64_t>& stamps,
                         const std::vector<Eigen::Matrix3d>& R_WC, const std::vector<Eigen::Vector3d>& p_WC);

}  // namespace gvins::sim
