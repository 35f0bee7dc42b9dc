#include "post_processing.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <optional>

#include "gvins/base/parse_error.hpp"
#include "gvins/gnss/base_station.hpp"

namespace gvins::rtkapp {
namespace {

/// Rover and base readers, told apart by content (BaseReader). UBX and RTCM add the ephemerides
/// they carry to `nav` as they are read.
struct Inputs {
  std::unique_ptr<BaseReader> rover, base;
  ObsEpoch roverEpoch;  ///< the first rover epoch, if haveRover
  bool haveRover = false;
};

/// Opens the rover and the base; 0 or the exit status (message printed).
int openInputs(const RtkOptions& args, EphemerisStore& nav, Inputs& in) {
  try {
    if (BaseReader::detect(args.inputs[0]) == BaseFormat::Rtcm) {
      printRtkError("rover " + args.inputs[0] + " is an RTCM 3 log; convert it with gvins-rtcm to-rinex --date first");
      return 1;
    }
    in.rover = BaseReader::open(args.inputs[0], GpsTime{}, &nav, !args.strict);
    in.haveRover = in.rover->next(in.roverEpoch);
    const BaseReader& rover = *in.rover;
    const GpsTime ref = in.haveRover ? in.roverEpoch.time
                                     : (rover.rinexHeader() ? rover.rinexHeader()->firstObs.value_or(GpsTime()) : GpsTime());
    in.base = BaseReader::open(args.inputs[1], ref, &nav, !args.strict);
  } catch (const ParseError& e) {
    printRtkError(e.what());
    return 1;
  }
  if (nav.size() == 0 && in.base->format() == BaseFormat::Rinex && in.rover->format() == BaseFormat::Rinex) {
    printRtkError("no usable ephemeris in the navigation files");
    return 1;
  }
  return 0;
}

/// Feeds the solver the base epochs up to the rover time and the first one after it (for
/// interpolation), never more: the base buffer only keeps what alignment can use.
class BaseFeed {
 public:
  void feedUpTo(PostRun& r, const GpsTime& roverTime) {
    try {
      while (!done_ && !(lastTime_ && *lastTime_ - roverTime > BaseStation::kSyncTolerance)) {
        if (!pending_) {
          if (!r.base.next(epoch_)) {
            done_ = true;
            break;
          }
          pending_ = true;
          ++r.counts.baseEpochs;
        }
        if (r.takeBaseAntennaPosition()) r.solver.setBasePosition(*r.basePos.position);
        r.solver.setBaseGlonassChannels(r.base.glonassChannels());
        r.solver.setPhaseAlignment(r.roverAlignment, r.base.phaseAlignment());
        r.solver.addBaseEpoch(epoch_);
        lastTime_ = epoch_.time;
        pending_ = false;
      }
    } catch (const ParseError& e) {
      r.fail(e.what());
      done_ = true;
    }
  }

