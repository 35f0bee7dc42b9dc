#include "spp_run.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <exception>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "gvins/base/parse_error.hpp"
#include "gvins/base/rinex_obs_reader.hpp"
#include "gvins/gnss/accuracy_statistics.hpp"
#include "gvins/gnss/base_reader.hpp"
#include "gvins/gnss/carrier_smoothing.hpp"
#include "gvins/gnss/clock_jump_repair.hpp"
#include "gvins/gnss/doppler_consistency.hpp"
#include "gvins/gnss/spp.hpp"
#include "spp_inputs.hpp"
#include "spp_output.hpp"
#include "spp_summary.hpp"

namespace gvins::sppapp {
namespace {

/// Prints the warnings of `all` from `shown` on (each once).
void printWarnings(const std::vector<std::string>& all, std::size_t& shown, bool tty) {
  for (; shown < all.size(); ++shown) std::fprintf(stderr, "%sgvins-spp: warning: %s\n", tty ? "\r" : "", all[shown].c_str());
}

/// One epoch's way to a solution: whole-ms receiver clock jumps repaired (clock_jump_repair.hpp),
/// the Doppler checked (doppler_consistency.hpp: a flipped sign is corrected, a Doppler that
/// disagrees with the phase/code rate is dropped), the pseudoranges carrier-smoothed if asked,
/// then the solver; each warning printed once.
class EpochProcessor {
 public:
  EpochProcessor(const EphemerisStore& nav, const SppConfig& cfg, const BaseReader& obs, const RinexObsHeader& hdr,
                 bool tty)
      : nav_(nav), solver_(nav, cfg), tty_(tty) {
    solver_.setGlonassChannels(obs.glonassChannels());
    // GLONASS channels for the carrier smoothing's wavelengths: the header's, else the
    // navigation records' (as the solver does).
    channels_ = obs.glonassChannels();
    channels_.mergeMissing(nav.glonassChannels());
    if (hdr.station.approxPosition) solver_.setInitialPosition(*hdr.station.approxPosition);
    if (cfg.carrierSmoothing > 0.0) {
      CarrierSmoothingOptions so;
      so.window = cfg.carrierSmoothing;
      smoother_.emplace(so);
    }
  }

  SppSolution process(ObsEpoch& epoch, const BaseReader& obs) {
    if (obs.format() == BaseFormat::Ubx) {  // UBX: GLONASS channels arrive with the observations (RAWX freqId)
      channels_ = obs.glonassChannels();
      channels_.mergeMissing(nav_.glonassChannels());
      solver_.setGlonassChannels(obs.glonassChannels());
    }
    clockJumps_.apply(epoch, channels_);  // before the Doppler check and smoothing
    printWarnings(clockJumps_.warnings(), jumpWarned_, tty_);
    doppler_.apply(epoch, channels_);
    printWarnings(doppler_.warnings(), dopplerWarned_, tty_);
    if (smoother_) smoother_->apply(epoch, channels_);
    SppSolution sol = solver_.solve(epoch);
    printWarnings(solver_.signalNotices(), signalWarned_, tty_);  // primary signals from a fallback band
    return sol;
  }

  const DopplerConsistency& doppler() const { return doppler_; }

 private:
  const EphemerisStore& nav_;
  SppSolver solver_;
  GlonassChannels channels_;
  std::optional<CarrierSmoother> smoother_;
  DopplerConsistency doppler_{"rover"};
  ClockJumpRepair clockJumps_{"rover"};
  std::size_t dopplerWarned_ = 0, jumpWarned_ = 0, signalWarned_ = 0;
  bool tty_;
};

/// The progress line on stderr: every 200 ms on a terminal (overwritten), else every 5 s.
class Progress {
 public:
  Progress(const RinexObsHeader& hdr, bool tty, std::chrono::steady_clock::time_point wall0)
      : hdr_(hdr), tty_(tty), last_(wall0), span_(hdr.firstObs && hdr.lastObs ? *hdr.lastObs - *hdr.firstObs : 0.0) {}

  void update(GpsTime t, long epochs, long solutions) {
    const auto now = std::chrono::steady_clock::now();
    if (now - last_ <= std::chrono::milliseconds(tty_ ? 200 : 5000)) return;
    last_ = now;
    std::string pct;
    if (span_ > 0.0 && hdr_.firstObs) {
      char buf[160];
      std::snprintf(buf, sizeof buf, " %5.1f%%", 100.0 * std::clamp((t - *hdr_.firstObs) / span_, 0.0, 1.0));
      pct = buf;
    }
    std::fprintf(stderr, "%s%s epoch %ld %s solutions %ld%s", tty_ ? "\r" : "", t.toString(1).c_str(), epochs,
                 pct.c_str(), solutions, tty_ ? "   " : "\n");
    std::fflush(stderr);
  }

 private:
  const RinexObsHeader& hdr_;
  bool tty_;
  std::chrono::steady_clock::time_point last_;
  double span_;
};

}  // namespace

int runSpp(const SppOptions& args, const SppConfig& cfg, EphemerisStore& nav, std::chrono::steady_clock::time_point wall0) {
  const std::unique_ptr<BaseReader> obs = openObservations(args, nav);
  if (!obs) return 1;
  if (nav.size() == 0 && obs->format() != BaseFormat::Ubx) {
    std::fprintf(stderr, "gvins-spp: error: no usable ephemeris in the navigation files\n");
    return 1;
  }
  static const RinexObsHeader kNoHeader;
  const RinexObsHeader& hdr = obs->rinexHeader() ? *obs->rinexHeader() : kNoHeader;
  if (!args.ssr.empty()) {
    if (const int rc = readSsr(args, nav)) return rc;
  }

  const bool tty = isatty(fileno(stderr));
  EpochProcessor processor(nav, cfg, *obs, hdr, tty);
  std::unique_ptr<SppOutput> output;
  try {
    output = std::make_unique<SppOutput>(args, posOptions(args, cfg, *obs, hdr));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "gvins-spp: error: %s\n", e.what());
    return 1;
  }
  std::optional<AccuracyStatistics> stats;
  if (args.truth) stats.emplace(*args.truth);

  RunCounts c;
  Progress progress(hdr, tty, wall0);
  int exitCode = 0;
  ObsEpoch epoch;
  for (;;) {
    try {
      if (!obs->next(epoch)) break;
    } catch (const ParseError& e) {
      printSppError(e.what());
      exitCode = 1;
      break;
    }
    ++c.epochs;
    const SppSolution sol = processor.process(epoch, *obs);
    c.add(sol);
    if (sol.valid()) {
      const PositionSolution ps = sol.toPositionSolution();
      c.addValid(sol, ps);
      if (args.dropFailed && ps.residualTest == ResidualTest::Failed) continue;
      ++c.written;
      output->write(sol, ps);
      if (stats) {
        stats->addPosition(sol.position);
        if (sol.velocity.valid) stats->addVelocity(sol.velocity.velocity);
      }
    }
    if (!args.quiet) progress.update(epoch.time, c.epochs, c.solutions);
  }
  exitCode = output->finish(exitCode);
  if (!args.quiet && tty) std::fprintf(stderr, "\r%60s\r", "");
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  printSummary(args, *obs, hdr, c, processor.doppler(), wall);
  if (stats) std::fputs(stats->table().c_str(), stderr);
  if (c.solutions == 0 && exitCode == 0) exitCode = 3;
  return exitCode;
}

}  // namespace gvins::sppapp
