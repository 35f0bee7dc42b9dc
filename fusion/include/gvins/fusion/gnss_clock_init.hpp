// Receiver clock initialisation (paper Sec. III-B): at a known antenna position and velocity
// every pseudorange gives c·dt_r of its constellation and every Doppler range rate gives c·ḋt_r,
// i.e. the linear system A X = b with X = [c·dt_0 … c·dt_{N−1}, c·ḋt]. RANSAC (Fischler & Bolles
// 1981) on minimal samples (one row per unknown) rejects faulty rows (NLOS, wrong position for a
// few satellites); least squares on the inliers of the best hypothesis gives X.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace gvins::fusion {

/// One row of A X = b: b = X[unknown] + noise (pseudorange rows: a clock index; Doppler rows:
/// the drift index N).
struct ClockRow {
  int unknown = 0;
  double value = 0.0;      ///< m or m/s
  double threshold = 5.0;  ///< inlier threshold for this row (m or m/s)
};

struct ClockInitResult {
  bool ok = false;                 ///< every unknown has at least `minInliers` inliers
  std::vector<double> x;           ///< N+1 values
  std::vector<double> sigma;       ///< standard deviation of each value (inlier scatter / √n)
  std::vector<int> inliers;        ///< per unknown
  std::vector<bool> inlier;        ///< per row
};

/// `numUnknowns` = N + 1. Deterministic for a given seed.
ClockInitResult initializeClocksRansac(std::span<const ClockRow> rows, int numUnknowns, int iterations = 64,
                                       int minInliers = 1, std::uint64_t seed = 1);

}  // namespace gvins::fusion
