// A position (and optional velocity) solution of one epoch as written to RTKLIB-style .pos files
// by SPP, RTK and the fused replay.
#pragma once

#include <optional>

#include <Eigen/Core>

#include "gvins/base/gnss_time.hpp"

namespace gvins {

/// Solution quality flags with RTKLIB's "Q" numbering.
enum class SolutionQuality : int { None = 0, Fix = 1, Float = 2, Sbas = 3, Dgps = 4, Single = 5, Ppp = 6 };

/// Outcome of the epoch's residual (RAIM) test, the value of the .pos "test" column
/// (docs/pos_format.md): 0 passed, 1 failed after fault exclusion (the solution is kept, not
/// trustworthy), 2 not testable (no redundancy: as many measurements as unknowns).
enum class ResidualTest : int { Passed = 0, Failed = 1, Untestable = 2 };

struct PositionSolution {
  GpsTime time;  ///< GPST of the solution
  SolutionQuality quality = SolutionQuality::None;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< ECEF, m
  Eigen::Matrix3d positionCovariance = Eigen::Matrix3d::Zero();  ///< ECEF, m^2
  int numSatellites = 0;
  double age = 0.0;    ///< differential age, s
  double ratio = 0.0;  ///< ambiguity ratio test value
  /// Residual test of the epoch, when the producer ran one (written with PosWriterOptions::testColumn).
  std::optional<ResidualTest> residualTest;
  std::optional<Eigen::Vector3d> velocity;                        ///< ECEF, m/s
  Eigen::Matrix3d velocityCovariance = Eigen::Matrix3d::Zero();   ///< ECEF, (m/s)^2
};

}  // namespace gvins
