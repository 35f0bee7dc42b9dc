// Pose covariance files that accompany a TUM trajectory (our extension; gvins-replay writes
// <trajectory>.cov.csv next to trajectory.tum and gvins-eval reads it for NEES):
//
//   # t [s], then the 36 entries of the 6x6 covariance, row-major
//   1403715274.312143104,c00,c01,...,c05,c10,...,c55
//
// The covariance is that of the pose error [δθ; δp] (rad, m) with R_WB = R̂_WB·Exp(δθ) (δθ in
// the body frame) and p_WB = p̂_WB + δp (δp in the trajectory's world frame) — the convention of
// the estimator's pose blocks (estimator_backend.hpp). Separators: commas or blanks. Lines
// starting with '#' are comments. Rows must have strictly increasing times; each matrix must be
// finite and symmetric (|c_ij − c_ji| ≤ 1e-6·max|c| + 1e-12) with non-negative diagonal.
// Everything else is a gvins::ParseError naming file, line and field ("c23", ...).
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

namespace gvins::vio {

using Matrix6d = Eigen::Matrix<double, 6, 6>;

struct PoseCovariance {
  std::int64_t t_ns = 0;
  Matrix6d P = Matrix6d::Zero();  ///< [δθ (body); δp (world)]
};

std::vector<PoseCovariance> readPoseCovarianceCsv(const std::string& path);
std::vector<PoseCovariance> parsePoseCovarianceCsv(std::string_view text, const std::string& name);

/// Streaming writer (same number format as TumTrajectoryWriter for the time).
class PoseCovarianceWriter {
 public:
  /// Throws std::runtime_error if the file cannot be created.
  explicit PoseCovarianceWriter(const std::string& path);
  ~PoseCovarianceWriter();
  PoseCovarianceWriter(const PoseCovarianceWriter&) = delete;
  PoseCovarianceWriter& operator=(const PoseCovarianceWriter&) = delete;
  /// Writes the symmetrised matrix; negative times are std::invalid_argument.
  void write(std::int64_t t_ns, const Matrix6d& P);
  /// Flushes and closes; throws std::runtime_error on a write error.
  void close();

 private:
  std::FILE* f_ = nullptr;
  std::string path_;
};

}  // namespace gvins::vio
