// gvins-rtk: relative positioning (RTK, static or kinematic) with integer ambiguity resolution
// from rover RINEX observations, base RINEX observations or an RTCM 3 log, and broadcast
// navigation files; writes an RTKLIB-compatible .pos file.
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "gvins/base/atomic_output_file.hpp"
#include "gvins/base/command_line.hpp"
#include "gvins/base/constants.hpp"
#include "gvins/base/geodetic.hpp"
#include "gvins/base/heap_pages.hpp"
#include "gvins/base/parse_error.hpp"
#include "gvins/base/rinex_obs_reader.hpp"
#include "gvins/ephemeris/ephemeris_store.hpp"
#include "gvins/ephemeris/rinex_nav.hpp"
#include "gvins/gnss/accuracy_statistics.hpp"
#include "gvins/gnss/base_reader.hpp"
#include "gvins/gnss/pos_writer.hpp"
#include "gvins/gnss/solution_outputs.hpp"
#include "gvins/gnss/rtk.hpp"
#include "gvins/gnss/rtk_combination.hpp"
#include "gvins/gnss/rtk_config.hpp"
#include "gvins/gnss/rtk_pass.hpp"
#include "gvins/gnss/spp_config.hpp"
#include "live.hpp"

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

struct Args {
  std::string config, out;
  std::string nmea, kml;
  std::string roverStream, baseStream, latencyLog;
  double baseWait = 0.0, maxOutage = 0.0;
  std::vector<std::string> inputs;
  std::optional<Eigen::Vector3d> baseXyz, truth;
  std::optional<gvins::RtkMode> mode;
  std::optional<gvins::RtkDynamics> dynamics;
  std::optional<gvins::AmbiguityMode> armode;
  std::optional<gvins::AmbiguityValidation> validation;
  std::optional<std::string> systems, arSystems;
  std::optional<double> ratio, elmask, maxAge, maxFailureRate;
  std::optional<int> freq;
  bool combined = false;
  bool noPartial = false, noInterpolation = false, xyz = false, noVelocity = false, strict = false, quiet = false;
  int timeDecimals = 3;
};

[[noreturn]] void usageError(const std::string& msg) { gvins::usageError("gvins-rtk", msg); }

Args parseArgs(int argc, char** argv) {
  Args a;
  gvins::CommandLine cl("gvins-rtk", kUsage, argc, argv);
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
    else if (cl.is("--mode")) a.mode = cl.choice(gvins::kRtkModeNames);
    else if (cl.is("--dynamics")) a.dynamics = cl.choice(gvins::kRtkDynamicsNames);
    else if (cl.is("--armode")) a.armode = cl.choice(gvins::kAmbiguityModeNames);
    else if (cl.is("--ratio")) a.ratio = cl.number(1.0, 1000.0);
    else if (cl.is("--max-failure-rate")) a.maxFailureRate = cl.number(1e-9, 0.5);
    else if (cl.is("--validation")) a.validation = cl.choice(gvins::kAmbiguityValidationNames);
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
  const bool ubxInput = a.inputs.size() == 2 && (gvins::BaseReader::detect(a.inputs[0]) == gvins::BaseFormat::Ubx ||
                                                 gvins::BaseReader::detect(a.inputs[1]) == gvins::BaseFormat::Ubx);
  if (a.inputs.size() < 3 && !ubxInput) {
    cl.error("need a rover observation file, base data and at least one navigation file (not needed with UBX)");
  }
  return a;
}

std::string systemsText(const std::array<bool, gvins::kNumSystems>& s) {
  std::string t;
  for (int i = 0; i < gvins::kNumSystems; ++i) {
    if (s[static_cast<std::size_t>(i)]) t += gvins::systemLetter(static_cast<gvins::System>(i));
  }
  return t.empty() ? "-" : t;
}

bool live(const Args& a) { return !a.roverStream.empty(); }

/// The live mode (live.cpp) with the options of the command line.
int runLive(const Args& a, const gvins::RtkConfig& cfg, const gvins::SppConfig& sppCfg, gvins::EphemerisStore& nav) {
  gvins::rtklive::LiveOptions o;
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
  o.pos.coordinates = a.xyz ? gvins::PosCoordinates::Xyz : gvins::PosCoordinates::Llh;
  o.pos.velocity = !a.noVelocity;
  o.pos.timeDecimals = a.timeDecimals;
  o.pos.program = "SRI-GVINS gvins-rtk (live)";
  o.pos.headerFields.emplace_back("rover", a.roverStream);
  o.pos.headerFields.emplace_back("base", a.baseStream);
  if (!a.kml.empty()) usageError("--kml is not available in live mode");
  return gvins::rtklive::runLive(o, cfg, sppCfg, nav);
}

