// TUM RGB-D benchmark trajectory files (Sturm et al., IROS 2012, "File formats"): one pose per
// line, "t x y z qx qy qz qw", t in seconds, p the position of the body in the world frame, q the
// Hamilton unit quaternion of the body-to-world rotation (note the scalar LAST, unlike EuRoC).
// Lines starting with '#' are comments. The reader also accepts comma separators.
#pragma once

#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

namespace gvins::vio {

struct TumPose {
  std::int64_t t_ns = 0;
  Eigen::Vector3d p = Eigen::Vector3d::Zero();       ///< position in the world frame
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();   ///< body-to-world rotation
};

enum class TumTimeUnit { Seconds, Nanoseconds };

/// gvins-replay's reset mark: a comment line "# VIO reset ..." (TumTrajectoryWriter::markReset)
/// before pose i means that the poses from i on are in a new VIO world frame (the estimator
/// started again after a visual lock-out).
inline constexpr std::string_view kTumResetMark = "VIO reset";

/// Reads a trajectory; throws gvins::ParseError (file, line, field) for malformed lines,
/// non-unit quaternions (|q| off by more than 1e-3; otherwise renormalised) and time stamps that
/// do not increase strictly. `resetMarks` (if given) receives the indices of the poses that
/// follow reset marks (several marks before the same pose count once).
std::vector<TumPose> readTumTrajectory(const std::string& path, TumTimeUnit unit = TumTimeUnit::Seconds,
                                       std::vector<std::size_t>* resetMarks = nullptr);
std::vector<TumPose> parseTumTrajectory(std::string_view text, const std::string& name,
                                        TumTimeUnit unit = TumTimeUnit::Seconds,
                                        std::vector<std::size_t>* resetMarks = nullptr);

/// Writes poses as they come (streaming); times with nanosecond resolution ("%d.%09d"),
/// positions to 1e-9 m, quaternions with qw >= 0. Negative times are std::invalid_argument.
class TumTrajectoryWriter {
 public:
  /// Throws std::runtime_error if the file cannot be created. `header` (if not empty) is written
  /// as a comment line.
  explicit TumTrajectoryWriter(const std::string& path, const std::string& header = "t x y z qx qy qz qw");
  ~TumTrajectoryWriter();
  TumTrajectoryWriter(const TumTrajectoryWriter&) = delete;
  TumTrajectoryWriter& operator=(const TumTrajectoryWriter&) = delete;

  void write(const TumPose& pose);
  void write(std::int64_t t_ns, const Eigen::Matrix3d& R, const Eigen::Vector3d& p) { write(TumPose{t_ns, p, R}); }
  /// A comment line "# text" between poses (readers skip it); `text` must be one line.
  void comment(const std::string& text);
  /// The reset mark (kTumResetMark) before the poses of a new VIO world frame, followed by `detail`.
  void markReset(const std::string& detail) { comment(std::string(kTumResetMark) + " " + detail); }
  /// Flushes and closes; throws std::runtime_error on a write error (disk full, ...).
  void close();

 private:
  std::FILE* f_ = nullptr;
  std::string path_;
};

void writeTumTrajectory(const std::string& path, const std::vector<TumPose>& poses);

}  // namespace gvins::vio
