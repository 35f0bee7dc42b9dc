// gvins-spp's command line (usage text, parsing) and configuration.
#include "spp_options.hpp"

#include <cstdio>
#include <cstdlib>
#include <stdexcept>

#include "gvins/base/command_line.hpp"
#include "gvins/base/constants.hpp"
#include "gvins/base/parse_error.hpp"
#include "gvins/gnss/base_reader.hpp"

namespace gvins::sppapp {
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

}  // namespace

SppOptions parseSppOptions(int argc, char** argv) {
  SppOptions a;
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

void printSppError(const std::string& message) { std::fprintf(stderr, "gvins-spp: error: %s\n", message.c_str()); }

/// Configuration: defaults, YAML, command line; exit status 2 on a bad configuration file.
SppConfig sppConfiguration(const SppOptions& args) {
  SppConfig cfg;
  try {
    if (!args.config.empty()) cfg = loadSppConfig(args.config, cfg);
  } catch (const ParseError& e) {
    printSppError(e.what());
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

}  // namespace gvins::sppapp