void printError(const gvins::ParseError& e) { std::fprintf(stderr, "gvins-rtk: error: %s\n", e.what()); }

/// Configuration: defaults, YAML, command line; 0 or the exit status of a bad configuration file.
int configuration(const Args& args, gvins::RtkConfig& cfg, gvins::SppConfig& sppCfg) {
  using namespace gvins;
  try {
    if (!args.config.empty()) {
      cfg = loadRtkConfig(args.config, cfg);
      sppCfg = loadSppConfig(args.config, sppCfg);
    }
  } catch (const ParseError& e) {
    printError(e);
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
    usageError(std::string("--systems/--ar-systems: ") + e.what());
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

double pct(long a, long b) { return b > 0 ? 100.0 * static_cast<double>(a) / static_cast<double>(b) : 0.0; }

/// Counts of a run for the summary.
struct RunCounts {
  long epochs = 0, fixed = 0, floats = 0, singles = 0, none = 0, partial = 0, held = 0;
  std::map<gvins::RtkIssue, long> issues;
  std::map<gvins::ArStatus, long> arStatus;
  gvins::QuantileHistogram ratios;
  double ratioMin = 1e300, ratioMax = 0.0, ratioSum = 0.0;
  long ratioCount = 0;
  double satSum = 0.0, ageMax = 0.0;
  long wrongFixes = 0;  ///< fixed epochs farther than kWrongFix from --truth
  long baseEpochs = 0;
  gvins::CombinationCounts combination;
  double passSeconds[2] = {0.0, 0.0};
};

/// A fixed epoch farther than this from --truth counts as a wrong fix (3-D, m).
constexpr double kWrongFix = 0.10;

/// The summary on stderr.
void printSummary(const Args& args, const gvins::RtkConfig& cfg, gvins::RtkSolver& solver, gvins::BaseReader& rover,
                  gvins::BaseReader& base, const RunCounts& counts, const std::optional<Eigen::Vector3d>& basePosUsed,
                  const std::string& baseSource, double wall, const std::optional<gvins::AccuracyStatistics>& fixStats,
                  const std::optional<gvins::AccuracyStatistics>& rtkStats) {
  using namespace gvins;
  const long epochs = counts.epochs, fixed = counts.fixed, floats = counts.floats, singles = counts.singles,
             none = counts.none, partial = counts.partial, held = counts.held;
  const auto& issues = counts.issues;
  const auto& arStatus = counts.arStatus;
  const QuantileHistogram& ratios = counts.ratios;
  const double ratioMin = counts.ratioMin, ratioMax = counts.ratioMax, ratioSum = counts.ratioSum;
  const long ratioCount = counts.ratioCount;
  const double satSum = counts.satSum, ageMax = counts.ageMax;
  const long wrongFixes = counts.wrongFixes, baseEpochs = counts.baseEpochs;
  const CombinationCounts& combination = counts.combination;
  const double* passSeconds = counts.passSeconds;
  const long solved = fixed + floats + singles;
  std::fprintf(stderr, "gvins-rtk summary (%s, base %s)\n", args.inputs[0].c_str(), base.describe().c_str());
  std::fprintf(stderr, "  mode                   %s, %s, AR %s, ratio %.1f\n", toString(cfg.mode),
               cfg.mode == RtkMode::Kinematic ? toString(cfg.dynamics) : "static position", toString(cfg.ambiguityMode),
               cfg.ar.ratioThreshold);
  if (basePosUsed) {
    std::fprintf(stderr, "  base position          %.4f %.4f %.4f (%s)\n", (*basePosUsed)[0], (*basePosUsed)[1], (*basePosUsed)[2],
                 baseSource.c_str());
  } else {
    std::fprintf(stderr, "  base position          unknown (no header position, 1005/1006 or --base-xyz)\n");
  }
  std::fprintf(stderr, "  rover epochs           %8ld\n", epochs);
  std::fprintf(stderr, "  base epochs read       %8ld\n", baseEpochs);
  std::fprintf(stderr, "  fixed   (Q=1)          %8ld  %6.2f %%%s\n", fixed, pct(fixed, epochs),
               partial ? (" (" + std::to_string(partial) + " partial)").c_str() : "");
  std::fprintf(stderr, "  float   (Q=2)          %8ld  %6.2f %%\n", floats, pct(floats, epochs));
  std::fprintf(stderr, "  single  (Q=5)          %8ld  %6.2f %%\n", singles, pct(singles, epochs));
  std::fprintf(stderr, "  no solution            %8ld  %6.2f %%\n", none, pct(none, epochs));
  std::fprintf(stderr, "  fix rate               %8.2f %% of epochs, %.2f %% of RTK epochs\n", pct(fixed, epochs),
               pct(fixed, fixed + floats));
  if (ratioCount) {
    std::fprintf(stderr, "  ratio                  min %.2f  median %.2f  mean %.2f  max %.1f  (%ld epochs)\n", ratioMin,
                 ratios.quantile(0.5), ratioSum / ratioCount, ratioMax, ratioCount);
  }
  std::fprintf(stderr, "  mean satellites        %8.1f   max age %.1f s\n", solved ? satSum / solved : 0.0, ageMax);
  if (held) std::fprintf(stderr, "  fix-and-hold updates   %8ld\n", held);
  if (args.combined) {
    const CombinationCounts& k = combination;
    std::fprintf(stderr, "  combined               forward %lld fixed (%.1f s), backward %lld fixed (%.1f s)\n",
                 static_cast<long long>(k.forwardFixed), passSeconds[0], static_cast<long long>(k.backwardFixed),
                 passSeconds[1]);
    std::fprintf(stderr, "  combined fixes         %8lld  (%lld both, %lld forward only, %lld backward only)\n",
                 static_cast<long long>(k.combinedFixed), static_cast<long long>(k.bothFixed),
                 static_cast<long long>(k.forwardOnlyFixed), static_cast<long long>(k.backwardOnlyFixed));
    std::fprintf(stderr, "  combined to float      %8lld disagreements (both fixed), %lld fixes inconsistent with the other float\n",
                 static_cast<long long>(k.disagreements), static_cast<long long>(k.fixRejected));
  }
  for (const auto& [i, n] : issues) std::fprintf(stderr, "  no RTK: %-30s %6ld\n", toString(i), n);
  for (const auto& [s, n] : arStatus) {
    if (s != ArStatus::Fixed && s != ArStatus::PartialFixed) std::fprintf(stderr, "  AR: %-34s %6ld\n", toString(s), n);
  }
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
  if (fixStats) {
    std::fprintf(stderr, "  wrong fixes            %8ld of %ld fixed epochs more than %.2f m from the truth\n", wrongFixes, fixed,
                 kWrongFix);
  }
  if (fixStats && fixStats->position().count > 0) {
    std::fputs("  fixed solutions vs truth:\n", stderr);
    std::fputs(fixStats->table().c_str(), stderr);
  }
  if (rtkStats && rtkStats->position().count > 0) {
    std::fputs("  fixed and float solutions vs truth:\n", stderr);
    std::fputs(rtkStats->table().c_str(), stderr);
  }
}


}  // namespace

int main(int argc, char** argv) {
  using namespace gvins;
  keepHeapPages();
  const Args args = parseArgs(argc, argv);
  const auto wall0 = std::chrono::steady_clock::now();

  RtkConfig cfg;
  SppConfig sppCfg;
  if (const int rc = configuration(args, cfg, sppCfg)) return rc;

  // Navigation data.
  EphemerisStore nav;
  try {
    for (std::size_t i = live(args) ? 0 : 2; i < args.inputs.size(); ++i) nav.add(readRinexNav(args.inputs[i]));
  } catch (const ParseError& e) {
    printError(e);
    return 1;
  }

  if (live(args)) return runLive(args, cfg, sppCfg, nav);

  // Rover and base: RINEX, UBX (rover and base) or RTCM 3 (base), told apart by content
  // (BaseReader). UBX and RTCM add the ephemerides they carry to `nav` as they are read.
  std::unique_ptr<BaseReader> rover;
  std::unique_ptr<BaseReader> base;
  ObsEpoch roverEpoch;
  bool haveRover = false;
  try {
    if (BaseReader::detect(args.inputs[0]) == BaseFormat::Rtcm) {
      std::fprintf(stderr, "gvins-rtk: error: rover %s is an RTCM 3 log; convert it with gvins-rtcm to-rinex --date first\n",
                   args.inputs[0].c_str());
      return 1;
    }
    rover = BaseReader::open(args.inputs[0], GpsTime{}, &nav, !args.strict);
    haveRover = rover->next(roverEpoch);
    const GpsTime ref = haveRover ? roverEpoch.time
                                  : (rover->rinexHeader() ? rover->rinexHeader()->firstObs.value_or(GpsTime()) : GpsTime());
    base = BaseReader::open(args.inputs[1], ref, &nav, !args.strict);
  } catch (const ParseError& e) {
    printError(e);
    return 1;
  }
  if (nav.size() == 0 && base->format() == BaseFormat::Rinex && rover->format() == BaseFormat::Rinex) {
    std::fprintf(stderr, "gvins-rtk: error: no usable ephemeris in the navigation files\n");
    return 1;
  }
  static const RinexObsHeader kNoHeader;
  const RinexObsHeader& hdr = rover->rinexHeader() ? *rover->rinexHeader() : kNoHeader;

  RtkSolver solver(nav, cfg, sppCfg);
  solver.setRoverGlonassChannels(rover->glonassChannels());
  const PhaseAlignments roverAlignment = rover->phaseAlignment();
  if (hdr.station.approxPosition && hdr.station.approxPosition->norm() > 1e6) {
    solver.setRoverInitialPosition(*hdr.station.approxPosition);
  }
  std::string baseSource = "command line";
  if (args.baseXyz) solver.setBasePosition(*args.baseXyz);

  // The .pos file is written under a temporary name and renamed only when the run succeeds: a
  // failed run leaves no file that looks valid (and an older file of that name intact).
  std::optional<OutputTarget> output;
  std::optional<SolutionOutputs> side;
  try {
    output.emplace(args.out);
    side.emplace(args.nmea, args.kml, "gvins-rtk " + args.inputs[0]);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "gvins-rtk: error: %s\n", e.what());
    return 1;
  }
  std::ostream* out = &output->stream();
  PosWriterOptions popt;
  popt.coordinates = args.xyz ? PosCoordinates::Xyz : PosCoordinates::Llh;
  popt.velocity = !args.noVelocity;
  popt.timeDecimals = args.timeDecimals;
  popt.program = "SRI-GVINS gvins-rtk";
  for (const auto& f : args.inputs) popt.headerFields.emplace_back("inp file", f);
  popt.headerFields.emplace_back("pos mode", std::string(toString(cfg.mode)) + " (" +
                                                 (cfg.mode == RtkMode::Kinematic ? toString(cfg.dynamics) : "fixed position") + ")");
  char buf[200];
  std::snprintf(buf, sizeof buf, "%d", cfg.frequencies);
  popt.headerFields.emplace_back("freqs", buf);
  std::snprintf(buf, sizeof buf, "%.1f deg", cfg.elevationMask * constants::kRadToDeg);
  popt.headerFields.emplace_back("elev mask", buf);
  popt.headerFields.emplace_back("navi sys", systemsText(cfg.systems));
  std::snprintf(buf, sizeof buf, "%s, systems %s, ratio %.1f, %s validation, failure rate %g%s", toString(cfg.ambiguityMode),
                systemsText(cfg.arSystems).c_str(), cfg.ar.ratioThreshold, toString(cfg.ar.validation),
                cfg.ar.maxFailureRate, cfg.ar.partial ? ", partial" : "");
  popt.headerFields.emplace_back("amb res", buf);
  if (args.combined) popt.headerFields.emplace_back("solution", "combined (forward + backward)");
  // The base position line is added once known (before the first row is written).
  std::unique_ptr<PosWriter> writer;

  std::optional<AccuracyStatistics> fixStats, rtkStats;
  RunCounts counts;
  long& wrongFixes = counts.wrongFixes;
  if (args.truth) {
    fixStats.emplace(*args.truth);
    rtkStats.emplace(*args.truth);
  }

  // Counters.
  long &epochs = counts.epochs, &fixed = counts.fixed, &floats = counts.floats, &singles = counts.singles,
       &none = counts.none, &partial = counts.partial, &held = counts.held;
  std::map<RtkIssue, long>& issues = counts.issues;
  std::map<ArStatus, long>& arStatus = counts.arStatus;
  QuantileHistogram& ratios = counts.ratios;
  double &ratioMin = counts.ratioMin, &ratioMax = counts.ratioMax, &ratioSum = counts.ratioSum;
  long& ratioCount = counts.ratioCount;
  double &satSum = counts.satSum, &ageMax = counts.ageMax;
  int exitCode = 0;
  const bool tty = isatty(fileno(stderr));
  auto lastProgress = wall0;
  const double span = hdr.firstObs && hdr.lastObs ? *hdr.lastObs - *hdr.firstObs : 0.0;
  std::optional<GpsTime> first;
  // Doppler verdicts other than "consistent" (doppler_consistency.hpp), printed when made.
  std::size_t roverWarned = 0, baseWarned = 0;
  auto showDopplerWarnings = [&](const DopplerConsistency& d, std::size_t& shown) {
    for (; shown < d.warnings().size(); ++shown) {
      std::fprintf(stderr, "%sgvins-rtk: warning: %s\n", tty ? "\r" : "", d.warnings()[shown].c_str());
    }
  };

  ObsEpoch baseEpoch;
  bool baseDone = false, basePending = false;
  std::optional<GpsTime> lastBaseTime;
  long& baseEpochs = counts.baseEpochs;
  std::optional<Eigen::Vector3d> basePosUsed = args.baseXyz;

  // Counts and writes one solution (streamed, or the combined solution of an epoch).
  auto consume = [&](const RtkSolution& sol) {
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
    if (sol.valid()) {
      if (!writer) {
        if (basePosUsed) {
          std::snprintf(buf, sizeof buf, "%.4f %.4f %.4f (%s)", (*basePosUsed)[0], (*basePosUsed)[1], (*basePosUsed)[2],
                        baseSource.c_str());
          popt.headerFields.emplace_back("ref pos", buf);
        }
        writer = std::make_unique<PosWriter>(*out, popt);
      }
      writer->write(sol.toPositionSolution());
      if (side) side->add(sol.toPositionSolution(), NmeaExtras{sol.hdop, std::nullopt});
      satSum += sol.numSatellites;
      if (sol.quality != SolutionQuality::Single) ageMax = std::max(ageMax, sol.age);
      if (fixStats && sol.quality == SolutionQuality::Fix) {
        fixStats->addPosition(sol.position);
        if ((sol.position - *args.truth).norm() > kWrongFix) ++wrongFixes;
      }
      if (rtkStats && sol.quality != SolutionQuality::Single) rtkStats->addPosition(sol.position);
    }
  };

  // Combined mode (post-processing): every rover and base epoch in memory, a forward and a
  // backward pass, and per epoch the combination of the two (rtk_combination.hpp).
  std::optional<RtkSolver> backward;
  CombinationCounts& combination = counts.combination;
  double (&passSeconds)[2] = counts.passSeconds;
  if (args.combined) {
    std::vector<ObsEpoch> rovers, bases;
    try {
      while (haveRover) {
        rovers.push_back(roverEpoch);
        haveRover = rover->next(roverEpoch);
      }
      while (base->next(baseEpoch)) bases.push_back(baseEpoch);
    } catch (const ParseError& e) {
      printError(e);
      exitCode = 1;
    }
    baseEpochs = static_cast<long>(bases.size());
    if (!args.baseXyz) {
      if (auto p = base->antennaPosition()) {
        basePosUsed = p;
        baseSource = base->format() == BaseFormat::Rtcm ? "RTCM 1005/1006" : "RINEX header";
      }
    }
    backward.emplace(nav, cfg, sppCfg);
    for (RtkSolver* s : {&solver, &*backward}) {
      s->setRoverGlonassChannels(hdr.glonassChannels);
      if (hdr.station.approxPosition && hdr.station.approxPosition->norm() > 1e6) {
        s->setRoverInitialPosition(*hdr.station.approxPosition);
      }
      if (basePosUsed) s->setBasePosition(*basePosUsed);
      s->setBaseGlonassChannels(base->glonassChannels());
      s->setPhaseAlignment(roverAlignment, base->phaseAlignment());
    }
    std::vector<RtkSolution> passes[2];
    for (int p = 0; p < 2; ++p) {
      const TimeDirection dir = p == 0 ? TimeDirection::Forward : TimeDirection::Backward;
      long passFixed = 0;
      const auto t0 = std::chrono::steady_clock::now();
      passes[p] = runRtkPass(p == 0 ? solver : *backward, rovers, bases, dir,
                             [&](std::size_t done, std::size_t total, const RtkSolution& sol) {
                               if (sol.quality == SolutionQuality::Fix) ++passFixed;
                               if (args.quiet) return;
                               const auto now = std::chrono::steady_clock::now();
                               if (done < total && now - lastProgress < std::chrono::milliseconds(tty ? 200 : 5000)) return;
                               lastProgress = now;
                               std::fprintf(stderr, "%s%s pass: %s epoch %zu/%zu fix %ld%s", tty ? "\r" : "", toString(dir),
                                            sol.time.toString(1).c_str(), done, total, passFixed, tty ? "   " : "\n");
                               std::fflush(stderr);
                             });
      passSeconds[p] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      if (!args.quiet && tty) std::fputc('\n', stderr);
    }
    showDopplerWarnings(solver.roverDoppler(), roverWarned);
    showDopplerWarnings(solver.base().doppler(), baseWarned);
    for (std::size_t i = 0; i < rovers.size(); ++i) {
      Combination how;
      const RtkSolution sol = combineSolutions(passes[0][i], passes[1][i], CombinationOptions{}, &how);
      combination.add(passes[0][i], passes[1][i], how);
      ++epochs;
      if (!first) first = rovers[i].time;
      consume(sol);
    }
  }

  while (!args.combined && haveRover) {
    ++epochs;
    if (!first) first = roverEpoch.time;
    // Feed base epochs up to the rover time and the first one after it (for interpolation),
    // never more: the base buffer only keeps what alignment can use.
    try {
      while (!baseDone && !(lastBaseTime && *lastBaseTime - roverEpoch.time > BaseStation::kSyncTolerance)) {
        if (!basePending) {
          if (!base->next(baseEpoch)) {
            baseDone = true;
            break;
          }
          basePending = true;
          ++baseEpochs;
        }
        if (!args.baseXyz && !basePosUsed) {
          if (auto p = base->antennaPosition()) {
            solver.setBasePosition(*p);
            basePosUsed = p;
            baseSource = base->format() == BaseFormat::Rtcm ? "RTCM 1005/1006" : "RINEX header";  // UBX gives none
          }
        }
        solver.setBaseGlonassChannels(base->glonassChannels());
        solver.setPhaseAlignment(roverAlignment, base->phaseAlignment());
        solver.addBaseEpoch(baseEpoch);
        lastBaseTime = baseEpoch.time;
        basePending = false;
      }
    } catch (const ParseError& e) {
      printError(e);
      exitCode = 1;
      baseDone = true;
    }
    if (!args.baseXyz && !basePosUsed) {
      if (auto p = base->antennaPosition()) {
        solver.setBasePosition(*p);
        basePosUsed = p;
        baseSource = base->format() == BaseFormat::Rtcm ? "RTCM 1005/1006" : "RINEX header";  // UBX gives none
      }
    }

    if (rover->format() != BaseFormat::Rinex) solver.setRoverGlonassChannels(rover->glonassChannels());
    const RtkSolution sol = solver.process(roverEpoch);
    showDopplerWarnings(solver.roverDoppler(), roverWarned);
    showDopplerWarnings(solver.base().doppler(), baseWarned);
    consume(sol);
    if (!args.quiet) {
      const auto now = std::chrono::steady_clock::now();
      if (now - lastProgress > std::chrono::milliseconds(tty ? 200 : 5000)) {
        lastProgress = now;
        std::string p;
        if (span > 0.0 && hdr.firstObs) {
          std::snprintf(buf, sizeof buf, " %5.1f%%", 100.0 * std::clamp((roverEpoch.time - *hdr.firstObs) / span, 0.0, 1.0));
          p = buf;
        }
        std::fprintf(stderr, "%s%s epoch %ld%s fix %ld float %ld single %ld ratio %.1f%s", tty ? "\r" : "",
                     roverEpoch.time.toString(1).c_str(), epochs, p.c_str(), fixed, floats, singles, sol.ratio,
                     tty ? "   " : "\n");
        std::fflush(stderr);
      }
    }
    try {
      haveRover = rover->next(roverEpoch);
    } catch (const ParseError& e) {
      printError(e);
      exitCode = 1;
      break;
    }
  }
  if (!writer) writer = std::make_unique<PosWriter>(*out, popt);
  writer->finish();
  const bool toFile = output->isFile();
  try {
    output->finish(exitCode == 0);
    side->finish(exitCode == 0);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "gvins-rtk: error: %s\n", e.what());
    exitCode = 1;
  }
  if (exitCode != 0 && toFile)
    std::fprintf(stderr, "gvins-rtk: no output written to '%s' (the run failed)\n", args.out.c_str());
  if (!args.quiet && tty) std::fprintf(stderr, "\r%90s\r", "");
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();

  printSummary(args, cfg, solver, *rover, *base, counts, basePosUsed, baseSource, wall, fixStats, rtkStats);
  const long solved = fixed + floats + singles;
  if (solved == 0 && exitCode == 0) exitCode = 3;
  return exitCode;
}
