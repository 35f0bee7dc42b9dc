// Readers of the EuRoC/ASL CSV files (Burri et al., IJRR 2016, dataset format description):
//   imu0/data.csv:                        t[ns], w_x, w_y, w_z [rad/s], a_x, a_y, a_z [m/s^2]
//   cam*/data.csv:                        t[ns], filename
//   state_groundtruth_estimate0/data.csv: t[ns], p_x, p_y, p_z [m], q_w, q_x, q_y, q_z,
//                                         v_x, v_y, v_z [m/s], bg_x.. [rad/s], ba_x.. [m/s^2]
//                                         (the 8-column pose-only form is accepted too)
// Plain or gzip-compressed files (detected from the content). Lines starting with '#' and blank
// lines are skipped. Time stamps are integer nanoseconds (a fractional part such as
// "1403715274312143104.0000" is rounded) and must increase strictly: a repeated or decreasing
// stamp is a gvins::ParseError naming file, line and field, as is any malformed field.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "gvins/base/line_reader.hpp"
#include "gvins/vio/imu_sample.hpp"
#include "gvins/vio/imu_state.hpp"

namespace gvins::vio {

/// Gaps in an IMU log: intervals longer than 1.5 nominal periods.
struct ImuGapReport {
  std::int64_t nominalPeriod_ns = 0;  ///< 0: gap detection off
  std::size_t samples = 0;
  std::size_t gaps = 0;
  std::size_t missingSamples = 0;      ///< estimated samples lost in the gaps
  std::int64_t largestGap_ns = 0;
  std::int64_t largestGapStart_ns = 0;  ///< stamp of the sample before the largest gap
};

/// Streaming reader of an ASL IMU CSV file.
class ImuCsvReader {
 public:
  /// `nominalRateHz` (e.g. sensor.yaml rate_hz) enables gap counting; 0 disables it.
  explicit ImuCsvReader(const std::string& path, double nominalRateHz = 0.0);
  ImuCsvReader(std::string_view text, std::string name, double nominalRateHz = 0.0);

  /// Next sample; false at end of file. Throws ParseError.
  bool next(ImuSample& sample);
  const ImuGapReport& gaps() const { return gaps_; }
  const std::string& name() const { return reader_.name(); }

 private:
  LineReader reader_;
  ImuGapReport gaps_;
  std::int64_t last_ = -1;
  std::string line_;
  std::vector<std::string_view> fields_;
};

/// Reads a whole IMU file (with gap statistics).
std::vector<ImuSample> readImuCsv(const std::string& path, double nominalRateHz = 0.0,
                                  ImuGapReport* gaps = nullptr);

struct CameraCsvEntry {
  std::int64_t t_ns = 0;
  std::string filename;  ///< relative to the camera's data/ folder; no path separators
  std::int64_t line = 0;  ///< line in data.csv, for error messages about the image
};

/// Reads a camera data.csv (small: one line per image).
std::vector<CameraCsvEntry> readCameraCsv(const std::string& path);
std::vector<CameraCsvEntry> parseCameraCsv(std::string_view text, const std::string& name);

/// Ground truth row: pose always, velocity and biases when the file has 17 columns.
struct GroundTruthSample {
  ImuState state;  ///< body frame of the ground truth (EuRoC: the IMU frame)
  bool hasVelocityAndBiases = false;
};

/// Streaming reader of state_groundtruth_estimate0/data.csv. Quaternions must be unit to 1e-3
/// (they are renormalised).
class GroundTruthCsvReader {
 public:
  explicit GroundTruthCsvReader(const std::string& path);
  GroundTruthCsvReader(std::string_view text, std::string name);
  bool next(GroundTruthSample& sample);

 private:
  LineReader reader_;
  std::int64_t last_ = -1;
  std::size_t columns_ = 0;
  std::string line_;
  std::vector<std::string_view> fields_;
};

std::vector<GroundTruthSample> readGroundTruthCsv(const std::string& path);

}  // namespace gvins::vio
