// IMU logs in other layouts than EuRoC's imu0/data.csv: delimited text with one sample per line,
// any column order, units of g or m/s² and deg/s or rad/s, a mounting rotation, and one of
// several time columns (GPST seconds or nanoseconds, or a device counter placed on GPST with an
// RTKLIB time-tag file). The result is the project's ImuSample stream (GPST ns, rad/s, m/s² in
// the output frame), e.g. to write a dataset's imu0/data.csv (gvins-imu).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "gvins/vio/imu_sample.hpp"
#include "gvins/vio/rtklib_time_tag.hpp"

namespace gvins::vio {

enum class ImuColumn { Time, Ax, Ay, Az, Gx, Gy, Gz, Ignore };

enum class ImuTimeKind {
  GpstNanoseconds,  ///< integer ns since 1980-01-06 GPST (the project's convention)
  GpstSeconds,      ///< seconds since 1980-01-06 GPST
  GpstUnixSeconds,  ///< seconds since 1970-01-01 counted on the GPST scale (no leap seconds)
  CounterMs,        ///< device counter in ms (e.g. since power-up): needs a time-tag file
};

struct ImuTableFormat {
  /// One entry per field of a line; fields past the list are ignored. Must name each of Time,
  /// Ax..Gz exactly once.
  std::vector<ImuColumn> columns{ImuColumn::Time, ImuColumn::Gx, ImuColumn::Gy, ImuColumn::Gz,
                                 ImuColumn::Ax,   ImuColumn::Ay, ImuColumn::Az};
  ImuTimeKind time = ImuTimeKind::GpstNanoseconds;
  double accelScale = 1.0;  ///< to m/s² (g: 9.80665, the standard gravity of the unit "g")
  double gyroScale = 1.0;   ///< to rad/s (deg/s: π/180)
  /// Rotation from the log's sensor axes to the output frame: v_out = R v_in.
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
};

/// "t,ax,ay,az,gx,gy,gz,-": names t (time), ax ay az, gx gy gz, and - (ignored). Throws
/// std::invalid_argument naming the bad entry.
std::vector<ImuColumn> parseImuColumns(std::string_view spec);
/// "gpst-ns", "gpst-s", "gpst-unix-s", "counter-ms"; throws std::invalid_argument.
ImuTimeKind parseImuTimeKind(std::string_view name);
/// Rotation from roll, pitch, yaw (deg) of the sensor axes in the output frame:
/// R = Rz(yaw) Ry(pitch) Rx(roll).
Eigen::Matrix3d rotationFromRollPitchYaw(double rollDeg, double pitchDeg, double yawDeg);

/// What reading an IMU table found.
struct ImuTableReport {
  std::size_t lines = 0;               ///< data lines (not blank, not '#')
  std::size_t samples = 0;
  std::size_t truncatedSkipped = 0;    ///< a cut-off first or last line (logs started or ended mid-line)
  std::size_t untaggedSkipped = 0;     ///< counter lines after the last time tag
  double medianPeriod_s = 0.0;         ///< median interval between samples
  // Counter logs: GPST = a + (1 + drift) · counter, the drift fitted to the tags and a the
  // earliest the logger saw each sample (the tags only lag the sensor).
  bool counterFit = false;
  double counterDrift_ppm = 0.0;
  double tagLatencyMedian_ms = 0.0;    ///< tag time minus the fitted time, median
  double tagLatencyMax_ms = 0.0;
  bool tagOffsetsCountCrLf = false;    ///< the tags count two-byte line ends the file no longer has
};

/// Reads a whole IMU table (plain text; '#' lines and blank lines skipped). `tag` is required
/// for ImuTimeKind::CounterMs and ignored otherwise. Throws gvins::ParseError naming file, line
/// and field for a malformed line (other than a cut-off first/last one), a non-increasing time,
/// or a value beyond physical limits.
std::vector<ImuSample> readImuTable(const std::string& path, const ImuTableFormat& format,
                                    const RtklibTimeTag* tag = nullptr, ImuTableReport* report = nullptr);
std::vector<ImuSample> parseImuTable(std::string_view text, const std::string& name, const ImuTableFormat& format,
                                     const RtklibTimeTag* tag = nullptr, ImuTableReport* report = nullptr);

}  // namespace gvins::vio
