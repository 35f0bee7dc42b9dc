// gvins-spp: single point positioning (and Doppler velocity) from RINEX observation and
// navigation files, written as an RTKLIB-compatible .pos file.
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <map>
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
#include "gvins/ephemeris/precise_product_files.hpp"
#include "gvins/ephemeris/rinex_nav.hpp"
#include "gvins/gnss/accuracy_statistics.hpp"
#include "gvins/gnss/base_reader.hpp"
#include "gvins/gnss/carrier_smoothing.hpp"
#include "gvins/gnss/clock_jump_repair.hpp"
#include "gvins/gnss/doppler_consistency.hpp"
#include "gvins/gnss/pos_reader.hpp"
#include "gvins/gnss/pos_writer.hpp"
#include "gvins/gnss/solution_outputs.hpp"
#include "gvins/gnss/spp.hpp"
#include "gvins/gnss/spp_config.hpp"
#include "gvins/rtcm/ssr_file.hpp"

namespace {

const char* kUsage =
    "usage: gvins-spp [options] -o OUT.pos OBS [NAV...] [ORBIT.sp3...] [CLOCK.clk...] [ANT.atx]\n"
    "                 [BIAS.bia...]\n"
    "       gvins-spp --score FILE.pos --truth X,Y,Z | --truth-llh LAT,LON,H\n"
    "\n"
    "Single point positioning from RINEX observations (2.10/2.11, 3.0x; plain or .gz) or a u-blox\n"
    "UBX log (RXM-RAWX; told apart by content) and broadcast navigation files (RINEX 2/3/4, merged;\n"
    "optional for UBX, whose RXM-SFRBX ephemerides are used as they arrive). Writes one RTKLIB-style .pos row per\n"
    "solved epoch, prints progress and a summary to stderr. Precise products among the inputs\n"
    "(SP3-c/d orbits *.sp3, RINEX clocks *.clk, plain or .gz; told apart by their names) replace\n"
    "the broadcast orbits and clocks where they cover a satellite; an ANTEX file (*.atx) moves\n"
    "their centre-of-mass positions to the antenna phase centre (needed for IGS products), and\n"
    "Bias-SINEX code biases (*.bia, *.bsx: OSBs) replace the broadcast group delays with them.\n"
    "\n"
    "  -o FILE            output .pos file ('-' for stdout); required\n"
    "  --nmea FILE        also NMEA 0183 GGA+RMC sentences of the solutions (docs/nmea.md)\n"
    "  --kml FILE         also a KML track of the solutions\n"
    "  --config F.yaml    options from the 'spp:' section of a YAML file (see docs); command-line\n"
    "                     options given after it override it\n"
    "  --systems GRECJ    systems to use (G GPS, R GLONASS, E Galileo, C BeiDou, J QZSS, S SBAS,\n"
    "                     I NavIC); default GRECJ\n"
    "  --elmask DEG       elevation mask, degrees (default 15)\n"
    "  --snrmask DBHZ     C/N0 mask, dB-Hz (default 0 = off)\n"
    "  --freq N           bands per system, 1-3 (default 1); with 2 or 3 and --iono dual-frequency\n"
    "                     ionosphere-free pseudoranges are formed where two bands exist\n"
    "  --iono MODEL       off | broadcast | dual-frequency (default broadcast: Klobuchar, BeiDou's\n"
    "                     own parameters for BeiDou)\n"
    "  --tropo MODEL      off | saastamoinen (default; Niell mapping)\n"
    "  --ssr F            SSR orbit/clock/code-bias corrections from a recorded RTCM 3 stream\n"
    "                     (repeatable): they correct the broadcast records where no precise\n"
    "                     products cover a satellite\n"
    "  --smooth S         carrier-smoothed pseudoranges, Hatch window S seconds (e.g. 100; default\n"
    "                     the config's carrier_smoothing_s, 0 = raw codes); with --freq 2 --iono\n"
    "                     dual-frequency free of divergence\n"
    "  --no-fde           no fault detection and exclusion\n"
    "  --no-velocity      no Doppler velocity (no velocity columns)\n"
    "  --drop-failed      omit the epochs whose residual (RAIM) test failed even after fault\n"
    "                     exclusion (by default they are written with test = 1 in the last column)\n"
    "  --xyz              ECEF x/y/z columns instead of latitude/longitude/height\n"
    "  --time-decimals N  decimals of the time column (default 3)\n"
    "  --truth X,Y,Z      true antenna position (ECEF, m): adds an accuracy table (east/north/up\n"
    "                     mean, std, RMS, horizontal/vertical RMS, 95 %, max; velocity errors are\n"
    "                     taken against zero, i.e. a static receiver)\n"
    "  --truth-llh LAT,LON,H   the same as latitude, longitude (deg) and ellipsoidal height (m)\n"
    "  --strict           stop at the first malformed epoch (default: skip it and count it)\n"
    "  --score FILE.pos   only print the accuracy table of an existing .pos file (ours or RTKLIB's,\n"
    "                     geodetic or ECEF layout) against --truth / --truth-llh\n"
    "  -q, --quiet        no progress line\n"
    "  -h, --help         this text\n";

struct Args {
  std::string config;
  std::string out;
  std::string nmea, kml;
  std::string score;
  std::vector<std::string> inputs;
  std::optional<std::string> systems;
  std::optional<double> elmask, snrmask;
  std::optional<int> freq;
  std::optional<gvins::IonosphereOption> iono;
  std::optional<gvins::TroposphereOption> tropo;
  std::optional<double> smooth;
  std::vector<std::string> ssr;
  bool noFde = false, noVelocity = false, xyz = false, strict = false, quiet = false, dropFailed = false;
  int timeDecimals = 3;
  std::optional<Eigen::Vector3d> truth;
};

Args parseArgs(int argc, char** argv) {
  Args a;
  gvins::CommandLine cl("gvins-spp", kUsage, argc, argv);
  while (cl.next()) {
    if (cl.is("-o")) a.out = cl.value();
    else if (cl.is("--nmea")) a.nmea = cl.value();
    else if (cl.is("--kml")) a.kml = cl.value();
    else if (cl.is("--config")) a.config = cl.value();
    else if (cl.is("--systems")) a.systems = cl.value();
    else if (cl.is("--elmask")) a.elmask = cl.number(-10.0, 90.0, "deg");
    else if (cl.is("--snrmask")) a.snrmask = cl.number(0.0, 100.0, "dB-Hz");
    else if (cl.is("--freq")) a.freq = static_cast<int>(cl.integer(1, 3));
    else if (cl.is("--iono")) a.iono = cl.choice(gvins::kIonosphereOptionNames);
    else if (cl.is("--tropo")) a.tropo = cl.choice(gvins::kTroposphereOptionNames);
    else if (cl.is("--smooth")) a.smooth = cl.number(0.0, 3600.0, "s");
    else if (cl.is("--ssr")) a.ssr.push_back(cl.value());
    else if (cl.is("--no-fde")) a.noFde = true;
    else if (cl.is("--no-velocity")) a.noVelocity = true;
    else if (cl.is("--drop-failed")) a.dropFailed = true;
    else if (cl.is("--xyz")) a.xyz = true;
    else if (cl.is("--time-decimals")) a.timeDecimals = static_cast<int>(cl.integer(0, 9));
    else if (cl.is("--truth")) a.truth = cl.vector3(-1e8, 1e8, "m");
    else if (cl.is("--truth-llh")) a.truth = cl.stationLlh();
    else if (cl.is("--score")) a.score = cl.value();
    else if (cl.is("--strict")) a.strict = true;
    else if (cl.is("-q", "--quiet")) a.quiet = true;
    else a.inputs.push_back(cl.operand());
  }
  if (!a.score.empty()) {
    if (!a.truth) cl.error("--score needs --truth or --truth-llh");
    return a;
  }
  if (a.out.empty()) cl.error("no output file (-o OUT.pos)");
  if (a.inputs.empty() || (a.inputs.size() == 1 && gvins::BaseReader::detect(a.inputs[0]) != gvins::BaseFormat::Ubx)) {
    cl.error("need an observation file and at least one navigation file (a UBX log may come alone: it carries its own)");
  }
  return a;
}

std::string systemsText(const gvins::SppConfig& c) {
  std::string s;
  for (int i = 0; i < gvins::kNumSystems; ++i) {
    if (c.systems[i]) s += gvins::systemLetter(static_cast<gvins::System>(i));
  }
  return s;
}

void printError(const gvins::ParseError& e) { std::fprintf(stderr, "gvins-spp: error: %s\n", e.what()); }

using namespace gvins;

/// --score: the accuracy table of an existing .pos file.
int score(const Args& args) {
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
    printError(e);
    return 1;
  }
}

