// The counts of a gvins-rtk post-processing run and the summary printed from them on stderr.
#pragma once

#include <map>
#include <optional>

#include <Eigen/Core>

#include "gvins/gnss/accuracy_statistics.hpp"
#include "gvins/gnss/base_reader.hpp"
#include "gvins/gnss/rtk.hpp"
#include "gvins/gnss/rtk_combination.hpp"
#include "gvins/gnss/rtk_config.hpp"
#include "rtk_options.hpp"
#include "rtk_output.hpp"

namespace gvins::rtkapp {

/// A fixed epoch farther than this from --truth counts as a wrong fix (3-D, m).
constexpr double kWrongFix = 0.10;

/// Counts of a run for the summary.
struct RunCounts {
  long epochs = 0, fixed = 0, floats = 0, singles = 0, none = 0, partial = 0, held = 0;
  std::map<RtkIssue, long> issues;
  std::map<ArStatus, long> arStatus;
  QuantileHistogram ratios;
  double ratioMin = 1e300, ratioMax = 0.0, ratioSum = 0.0;
  long ratioCount = 0;
  double satSum = 0.0, ageMax = 0.0;
  long wrongFixes = 0;  ///< fixed epochs farther than kWrongFix from --truth
  long baseEpochs = 0;
  CombinationCounts combination;
  double passSeconds[2] = {0.0, 0.0};
  std::optional<Eigen::Vector3d> truth;
  /// Accuracy of the fixed and of all RTK solutions against --truth (with a truth only).
  std::optional<AccuracyStatistics> fixStats, rtkStats;

  explicit RunCounts(const std::optional<Eigen::Vector3d>& truthPosition);
  /// Counts one epoch's solution (the epoch itself is counted by the caller).
  void add(const RtkSolution& sol);
};

/// The summary on stderr; `wall` is the run's duration, s.
void printSummary(const RtkOptions& args, const RtkConfig& cfg, const RtkSolver& solver, const BaseReader& rover,
                  const BaseReader& base, const RunCounts& counts, const BaseLocation& basePos, double wall);

}  // namespace gvins::rtkapp
