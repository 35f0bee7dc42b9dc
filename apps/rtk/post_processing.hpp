// The post-processing run of gvins-rtk: rover and base files (RINEX, UBX, RTCM 3 base), solved
// epoch by epoch as they are read (streamed) or, with --combined, by a forward and a backward
// pass whose solutions are combined per epoch (combined_run.cpp).
#pragma once

#include <chrono>
#include <cstddef>
#include <string>

#include "gvins/base/observation.hpp"
#include "gvins/base/rinex_obs_header.hpp"
#include "gvins/ephemeris/ephemeris_store.hpp"
#include "gvins/gnss/base_reader.hpp"
#include "gvins/gnss/rtk.hpp"
#include "gvins/gnss/rtk_config.hpp"
#include "gvins/gnss/spp_config.hpp"
#include "rtk_options.hpp"
#include "rtk_output.hpp"
#include "rtk_summary.hpp"

namespace gvins::rtkapp {

/// Runs the post-processing of `args` (navigation data already in `nav`; UBX and RTCM inputs add
/// theirs as they are read), writes the outputs and prints the summary. `wall0` is the start of
/// the run. Returns the exit status: 0, 1 (input or output error), 3 (no solution at all).
int runPostProcessing(const RtkOptions& args, const RtkConfig& cfg, const SppConfig& sppCfg, EphemerisStore& nav,
                      std::chrono::steady_clock::time_point wall0);

/// The state of one post-processing run shared by its streamed and combined forms.
struct PostRun {
  const RtkOptions& args;
  const RtkConfig& cfg;
  const SppConfig& sppCfg;
  EphemerisStore& nav;
  BaseReader& rover;
  BaseReader& base;
  const RinexObsHeader& hdr;  ///< the rover's RINEX header (empty for UBX)
  PhaseAlignments roverAlignment;
  RtkSolver& solver;
  RtkOutput& output;
  RunCounts& counts;
  ObsEpoch roverEpoch;  ///< the next rover epoch, if haveRover
  bool haveRover = false;
  BaseLocation basePos;
  bool tty = false;  ///< stderr is a terminal: progress lines overwrite each other
  std::chrono::steady_clock::time_point lastProgress;
  int exitCode = 0;
  std::size_t roverWarned = 0, baseWarned = 0;  ///< Doppler warnings printed so far

  /// Counts a solution and writes it if valid.
  void consume(const RtkSolution& sol);
  /// Prints the Doppler verdicts other than "consistent" (doppler_consistency.hpp) made since the
  /// last call.
  void showDopplerWarnings();
  /// Without --base-xyz: takes the base's own position (RINEX header + antenna delta, RTCM
  /// 1005/1006; UBX gives none) once it is known. True when it was taken just now.
  bool takeBaseAntennaPosition();
  /// "gvins-rtk: error: ..." and exit status 1.
  void fail(const std::string& message);
};

/// Combined mode: every rover and base epoch in memory, a forward and a backward pass, and per
/// epoch the combination of the two (gvins/gnss/rtk_combination.hpp).
void runCombined(PostRun& run);

}  // namespace gvins::rtkapp