/// Configuration: defaults, YAML, command line; exit status 2 on a bad configuration file.
SppConfig configuration(const Args& args) {
  SppConfig cfg;
  try {
    if (!args.config.empty()) cfg = loadSppConfig(args.config, cfg);
  } catch (const ParseError& e) {
    printError(e);
    std::exit(2);
  }
  try {
    if (args.systems) cfg.systems = parseSystemLetters(*args.systems);
  } catch (const std::invalid_argument& e) {
    usageError("gvins-spp", std::string("--systems: ") + e.what());
  }
  if (args.elmask) cfg.elevationMask = *args.elmask * constants::kDegToRad;
  if (args.snrmask) cfg.snrMask = *args.snrmask;
  if (args.freq) cfg.frequencies = *args.freq;
  if (args.iono) cfg.ionosphere = *args.iono;
  if (args.tropo) cfg.troposphere = *args.tropo;
  if (args.noFde) cfg.faultExclusion.enabled = false;
  if (args.noVelocity) cfg.velocity = false;
  if (args.smooth) cfg.carrierSmoothing = *args.smooth;
  return cfg;
}

/// Navigation files and precise products (told apart by name) into `nav`; 0 or an exit status.
int readNavigation(const Args& args, EphemerisStore& nav) {
  try {
    PreciseProductFiles products;
    for (std::size_t i = 1; i < args.inputs.size(); ++i) {
      if (!products.add(args.inputs[i])) nav.add(readRinexNav(args.inputs[i]));
    }
    if (!products.antennas.empty()) nav.setSatelliteAntennas(readAntennaFiles(products.antennas));
    if (!products.biases.empty()) nav.setCodeBiases(readCodeBiasFiles(products.biases));
    if (products.orbits.empty() && !products.clocks.empty()) {
      std::fprintf(stderr, "gvins-spp: error: clock files need an SP3 orbit file\n");
      return 2;
    }
    if (!products.orbits.empty()) {
      auto precise = readPreciseProducts(products.orbits, products.clocks);
      if (!args.quiet) std::fprintf(stderr, "precise products: %zu satellites\n", precise->satellites().size());
      nav.setPrecise(std::move(precise));
    }
  } catch (const ParseError& e) {
    printError(e);
    return 1;
  }
  return 0;
}