 private:
  ObsEpoch epoch_;
  bool done_ = false, pending_ = false;
  std::optional<GpsTime> lastTime_;
};

/// The progress line of the streamed run (at most every 200 ms on a terminal, 5 s otherwise).
void showProgress(PostRun& r, const RtkSolution& sol) {
  const auto now = std::chrono::steady_clock::now();
  if (now - r.lastProgress <= std::chrono::milliseconds(r.tty ? 200 : 5000)) return;
  r.lastProgress = now;
  const RinexObsHeader& hdr = r.hdr;
  const double span = hdr.firstObs && hdr.lastObs ? *hdr.lastObs - *hdr.firstObs : 0.0;
  std::string p;
  if (span > 0.0 && hdr.firstObs) {
    char buf[200];
    std::snprintf(buf, sizeof buf, " %5.1f%%", 100.0 * std::clamp((r.roverEpoch.time - *hdr.firstObs) / span, 0.0, 1.0));
    p = buf;
  }
  const RunCounts& c = r.counts;
  std::fprintf(stderr, "%s%s epoch %ld%s fix %ld float %ld single %ld ratio %.1f%s", r.tty ? "\r" : "",
               r.roverEpoch.time.toString(1).c_str(), c.epochs, p.c_str(), c.fixed, c.floats, c.singles, sol.ratio,
               r.tty ? "   " : "\n");
  std::fflush(stderr);
}

/// Every rover epoch solved as it is read, with the base epochs fed up to it.
void runStreamed(PostRun& r) {
  BaseFeed feed;
  while (r.haveRover) {
    ++r.counts.epochs;
    feed.feedUpTo(r, r.roverEpoch.time);
    if (r.takeBaseAntennaPosition()) r.solver.setBasePosition(*r.basePos.position);
    if (r.rover.format() != BaseFormat::Rinex) r.solver.setRoverGlonassChannels(r.rover.glonassChannels());
    const RtkSolution sol = r.solver.process(r.roverEpoch);
    r.showDopplerWarnings();
    r.consume(sol);
    if (!r.args.quiet) showProgress(r, sol);
    try {
      r.haveRover = r.rover.next(r.roverEpoch);
    } catch (const ParseError& e) {
      r.fail(e.what());
      break;
    }
  }
}

}  // namespace

void PostRun::consume(const RtkSolution& sol) {
  counts.add(sol);
  if (sol.valid()) output.write(sol, basePos);
}

void PostRun::showDopplerWarnings() {
  auto show = [&](const DopplerConsistency& d, std::size_t& shown) {
    for (; shown < d.warnings().size(); ++shown) {
      std::fprintf(stderr, "%sgvins-rtk: warning: %s\n", tty ? "\r" : "", d.warnings()[shown].c_str());
    }
  };
  show(solver.roverDoppler(), roverWarned);
  show(solver.base().doppler(), baseWarned);
}

bool PostRun::takeBaseAntennaPosition() {
  if (args.baseXyz || basePos.position) return false;
  const auto p = base.antennaPosition();
  if (!p) return false;
  basePos.position = p;
  basePos.source = base.format() == BaseFormat::Rtcm ? "RTCM 1005/1006" : "RINEX header";
  return true;
}

void PostRun::fail(const std::string& message) {
  printRtkError(message);
  exitCode = 1;
}

int runPostProcessing(const RtkOptions& args, const RtkConfig& cfg, const SppConfig& sppCfg, EphemerisStore& nav,
                      std::chrono::steady_clock::time_point wall0) {
  Inputs in;
  if (const int rc = openInputs(args, nav, in)) return rc;
  static const RinexObsHeader kNoHeader;
  const RinexObsHeader& hdr = in.rover->rinexHeader() ? *in.rover->rinexHeader() : kNoHeader;

  RtkSolver solver(nav, cfg, sppCfg);
  solver.setRoverGlonassChannels(in.rover->glonassChannels());
  if (hdr.station.approxPosition && hdr.station.approxPosition->norm() > 1e6) {
    solver.setRoverInitialPosition(*hdr.station.approxPosition);
  }
  if (args.baseXyz) solver.setBasePosition(*args.baseXyz);
  std::optional<RtkOutput> output;
  try {
    output.emplace(args, cfg);
  } catch (const std::exception& e) {
    printRtkError(e.what());
    return 1;
  }
  RunCounts counts(args.truth);
  PostRun run{args, cfg, sppCfg, nav, *in.rover, *in.base, hdr, in.rover->phaseAlignment(), solver, *output,
              counts, in.roverEpoch, in.haveRover, BaseLocation{args.baseXyz}, isatty(fileno(stderr)) != 0, wall0};
  if (args.combined) runCombined(run);
  else runStreamed(run);

  int exitCode = output->finish(run.exitCode);
  if (!args.quiet && run.tty) std::fprintf(stderr, "\r%90s\r", "");
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  printSummary(args, cfg, solver, *in.rover, *in.base, counts, run.basePos, wall);
  const long solved = counts.fixed + counts.floats + counts.singles;
  if (solved == 0 && exitCode == 0) exitCode = 3;
  return exitCode;
}

}  // namespace gvins::rtkapp
