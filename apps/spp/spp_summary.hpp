// The counts of a gvins-spp run and the summary printed from them on stderr; --score.
#pragma once

#include <array>
#include <map>

#include "gvins/gnss/base_reader.hpp"
#include "gvins/gnss/doppler_consistency.hpp"
#include "gvins/gnss/spp.hpp"
#include "spp_options.hpp"

namespace gvins::sppapp {

/// Counts of the processing loop for the summary.
struct RunCounts {
  std::map<SppStatus, long> status;
  std::map<SatId, long> excluded;
  std::array<long, 8> use{};
  long epochs = 0, solutions = 0, velocities = 0, testFailed = 0, untestable = 0, written = 0;
  double satSum = 0.0;

  /// Counts the status, satellite use and exclusions of an epoch's solution.
  void add(const SppSolution& sol);
  /// Counts a valid solution (`ps` is sol.toPositionSolution()).
  void addValid(const SppSolution& sol, const PositionSolution& ps);
};

/// The summary on stderr; `wall` is the run's duration, s.
void printSummary(const SppOptions& args, const BaseReader& obs, const RinexObsHeader& hdr, const RunCounts& c,
                  const DopplerConsistency& doppler, double wall);

/// --score: the accuracy table of an existing .pos file; the exit status.
int scorePosFile(const SppOptions& args);

}  // namespace gvins::sppapp