/// SSR corrections: their times of week resolve against the first observation epoch.
int readSsr(const Args& args, EphemerisStore& nav) {
  GpsTime first;
  try {
    auto peek = BaseReader::open(args.inputs[0], GpsTime{}, nullptr, !args.strict);
    ObsEpoch e;
    if (peek->next(e)) first = e.time;
  } catch (const ParseError& e) {
    printError(e);
    return 1;
  }
  try {
    std::size_t n = 0;
    for (const std::string& f : args.ssr) {
      const rtcm::SsrFile ssr = rtcm::readSsrFile(f, first);
      for (const SsrMessage& m : ssr.messages) nav.addSsr(m);
      n += ssr.messages.size();
      if (ssr.stats.malformed > 0 && !args.quiet)
        std::fprintf(stderr, "%s: %lld malformed RTCM frames skipped\n", f.c_str(),
                     static_cast<long long>(ssr.stats.malformed));
    }
    if (!args.quiet) std::fprintf(stderr, "SSR corrections: %zu messages\n", n);
  } catch (const ParseError& e) {
    printError(e);
    return 1;
  }
  return 0;
}

/// The .pos header and columns.
PosWriterOptions posOptions(const Args& args, const SppConfig& cfg, const BaseReader& obs, const RinexObsHeader& hdr) {
  PosWriterOptions popt;
  popt.coordinates = args.xyz ? PosCoordinates::Xyz : PosCoordinates::Llh;
  // Velocity columns when a velocity can exist: Doppler observations in the file and asked for.
  bool hasDoppler = false;
  for (int i = 0; i < kNumSystems; ++i) {
    if (!cfg.systems[i]) continue;
    for (const ObsDescriptor& d : hdr.obsTypes[i]) hasDoppler = hasDoppler || d.type == ObsType::Doppler;
  }
  hasDoppler = hasDoppler || (obs.format() == BaseFormat::Ubx && obs.mayHaveDoppler());
  popt.velocity = cfg.velocity && hasDoppler;
  if (!cfg.velocity) popt.notes.emplace_back("no velocity columns: velocity not estimated (--no-velocity)");
  else if (!hasDoppler) popt.notes.emplace_back("no velocity columns: no Doppler observations in the input");
  popt.testColumn = true;
  popt.timeDecimals = args.timeDecimals;
  popt.program = "SRI-GVINS gvins-spp";
  for (const auto& f : args.inputs) popt.headerFields.emplace_back("inp file", f);
  popt.headerFields.emplace_back("pos mode", "single");
  char buf[160];
  std::snprintf(buf, sizeof buf, "%.1f deg", cfg.elevationMask * constants::kRadToDeg);
  popt.headerFields.emplace_back("elev mask", buf);
  popt.headerFields.emplace_back("ionos opt", enumName(kIonosphereOptionNames, cfg.ionosphere));
  popt.headerFields.emplace_back("tropo opt", cfg.troposphere == TroposphereOption::Off ? "off" : "saastamoinen+niell");
  popt.headerFields.emplace_back("navi sys", systemsText(cfg));
  std::snprintf(buf, sizeof buf, "%d", cfg.frequencies);
  popt.headerFields.emplace_back("freqs", buf);
  if (args.dropFailed) popt.headerFields.emplace_back("failed", "epochs failing the residual test omitted");
  if (cfg.carrierSmoothing > 0.0) {
    std::snprintf(buf, sizeof buf, "%.0f s", cfg.carrierSmoothing);
    popt.headerFields.emplace_back("carrier smoothing", buf);
  }
  return popt;
}

