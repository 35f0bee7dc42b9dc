// Fault detection and exclusion for least-squares solutions (RAIM-FDE): a global chi-square test
// of the weighted residuals, then exclusion of one measurement at a time, each chosen by refitting
// without every candidate (leave-one-out) and keeping the subset whose test statistic is smallest
// relative to its threshold.
#pragma once

#include <functional>
#include <vector>

namespace gvins {

struct FaultExclusionOptions {
  bool enabled = true;
  /// False-alarm probability of the global test (the chi-square quantile 1 - pfa is the threshold).
  double falseAlarmProbability = 1e-3;
  /// Most measurements excluded in one epoch.
  int maxExclusions = 6;
  /// Candidates tried per round: those with the largest normalised residuals (0: all).
  int maxCandidates = 10;
  /// Stop excluding when the remaining redundancy (degrees of freedom) would drop below this.
  int minRedundancy = 1;
};

/// A fit of a subset of the measurements.
struct SubsetFit {
  bool ok = false;
  double chi2 = 0.0;  ///< weighted sum of squared residuals
  int dof = 0;        ///< measurements (including pseudo-measurements) minus unknowns
  /// Normalised residual |v_i| / sigma(v_i) of every measurement in use (index: measurement), for
  /// ranking candidates; may be empty (then every measurement is a candidate).
  std::vector<double> normalizedResidual;
};

struct FaultExclusionResult {
  std::vector<int> excluded;  ///< measurement indices, in exclusion order
  bool testPassed = false;    ///< global test after the exclusions
  SubsetFit fit;              ///< final fit
  int fits = 0;               ///< number of fits made
};

/// Threshold of the global test for `dof` degrees of freedom.
double globalTestThreshold(int dof, double falseAlarmProbability);

/// Runs detection and exclusion. `fit(use)` must fit the measurements with use[i] != 0 (size n).
/// Measurements with use[i] == 0 on entry are never re-admitted.
FaultExclusionResult detectAndExclude(std::vector<char>& use,
                                      const std::function<SubsetFit(const std::vector<char>&)>& fit,
                                      const FaultExclusionOptions& options);

}  // namespace gvins
