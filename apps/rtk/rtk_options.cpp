#include "rtk_options.hpp"

#include <cstdio>
#include <stdexcept>

#include "gvins/base/command_line.hpp"
#include "gvins/base/constants.hpp"
#include "gvins/base/parse_error.hpp"
#include "gvins/gnss/base_reader.hpp"

namespace gvins::rtkapp {
namespace {

const char* kUsage =
    "usage: gvins-rtk [options] -o OUT.pos ROVER_OBS|ROVER_UBX BASE_OBS|BASE_RTCM|BASE_UBX [NAV...]\n"
    "\n"
    "Relative positioning (RTK) with integer ambiguity resolution. ROVER_OBS is RINEX observation\n"
    "data (2.10/2.11, 3.0x, 4.0x; plain or .gz) or a u-blox UBX log (RXM-RAWX); the base is RINEX,\n"
    "a binary RTCM 3 log (MSM or legacy observations, 1005/1006 position, ephemerides) or UBX, all\n"
    "told apart by content. NAV are RINEX navigation files (merged); required unless the rover or\n"
    "the base is a UBX log (whose RXM-SFRBX ephemerides are used as they arrive). Writes one RTKLIB-style .pos row per epoch with a solution\n"
    "(Q=1 fixed, 2 float, 5 single-point fallback), prints progress and a summary to stderr.\n"
    "\n"
    "  -o FILE               output .pos file ('-' for stdout); required\n"
    "  --nmea FILE           also NMEA 0183 GGA+RMC sentences of the solutions (docs/nmea.md)\n"
    "  --kml FILE            also a KML track of the solutions\n"
    "  --config F.yaml       options from the 'rtk:' (and 'spp:') sections of a YAML file;\n"
    "                        command-line options override it\n"
    "  --base-xyz X,Y,Z      base antenna reference point, ECEF (m)\n"
    "  --base-llh LAT,LON,H  the same as latitude, longitude (deg), ellipsoidal height (m)\n"
    "                        (default: RINEX header position + antenna delta, or RTCM 1005/1006)\n"
    "  --mode M              static | kinematic (default kinematic)\n"
    "  --dynamics D          random-walk | constant-velocity (kinematic; default random-walk)\n"
    "  --armode M            off | continuous | instantaneous | fix-and-hold (default continuous)\n"
    "  -c, --combined        post-processing: forward and backward passes combined per epoch\n"
    "                        (any --armode; reads all epochs into memory; docs/rtk.md)\n"
    "  --ratio R             ratio-test threshold (default 3)\n"
    "  --validation V        fixed-failure-rate | ratio | success-rate | ratio+success-rate\n"
    "                        (default fixed-failure-rate: the ratio's critical value bounds the\n"
    "                        probability of a wrong fix by --max-failure-rate)\n"
    "  --max-failure-rate P  bound on the wrong-fix probability (default 0.001)\n"
    "  --no-partial          no partial ambiguity resolution\n"
    "  --systems GRECJ       systems used (default GRECJ)\n"
    "  --ar-systems GECJ     systems whose ambiguities are fixed (default GECJ: GLONASS float)\n"
    "  --freq N              bands per system, 1-3 (default 2)\n"
    "  --elmask DEG          elevation mask, degrees (default 15); also the AR mask\n"
    "  --max-age S           oldest base data used, s (default 30)\n"
    "  --no-interpolation    do not interpolate the base between its epochs\n"
    "  --xyz                 ECEF x/y/z columns instead of latitude/longitude/height\n"
    "  --no-velocity         no velocity columns\n"
    "  --time-decimals N     decimals of the time column (default 3)\n"
    "  --truth X,Y,Z         true rover position (ECEF, m): accuracy tables of the fixed and of\n"
    "                        all RTK solutions\n"
    "  --truth-llh LAT,LON,H the same as latitude, longitude (deg), ellipsoidal height (m)\n"
    "  --strict              stop at the first malformed epoch (default: skip it and count it)\n"
    "  -q, --quiet           no progress line\n"
    "\n"
    "Live mode (docs/rtk.md): gvins-rtk --rover-stream PATH --base-stream PATH [-o OUT] [NAV...]\n"
    "  --rover-stream PATH   rover UBX or RTCM 3 stream: file://F, tcpcli://HOST:PORT, tcpsvr://:PORT,\n"
    "                        serial://DEV:BAUD, ntrip://USER:PASS@HOST:PORT/MOUNT, - (stdin)\n"
    "  --base-stream PATH    base RTCM 3 (or UBX) stream, same paths; NTRIP gets the rover's GGA\n"
    "  --base-wait S         wait up to S s for the base epoch after each rover epoch, as\n"
    "                        post-processing pairs them (default 0: solve at once)\n"
    "  --max-outage S        end a stream after S s without a connection (default 0: retry for ever)\n"
    "  --latency-log F.csv   per-epoch latency and base age\n"
    "  -o OUT, --nmea OUT    in live mode also tcpsvr://[ADDR]:PORT (solutions served to every TCP\n"
    "                        client connected) or tcpcli://HOST:PORT (sent to a TCP server)\n"
    "  -h, --help            this text\n";

}  // namespace

RtkOptions parseRtkOptions(int argc, char** argv) {
  RtkOptions a;
  CommandLine cl("gvins-rtk", kUsage, argc, argv);
  while (cl.next()) {
    if (cl.is("-o")) a.out = cl.value();
    else if (cl.is("--rover-stream")) a.roverStream = cl.value();
    else if (cl.is("--base-stream")) a.baseStream = cl.value();
    else if (cl.is("--latency-log")) a.latencyLog = cl.value();
    else if (cl.is("--base-wait")) a.baseWait = cl.number(0.0, 3600.0, "s");
    else if (cl.is("--max-outage")) a.maxOutage = cl.number(0.0, 1e9, "s");
    else if (cl.is("--nmea")) a.nmea = cl.value();
    else if (cl.is("--kml")) a.kml = cl.value();
    else if (cl.is("--config")) a.config = cl.value();
    // A base station near the Earth's surface (base/option_values.hpp).
    else if (cl.is("--base-xyz")) a.baseXyz = cl.stationEcef();
    else if (cl.is("--base-llh")) a.baseXyz = cl.stationLlh();
    else if (cl.is("--mode")) a.mode = cl.choice(kRtkModeNames);
    else if (cl.is("--dynamics")) a.dynamics = cl.choice(kRtkDynamicsNames);
    else if (cl.is("--armode")) a.armode = cl.choice(kAmbiguityModeNames);
    else if (cl.is("--ratio")) a.ratio = cl.number(1.0, 1000.0);
    else if (cl.is("--max-failure-rate")) a.maxFailureRate = cl.number(1e-9, 0.5);
    else if (cl.is("--validation")) a.validation = cl.choice(kAmbiguityValidationNames);
    else if (cl.is("--combined", "-c")) a.combined = true;
    else if (cl.is("--no-partial")) a.noPartial = true;
    else if (cl.is("--systems")) a.systems = cl.value();
    else if (cl.is("--ar-systems")) a.arSystems = cl.value();
    else if (cl.is("--freq")) a.freq = static_cast<int>(cl.integer(1, 3));
    else if (cl.is("--elmask")) a.elmask = cl.number(-10.0, 90.0, "deg");
    else if (cl.is("--max-age")) a.maxAge = cl.number(0.0, 1e9, "s");
    else if (cl.is("--no-interpolation")) a.noInterpolation = true;
    else if (cl.is("--xyz")) a.xyz = true;
    else if (cl.is("--no-velocity")) a.noVelocity = true;
    else if (cl.is("--time-decimals")) a.timeDecimals = static_cast<int>(cl.integer(0, 9));
    else if (cl.is("--truth")) a.truth = cl.stationEcef();
    else if (cl.is("--truth-llh")) a.truth = cl.stationLlh();
    else if (cl.is("--strict")) a.strict = true;
    else if (cl.is("-q", "--quiet")) a.quiet = true;
    else a.inputs.push_back(cl.operand());
  }
  if (!a.roverStream.empty() || !a.baseStream.empty()) {
    if (a.roverStream.empty() || a.baseStream.empty()) cl.error("live mode needs --rover-stream and --base-stream");
    if (a.out.empty()) a.out = "-";
    return a;  // the inputs are navigation files
  }
  if (a.out.empty()) cl.error("no output file (-o OUT.pos)");
  const bool ubxInput = a.inputs.size() == 2 && (BaseReader::detect(a.inputs[0]) == BaseFormat::Ubx ||
                                                 BaseReader::detect(a.inputs[1]) == BaseFormat::Ubx);
  if (a.inputs.size() < 3 && !ubxInput) {
    cl.error("need a rover observation file, base data and at least one navigation file (not needed with UBX)");
  }
  return a;
}

void printRtkError(const std::string& message) { std::fprintf(stderr, "gvins-rtk: error: %s\n", message.c_str()); }

int applyRtkOptions(const RtkOptions& args, RtkConfig& cfg, SppConfig& sppCfg) {
  try {
    if (!args.config.empty()) {
      cfg = loadRtkConfig(args.config, cfg);
      sppCfg = loadSppConfig(args.config, sppCfg);
    }
  } catch (const ParseError& e) {
    printRtkError(e.what());
    return 2;
  }
  if (args.mode) cfg.mode = *args.mode;
  if (args.dynamics) cfg.dynamics = *args.dynamics;
  if (args.armode) cfg.ambiguityMode = *args.armode;
  if (args.validation) cfg.ar.validation = *args.validation;
  if (args.ratio) cfg.ar.ratioThreshold = *args.ratio;
  if (args.maxFailureRate) cfg.ar.maxFailureRate = *args.maxFailureRate;
  if (args.noPartial) cfg.ar.partial = false;
  try {
    if (args.systems) {
      cfg.systems = parseSystemLetters(*args.systems);
      sppCfg.systems = cfg.systems;
    }
    if (args.arSystems) cfg.arSystems = parseSystemLetters(*args.arSystems);
  } catch (const std::invalid_argument& e) {
    usageError("gvins-rtk", std::string("--systems/--ar-systems: ") + e.what());
  }
  if (args.freq) cfg.frequencies = *args.freq;
  if (args.elmask) {
    cfg.elevationMask = *args.elmask * constants::kDegToRad;
    cfg.arElevationMask = cfg.elevationMask;
    sppCfg.elevationMask = cfg.elevationMask;
  }
  if (args.maxAge) cfg.maxAge = *args.maxAge;
  if (args.noInterpolation) cfg.interpolateBase = false;
  return 0;
}

}  // namespace gvins::rtkapp