/// Counts of the processing loop for the summary.
struct Counts {
  std::map<SppStatus, long> status;
  std::map<SatId, long> excluded;
  std::array<long, 8> use{};
  long epochs = 0, solutions = 0, velocities = 0, testFailed = 0, untestable = 0, written = 0;
  double satSum = 0.0;
};

/// The summary on stderr.
void printSummary(const Args& args, const BaseReader& obs, const RinexObsHeader& hdr, const Counts& c,
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

}  // namespace

int main(int argc, char** argv) {
  using namespace gvins;
  keepHeapPages();
  const Args args = parseArgs(argc, argv);
  const auto wall0 = std::chrono::steady_clock::now();
  if (!args.score.empty()) return score(args);
  const SppConfig cfg = configuration(args);
  EphemerisStore nav;
  if (const int rc = readNavigation(args, nav)) return rc;
  // Observations: RINEX or UBX, told apart by content (BaseReader). A UBX log adds the
  // ephemerides of its RXM-SFRBX subframes to `nav` as they are read.
  std::unique_ptr<BaseReader> obs;
  try {
    if (BaseReader::detect(args.inputs[0]) == BaseFormat::Rtcm) {
      std::fprintf(stderr, "gvins-spp: error: %s is an RTCM 3 log; convert it with gvins-rtcm to-rinex --date first\n",
                   args.inputs[0].c_str());
      return 1;
    }
    obs = BaseReader::open(args.inputs[0], GpsTime{}, &nav, !args.strict);
  } catch (const ParseError& e) {
    printError(e);
    return 1;
  }
  const bool streamInput = obs->format() == BaseFormat::Ubx;
  if (nav.size() == 0 && !streamInput) {
    std::fprintf(stderr, "gvins-spp: error: no usable ephemeris in the navigation files\n");
    return 1;
  }
  static const RinexObsHeader kNoHeader;
  const RinexObsHeader& hdr = obs->rinexHeader() ? *obs->rinexHeader() : kNoHeader;
  if (!args.ssr.empty()) {
    if (const int rc = readSsr(args, nav)) return rc;
  }

  SppSolver solver(nav, cfg);
  solver.setGlonassChannels(obs->glonassChannels());
  // GLONASS channels for the carrier smoothing's wavelengths: the header's, else the navigation
  // records' (as the solver does).
  GlonassChannels channels = obs->glonassChannels();
  channels.mergeMissing(nav.glonassChannels());
  if (hdr.station.approxPosition) solver.setInitialPosition(*hdr.station.approxPosition);

  // The .pos file is written under a temporary name and renamed only when the run succeeds: a
  // failed run leaves no file that looks valid (and an older file of that name intact).
  std::optional<OutputTarget> output;
  std::optional<SolutionOutputs> side;
  try {
    output.emplace(args.out);
    side.emplace(args.nmea, args.kml, "gvins-spp " + args.inputs[0]);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "gvins-spp: error: %s\n", e.what());
    return 1;
  }
  std::optional<CarrierSmoother> smoother;
  if (cfg.carrierSmoothing > 0.0) {
    CarrierSmoothingOptions so;
    so.window = cfg.carrierSmoothing;
    smoother.emplace(so);
  }
  PosWriter writer(output->stream(), posOptions(args, cfg, *obs, hdr));
  std::optional<AccuracyStatistics> stats;
  if (args.truth) stats.emplace(*args.truth);

  // Processing loop.
  Counts c;
  const bool tty = isatty(fileno(stderr));
  auto lastProgress = wall0;
  const double span = hdr.firstObs && hdr.lastObs ? *hdr.lastObs - *hdr.firstObs : 0.0;
  int exitCode = 0;
  // Doppler sanity of the receiver (doppler_consistency.hpp): a flipped sign is corrected, a
  // Doppler that disagrees with the phase/code rate is dropped, each with one warning.
  DopplerConsistency doppler("rover");
  std::size_t dopplerWarned = 0;
  ClockJumpRepair clockJumps("rover");  // whole-ms receiver clock jumps (clock_jump_repair.hpp)
  std::size_t jumpWarned = 0;
  std::size_t signalWarned = 0;  // primary signals from a fallback band (signal_choice.hpp)
  ObsEpoch epoch;
  char buf[160];
  for (;;) {
    try {
      if (!obs->next(epoch)) break;
    } catch (const ParseError& e) {
      printError(e);
      exitCode = 1;
      break;
    }
    ++c.epochs;
    if (streamInput) {  // UBX: GLONASS channels arrive with the observations (RAWX freqId)
      channels = obs->glonassChannels();
      channels.mergeMissing(nav.glonassChannels());
      solver.setGlonassChannels(obs->glonassChannels());
    }
    clockJumps.apply(epoch, channels);  // before the Doppler check and smoothing
    for (; jumpWarned < clockJumps.warnings().size(); ++jumpWarned) {
      std::fprintf(stderr, "%sgvins-spp: warning: %s\n", tty ? "\r" : "", clockJumps.warnings()[jumpWarned].c_str());
    }
    doppler.apply(epoch, channels);
    for (; dopplerWarned < doppler.warnings().size(); ++dopplerWarned) {
      std::fprintf(stderr, "%sgvins-spp: warning: %s\n", tty ? "\r" : "", doppler.warnings()[dopplerWarned].c_str());
    }
    if (smoother) smoother->apply(epoch, channels);
    const SppSolution sol = solver.solve(epoch);
    for (; signalWarned < solver.signalNotices().size(); ++signalWarned) {
      std::fprintf(stderr, "%sgvins-spp: warning: %s\n", tty ? "\r" : "", solver.signalNotices()[signalWarned].c_str());
    }
    ++c.status[sol.status];
    for (const auto& s : sol.satellites) ++c.use[static_cast<int>(s.use)];
    for (const auto& s : sol.excluded) ++c.excluded[s];
    if (sol.valid()) {
      ++c.solutions;
      const PositionSolution ps = sol.toPositionSolution();
      if (ps.residualTest == ResidualTest::Failed) ++c.testFailed;
      if (ps.residualTest == ResidualTest::Untestable) ++c.untestable;
      c.satSum += sol.numSatellites;
      if (sol.velocity.valid) ++c.velocities;
      if (args.dropFailed && ps.residualTest == ResidualTest::Failed) continue;
      ++c.written;
      writer.write(ps);
      side->add(ps, NmeaExtras{sol.dop.valid ? std::optional<double>(sol.dop.hdop) : std::nullopt, std::nullopt});
      if (stats) {
        stats->addPosition(sol.position);
        if (sol.velocity.valid) stats->addVelocity(sol.velocity.velocity);
      }
    }
    if (!args.quiet) {
      const auto now = std::chrono::steady_clock::now();
      if (now - lastProgress > std::chrono::milliseconds(tty ? 200 : 5000)) {
        lastProgress = now;
        std::string pct;
        if (span > 0.0 && hdr.firstObs) {
          std::snprintf(buf, sizeof buf, " %5.1f%%", 100.0 * std::clamp((epoch.time - *hdr.firstObs) / span, 0.0, 1.0));
          pct = buf;
        }
        std::fprintf(stderr, "%s%s epoch %ld %s solutions %ld%s", tty ? "\r" : "", epoch.time.toString(1).c_str(),
                     c.epochs, pct.c_str(), c.solutions, tty ? "   " : "\n");
        std::fflush(stderr);
      }
    }
  }
  writer.finish();
  const bool toFile = output->isFile();
  try {
    output->finish(exitCode == 0);
    side->finish(exitCode == 0);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "gvins-spp: error: %s\n", e.what());
    exitCode = 1;
  }
  if (exitCode != 0 && toFile)
    std::fprintf(stderr, "gvins-spp: no output written to '%s' (the run failed)\n", args.out.c_str());
  if (!args.quiet && tty) std::fprintf(stderr, "\r%60s\r", "");
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  printSummary(args, *obs, hdr, c, doppler, wall);
  if (stats) std::fputs(stats->table().c_str(), stderr);
  if (c.solutions == 0 && exitCode == 0) exitCode = 3;
  return exitCode;
}
