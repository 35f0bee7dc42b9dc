// Combined (forward + backward) post-processing solution: per epoch, the solutions of a forward
// and a backward RtkSolver pass over the same data are merged into one (the rule and its
// equations: docs/rtk.md, "Combined forward + backward solution").
//
//   float: the two float positions weighted by their covariances,
//          P = (Pf⁻¹ + Pb⁻¹)⁻¹,  x = P (Pf⁻¹ xf + Pb⁻¹ xb)
//          (the least-squares estimate from two independent estimates of the same position);
//   fixed: both passes fixed and their fixed positions agree (χ²(3) test on xf − xb with
//          Pf + Pb) -> the weighted mean of the two fixed positions, Q=1;
//          both fixed but disagreeing -> float (counted: Disagreement);
//          one pass fixed -> that fix if it agrees with the other pass's float position (χ²(3)
//          test with the float covariance, floored: a filter's float covariance is optimistic)
//          or if the other pass has no float, else float (counted: FixRejected).
// A fix that a pass's own validation rejected is never made: only Q=1 solutions count as fixes.
#pragma once

#include <cstdint>
#include <vector>

#include "gvins/gnss/rtk.hpp"

namespace gvins {

/// How the combined solution of an epoch came about.
enum class Combination : std::uint8_t {
  None,           ///< neither pass has a solution
  Single,         ///< no RTK solution in either pass: a single-point fallback (forward's first)
  Float,          ///< float, from one pass or combined from both
  BothFixed,      ///< both passes fixed and agreeing: combined fix
  ForwardFixed,   ///< forward fix, consistent with the backward float (or no backward float)
  BackwardFixed,  ///< backward fix, consistent with the forward float (or no forward float)
  FixRejected,    ///< one pass fixed, inconsistent with the other's float: float
  Disagreement,   ///< both passes fixed at different positions: float
};
const char* toString(Combination c);

struct CombinationOptions {
  /// Size of the χ²(3) consistency tests (probability of rejecting a right pair).
  double alpha = 1e-3;
  /// m, standard deviation added per axis to a float covariance in the test of a fix against
  /// that float (the float filter's error is correlated in time; its covariance is optimistic).
  double floatSigmaFloor = 0.10;
};

struct CombinationCounts {
  std::int64_t epochs = 0;
  std::int64_t forwardFixed = 0, backwardFixed = 0;
  std::int64_t combinedFixed = 0;  ///< Q=1 combined epochs (BothFixed + ForwardFixed + BackwardFixed)
  std::int64_t bothFixed = 0, forwardOnlyFixed = 0, backwardOnlyFixed = 0;
  std::int64_t fixRejected = 0, disagreements = 0;
  void add(const RtkSolution& forward, const RtkSolution& backward, Combination how);
};

/// Covariance-weighted combination of two independent estimates (xa, Pa), (xb, Pb) of one
/// position: P = (Pa⁻¹ + Pb⁻¹)⁻¹, x = P (Pa⁻¹ xa + Pb⁻¹ xb). False when a covariance is not
/// positive definite (x, P untouched).
bool combineEstimates(const Eigen::Vector3d& xa, const Eigen::Matrix3d& Pa, const Eigen::Vector3d& xb,
                      const Eigen::Matrix3d& Pb, Eigen::Vector3d& x, Eigen::Matrix3d& P);

/// Whether xa − xb is consistent with covariance S (χ²(3) test of size alpha).
bool consistent(const Eigen::Vector3d& xa, const Eigen::Vector3d& xb, const Eigen::Matrix3d& S, double alpha);

/// The combined solution of one epoch from its forward and backward solutions (same epoch).
RtkSolution combineSolutions(const RtkSolution& forward, const RtkSolution& backward, const CombinationOptions& options,
                             Combination* how = nullptr);

/// The combined solutions of a forward and a backward pass over the same rover epochs (one
/// solution per epoch in both, in the same order: rtk_pass.hpp): combineSolutions per epoch.
/// `how` (if given) receives each epoch's Combination, `counts` (if given) adds them up. Throws
/// std::invalid_argument when the passes differ in length.
std::vector<RtkSolution> combinePasses(const std::vector<RtkSolution>& forward, const std::vector<RtkSolution>& backward,
                                       const CombinationOptions& options, std::vector<Combination>* how = nullptr,
                                       CombinationCounts* counts = nullptr);

}  // namespace gvins
