#include "rtk_summary.hpp"

#include <algorithm>
#include <cstdio>
#include <string>

namespace gvins::rtkapp {
namespace {

double pct(long a, long b) { return b > 0 ? 100.0 * static_cast<double>(a) / static_cast<double>(b) : 0.0; }

/// Mode, base, epoch counts by quality, ratios, combination counts.
void printSolutionCounts(const RtkOptions& args, const RtkConfig& cfg, const BaseReader& base, const RunCounts& counts,
                         const BaseLocation& basePos) {
  const long epochs = counts.epochs, fixed = counts.fixed, floats = counts.floats, singles = counts.singles,
             none = counts.none, partial = counts.partial, held = counts.held;
  const long solved = fixed + floats + singles;
  std::fprintf(stderr, "gvins-rtk summary (%s, base %s)\n", args.inputs[0].c_str(), base.describe().c_str());
  std::fprintf(stderr, "  mode                   %s, %s, AR %s, ratio %.1f\n", toString(cfg.mode),
               cfg.mode == RtkMode::Kinematic ? toString(cfg.dynamics) : "static position", toString(cfg.ambiguityMode),
               cfg.ar.ratioThreshold);
  if (const auto& p = basePos.position) {
    std::fprintf(stderr, "  base position          %.4f %.4f %.4f (%s)\n", (*p)[0], (*p)[1], (*p)[2],
                 basePos.source.c_str());
  } else {
    std::fprintf(stderr, "  base position          unknown (no header position, 1005/1006 or --base-xyz)\n");
  }
  std::fprintf(stderr, "  rover epochs           %8ld\n", epochs);
  std::fprintf(stderr, "  base epochs read       %8ld\n", counts.baseEpochs);
  std::fprintf(stderr, "  fixed   (Q=1)          %8ld  %6.2f %%%s\n", fixed, pct(fixed, epochs),
               partial ? (" (" + std::to_string(partial) + " partial)").c_str() : "");
  std::fprintf(stderr, "  float   (Q=2)          %8ld  %6.2f %%\n", floats, pct(floats, epochs));
  std::fprintf(stderr, "  single  (Q=5)          %8ld  %6.2f %%\n", singles, pct(singles, epochs));
  std::fprintf(stderr, "  no solution            %8ld  %6.2f %%\n", none, pct(none, epochs));
  std::fprintf(stderr, "  fix rate               %8.2f %% of epochs, %.2f %% of RTK epochs\n", pct(fixed, epochs),
               pct(fixed, fixed + floats));
  if (counts.ratioCount) {
    std::fprintf(stderr, "  ratio                  min %.2f  median %.2f  mean %.2f  max %.1f  (%ld epochs)\n", counts.ratioMin,
                 counts.ratios.quantile(0.5), counts.ratioSum / counts.ratioCount, counts.ratioMax, counts.ratioCount);
  }
  std::fprintf(stderr, "  mean satellites        %8.1f   max age %.1f s\n", solved ? counts.satSum / solved : 0.0, counts.ageMax);
  if (held) std::fprintf(stderr, "  fix-and-hold updates   %8ld\n", held);
  if (args.combined) {
    const CombinationCounts& k = counts.combination;
    std::fprintf(stderr, "  combined               forward %lld fixed (%.1f s), backward %lld fixed (%.1f s)\n",
                 static_cast<long long>(k.forwardFixed), counts.passSeconds[0], static_cast<long long>(k.backwardFixed),
                 counts.passSeconds[1]);
    std::fprintf(stderr, "  combined fixes         %8lld  (%lld both, %lld forward only, %lld backward only)\n",
                 static_cast<long long>(k.combinedFixed), static_cast<long long>(k.bothFixed),
                 static_cast<long long>(k.forwardOnlyFixed), static_cast<long long>(k.backwardOnlyFixed));
    std::fprintf(stderr, "  combined to float      %8lld disagreements (both fixed), %lld fixes inconsistent with the other float\n",
                 static_cast<long long>(k.disagreements), static_cast<long long>(k.fixRejected));
  }
  for (const auto& [i, n] : counts.issues) std::fprintf(stderr, "  no RTK: %-30s %6ld\n", toString(i), n);
  for (const auto& [s, n] : counts.arStatus) {
    if (s != ArStatus::Fixed && s != ArStatus::PartialFixed) std::fprintf(stderr, "  AR: %-34s %6ld\n", toString(s), n);
  }
}

/// What the solver and the readers counted, the run time and the accuracy against --truth.
void printSolverCounts(const RtkConfig& cfg, const RtkSolver& solver, const BaseReader& rover, const BaseReader& base,
                       const RunCounts& counts, double wall) {
  const long epochs = counts.epochs, fixed = counts.fixed;
  const RtkCounters& c = solver.counters();
  std::fprintf(stderr, "  ambiguities            %lld added, %lld slip resets, %lld outlier resets, %lld removed\n",
               static_cast<long long>(c.ambiguitiesAdded), static_cast<long long>(c.slipResets),
               static_cast<long long>(c.phaseOutliers), static_cast<long long>(c.ambiguitiesRemoved));
  if (c.impreciseFixes || c.inconsistentFixes || c.unconfirmedFixes) {
    std::fprintf(stderr, "  fixes not used         %lld imprecise (sigma > %.2f m), %lld inconsistent with float, %lld awaiting confirmation\n",
                 static_cast<long long>(c.impreciseFixes), cfg.maxFixedSigma, static_cast<long long>(c.inconsistentFixes),
                 static_cast<long long>(c.unconfirmedFixes));
  }
  if (c.codeOutliers || c.filterResets || c.rejectedFixes) {
    std::fprintf(stderr, "  rejected               %lld code DDs, %lld fixes by residual check, %lld filter resets\n",
                 static_cast<long long>(c.codeOutliers), static_cast<long long>(c.rejectedFixes),
                 static_cast<long long>(c.filterResets));
  }
  auto slipLine = [&](const char* who, const CycleSlipCounts& s) {
    std::fprintf(stderr, "  %s slips             LLI %lld, geometry-free %lld, Doppler %lld, gap %lld, half-cycle %lld\n", who,
                 static_cast<long long>(s.lli), static_cast<long long>(s.geometryFree), static_cast<long long>(s.doppler),
                 static_cast<long long>(s.gaps), static_cast<long long>(s.halfCycle));
  };
  slipLine("rover", solver.roverSlipCounts());
  slipLine("base ", solver.base().slipCounts());
  for (const DopplerConsistency* d : {&solver.roverDoppler(), &solver.base().doppler()}) {
    std::fprintf(stderr, "  %-5s Doppler           %s\n", d->label().c_str(), d->countsText().c_str());
    for (const std::string& line : d->summary()) std::fprintf(stderr, "    %s\n", line.c_str());
  }
  const DdFormationStats& ds = solver.differenceStats();
  if (ds.notAtBase || ds.signalMismatch || ds.noEphemeris || ds.systemDisabled) {
    std::fprintf(stderr, "  satellite-epochs       %lld not at base, %lld signal mismatches, %lld no ephemeris, %lld below mask\n",
                 static_cast<long long>(ds.notAtBase), static_cast<long long>(ds.signalMismatch),
                 static_cast<long long>(ds.noEphemeris), static_cast<long long>(ds.belowMask));
  }
  if (ds.crossMode || ds.crossModeRefused) {
    std::fprintf(stderr, "  signal pairs           %lld across tracking modes (%s matching), %lld refused (strict, or phase alignment unknown)\n",
                 static_cast<long long>(ds.crossMode), toString(cfg.signalMatching),
                 static_cast<long long>(ds.crossModeRefused));
  }
  const BaseStationStats& bs = solver.base().stats();
  if (bs.outOfOrder || bs.positionChanges) {
    std::fprintf(stderr, "  base input             %lld epochs out of order, %lld position changes\n",
                 static_cast<long long>(bs.outOfOrder), static_cast<long long>(bs.positionChanges));
  }
  static const RinexObsReaderStats kNoStats;
  const RinexObsReaderStats& rs = rover.rinexStats() ? *rover.rinexStats() : kNoStats;
  if (rover.skipped() || base.skipped()) {
    std::fprintf(stderr, "  input                  %lld malformed rover epochs/frames skipped, %lld base epochs/frames skipped\n",
                 static_cast<long long>(rover.skipped()), static_cast<long long>(base.skipped()));
    for (const auto& m : rs.messages) std::fprintf(stderr, "    %s\n", m.c_str());
  }
  std::fprintf(stderr, "  time                   %8.3f s (%.0f epochs/s)\n", wall, wall > 0 ? epochs / wall : 0.0);
  if (counts.fixStats) {
    std::fprintf(stderr, "  wrong fixes            %8ld of %ld fixed epochs more than %.2f m from the truth\n", counts.wrongFixes, fixed,
                 kWrongFix);
  }
  if (counts.fixStats && counts.fixStats->position().count > 0) {
    std::fputs("  fixed solutions vs truth:\n", stderr);
    std::fputs(counts.fixStats->table().c_str(), stderr);
  }
  if (counts.rtkStats && counts.rtkStats->position().count > 0) {
    std::fputs("  fixed and float solutions vs truth:\n", stderr);
    std::fputs(counts.rtkStats->table().c_str(), stderr);
  }
}

}  // namespace

RunCounts::RunCounts(const std::optional<Eigen::Vector3d>& truthPosition) : truth(truthPosition) {
  if (truth) {
    fixStats.emplace(*truth);
    rtkStats.emplace(*truth);
  }
}

void RunCounts::add(const RtkSolution& sol) {
  if (sol.issue != RtkIssue::None) ++issues[sol.issue];
  if (sol.quality == SolutionQuality::Fix || sol.quality == SolutionQuality::Float) {
    ++arStatus[sol.ar];
    if (sol.ar != ArStatus::Off && sol.ar != ArStatus::TooFewAmbiguities && sol.ratio > 0.0) {
      ratios.add(sol.ratio);
      ratioMin = std::min(ratioMin, sol.ratio);
      ratioMax = std::max(ratioMax, sol.ratio);
      ratioSum += sol.ratio;
      ++ratioCount;
    }
  }
  switch (sol.quality) {
    case SolutionQuality::Fix: ++fixed; break;
    case SolutionQuality::Float: ++floats; break;
    case SolutionQuality::Single: ++singles; break;
    default: ++none; break;
  }
  if (sol.ar == ArStatus::PartialFixed && sol.quality == SolutionQuality::Fix) ++partial;
  if (sol.held) ++held;
  if (!sol.valid()) return;
  satSum += sol.numSatellites;
  if (sol.quality != SolutionQuality::Single) ageMax = std::max(ageMax, sol.age);
  if (fixStats && sol.quality == SolutionQuality::Fix) {
    fixStats->addPosition(sol.position);
    if ((sol.position - *truth).norm() > kWrongFix) ++wrongFixes;
  }
  if (rtkStats && sol.quality != SolutionQuality::Single) rtkStats->addPosition(sol.position);
}

void printSummary(const RtkOptions& args, const RtkConfig& cfg, const RtkSolver& solver, const BaseReader& rover,
                  const BaseReader& base, const RunCounts& counts, const BaseLocation& basePos, double wall) {
  printSolutionCounts(args, cfg, base, counts, basePos);
  printSolverCounts(cfg, solver, rover, base, counts, wall);
}

}  // namespace gvins::rtkapp
