#include "spp_summary.hpp"

#include <cstdio>

#include "gvins/base/parse_error.hpp"
#include "gvins/gnss/accuracy_statistics.hpp"
#include "gvins/gnss/pos_reader.hpp"

namespace gvins::sppapp {

void RunCounts::add(const SppSolution& sol) {
  ++status[sol.status];
  for (const auto& s : sol.satellites) ++use[static_cast<int>(s.use)];
  for (const auto& s : sol.excluded) ++excluded[s];
}

void RunCounts::addValid(const SppSolution& sol, const PositionSolution& ps) {
  ++solutions;
  if (ps.residualTest == ResidualTest::Failed) ++testFailed;
  if (ps.residualTest == ResidualTest::Untestable) ++untestable;
  satSum += sol.numSatellites;
  if (sol.velocity.valid) ++velocities;
}

void printSummary(const SppOptions& args, const BaseReader& obs, const RinexObsHeader& hdr, const RunCounts& c,
                  const DopplerConsistency& doppler, double wall) {
  static const RinexObsReaderStats kNoStats;
  const RinexObsReaderStats& rs = obs.rinexStats() ? *obs.rinexStats() : kNoStats;
  const long epochs = c.epochs, solutions = c.solutions;
  std::fprintf(stderr, "gvins-spp summary (%s)\n", args.inputs[0].c_str());
  std::fprintf(stderr, "  epochs read            %8ld\n", epochs);
  std::fprintf(stderr, "  solutions              %8ld (%.1f %%)\n", solutions, epochs ? 100.0 * solutions / epochs : 0.0);
  std::fprintf(stderr, "    residual test failed %8ld (%s)\n", c.testFailed,
               args.dropFailed ? "omitted: --drop-failed" : "written with test = 1");
  std::fprintf(stderr, "    not testable         %8ld (no redundancy; test = 2)\n", c.untestable);
  std::fprintf(stderr, "  rows written           %8ld\n", c.written);
  std::fprintf(stderr, "  velocity solutions     %8ld\n", c.velocities);
  std::fprintf(stderr, "  mean satellites used   %8.1f\n", solutions ? c.satSum / solutions : 0.0);
  std::fprintf(stderr, "  Doppler                %s\n", doppler.countsText().c_str());
  for (const std::string& line : doppler.summary()) std::fprintf(stderr, "    %s\n", line.c_str());
  for (const auto& [st, n] : c.status) {
    if (st != SppStatus::Ok && st != SppStatus::TestFailed) std::fprintf(stderr, "  no solution: %-22s %6ld\n", toString(st), n);
  }
  static const char* kUse[] = {"used", "system disabled", "no signal", "low C/N0", "no ephemeris", "below mask", "excluded"};
  std::fprintf(stderr, "  satellite-epochs:");
  for (int i = 0; i < 7; ++i) {
    if (c.use[i]) std::fprintf(stderr, " %s %ld;", kUse[i], c.use[i]);
  }
  std::fprintf(stderr, "\n");
  if (!c.excluded.empty()) {
    std::fprintf(stderr, "  excluded by FDE:");
    for (const auto& [s, n] : c.excluded) std::fprintf(stderr, " %s x%ld", s.str().c_str(), n);
    std::fprintf(stderr, "\n");
  }
  if (rs.skippedEpochs || rs.skippedSatellites || rs.specialRecords || rs.emptyEpochs) {
    std::fprintf(stderr, "  input: %lld malformed epochs skipped, %lld satellite records skipped, %lld event records, %lld empty epochs\n",
                 static_cast<long long>(rs.skippedEpochs), static_cast<long long>(rs.skippedSatellites),
                 static_cast<long long>(rs.specialRecords), static_cast<long long>(rs.emptyEpochs));
    for (const auto& m : rs.messages) std::fprintf(stderr, "    %s\n", m.c_str());
  }
  if (obs.format() == BaseFormat::Ubx) {
    std::fprintf(stderr, "  input: %s; %lld malformed messages skipped\n", obs.describe().c_str(),
                 static_cast<long long>(obs.skipped()));
  }
  if (!hdr.ignoredTypes.empty()) {
    std::fprintf(stderr, "  observation columns not used (unknown or non-measurement codes):");
    for (const auto& t : hdr.ignoredTypes) std::fprintf(stderr, " %s;", t.c_str());
    std::fprintf(stderr, "\n");
  }
  std::fprintf(stderr, "  time                   %8.3f s (%.0f epochs/s)\n", wall, wall > 0 ? epochs / wall : 0.0);
}

int scorePosFile(const SppOptions& args) {
  try {
    const PosFile f = readPosFile(args.score);
    AccuracyStatistics st(*args.truth);
    for (const auto& s : f.solutions) {
      st.addPosition(s.position);
      if (s.velocity) st.addVelocity(*s.velocity);
    }
    std::fprintf(stderr, "gvins-spp score (%s, %zu solutions)\n", args.score.c_str(), f.solutions.size());
    std::fputs(st.table().c_str(), stderr);
    return f.solutions.empty() ? 3 : 0;
  } catch (const ParseError& e) {
    printSppError(e.what());
    return 1;
  }
}

}  // namespace gvins::sppapp
