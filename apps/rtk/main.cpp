// gvins-rtk: relative positioning (RTK, static or kinematic) with integer ambiguity resolution
// from rover RINEX observations, base RINEX observations or an RTCM 3 log, and broadcast
// navigation files; writes an RTKLIB-compatible .pos file. Options: rtk_options.hpp;
// post-processing: post_processing.hpp; live mode: live.hpp.
#include <chrono>
#include <cstddef>

#include "gvins/base/command_line.hpp"
#include "gvins/base/heap_pages.hpp"
#include "gvins/base/parse_error.hpp"
#include "gvins/ephemeris/ephemeris_store.hpp"
#include "gvins/ephemeris/rinex_nav.hpp"
#include "live.hpp"
#include "post_processing.hpp"
#include "rtk_options.hpp"

namespace {

using namespace gvins;

/// The live mode (live.cpp) with the options of the command line.
int runLive(const rtkapp::RtkOptions& a, const RtkConfig& cfg, const SppConfig& sppCfg, EphemerisStore& nav) {
  rtklive::LiveOptions o;
  o.rover = a.roverStream;
  o.base = a.baseStream;
  o.out = a.out;
  o.nmea = a.nmea;
  o.latencyLog = a.latencyLog;
  o.baseWait = a.baseWait;
  o.maxOutage = a.maxOutage;
  o.baseXyz = a.baseXyz;
  o.strict = a.strict;
  o.quiet = a.quiet;
  o.pos.coordinates = a.xyz ? PosCoordinates::Xyz : PosCoordinates::Llh;
  o.pos.velocity = !a.noVelocity;
  o.pos.timeDecimals = a.timeDecimals;
  o.pos.program = "SRI-GVINS gvins-rtk (live)";
  o.pos.headerFields.emplace_back("rover", a.roverStream);
  o.pos.headerFields.emplace_back("base", a.baseStream);
  if (!a.kml.empty()) usageError("gvins-rtk", "--kml is not available in live mode");
  return rtklive::runLive(o, cfg, sppCfg, nav);
}

}  // namespace

int main(int argc, char** argv) {
  keepHeapPages();
  const rtkapp::RtkOptions args = rtkapp::parseRtkOptions(argc, argv);
  const auto wall0 = std::chrono::steady_clock::now();

  RtkConfig cfg;
  SppConfig sppCfg;
  if (const int rc = rtkapp::applyRtkOptions(args, cfg, sppCfg)) return rc;

  // Navigation data: the operands after rover and base (all of them in live mode).
  EphemerisStore nav;
  try {
    for (std::size_t i = args.live() ? 0 : 2; i < args.inputs.size(); ++i) nav.add(readRinexNav(args.inputs[i]));
  } catch (const ParseError& e) {
    rtkapp::printRtkError(e.what());
    return 1;
  }
  if (args.live()) return runLive(args, cfg, sppCfg, nav);
  return rtkapp::runPostProcessing(args, cfg, sppCfg, nav, wall0);
}
