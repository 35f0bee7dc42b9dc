#include <chrono>
#include <cstdio>
#include <vector>

#include "gvins/base/parse_error.hpp"
#include "gvins/gnss/rtk_combination.hpp"
#include "gvins/gnss/rtk_pass.hpp"
#include "post_processing.hpp"

namespace gvins::rtkapp {
namespace {

/// Reads all rover and base epochs; a malformed input ends the reading (exit status 1) and the
/// run goes on with what was read.
void readAll(PostRun& r, std::vector<ObsEpoch>& rovers, std::vector<ObsEpoch>& bases) {
  try {
    while (r.haveRover) {
      rovers.push_back(r.roverEpoch);
      r.haveRover = r.rover.next(r.roverEpoch);
    }
    ObsEpoch baseEpoch;
    while (r.base.next(baseEpoch)) bases.push_back(baseEpoch);
  } catch (const ParseError& e) {
    r.fail(e.what());
  }
}

/// One pass with a progress line (at most every 200 ms on a terminal, 5 s otherwise, and at the
/// end); its duration goes to `seconds`.
std::vector<RtkSolution> pass(PostRun& r, RtkSolver& solver, const std::vector<ObsEpoch>& rovers,
                              const std::vector<ObsEpoch>& bases, TimeDirection dir, double& seconds) {
  long passFixed = 0;
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<RtkSolution> out =
      runRtkPass(solver, rovers, bases, dir, [&](std::size_t done, std::size_t total, const RtkSolution& sol) {
        if (sol.quality == SolutionQuality::Fix) ++passFixed;
        if (r.args.quiet) return;
        const auto now = std::chrono::steady_clock::now();
        if (done < total && now - r.lastProgress < std::chrono::milliseconds(r.tty ? 200 : 5000)) return;
        r.lastProgress = now;
        std::fprintf(stderr, "%s%s pass: %s epoch %zu/%zu fix %ld%s", r.tty ? "\r" : "", toString(dir),
                     sol.time.toString(1).c_str(), done, total, passFixed, r.tty ? "   " : "\n");
        std::fflush(stderr);
      });
  seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!r.args.quiet && r.tty) std::fputc('\n', stderr);
  return out;
}

}  // namespace

void runCombined(PostRun& r) {
  std::vector<ObsEpoch> rovers, bases;
  readAll(r, rovers, bases);
  r.counts.baseEpochs = static_cast<long>(bases.size());
  r.takeBaseAntennaPosition();
  RtkSolver backward(r.nav, r.cfg, r.sppCfg);
  for (RtkSolver* s : {&r.solver, &backward}) {
    s->setRoverGlonassChannels(r.hdr.glonassChannels);
    if (r.hdr.station.approxPosition && r.hdr.station.approxPosition->norm() > 1e6) {
      s->setRoverInitialPosition(*r.hdr.station.approxPosition);
    }
    if (r.basePos.position) s->setBasePosition(*r.basePos.position);
    s->setBaseGlonassChannels(r.base.glonassChannels());
    s->setPhaseAlignment(r.roverAlignment, r.base.phaseAlignment());
  }
  const std::vector<RtkSolution> forwardPass =
      pass(r, r.solver, rovers, bases, TimeDirection::Forward, r.counts.passSeconds[0]);
  const std::vector<RtkSolution> backwardPass =
      pass(r, backward, rovers, bases, TimeDirection::Backward, r.counts.passSeconds[1]);
  r.showDopplerWarnings();
  const std::vector<RtkSolution> combined =
      combinePasses(forwardPass, backwardPass, CombinationOptions{}, nullptr, &r.counts.combination);
  for (const RtkSolution& sol : combined) {
    ++r.counts.epochs;
    r.consume(sol);
  }
}

}  // namespace gvins::rtkapp
