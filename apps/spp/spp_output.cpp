#include "spp_output.hpp"

#include <cstdio>
#include <exception>
#include <optional>
#include <utility>

#include "gvins/base/constants.hpp"

namespace gvins::sppapp {
namespace {

std::string systemsText(const SppConfig& c) {
  std::string s;
  for (int i = 0; i < kNumSystems; ++i) {
    if (c.systems[i]) s += systemLetter(static_cast<System>(i));
  }
  return s;
}

}  // namespace

PosWriterOptions posOptions(const SppOptions& args, const SppConfig& cfg, const BaseReader& obs, const RinexObsHeader& hdr) {
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

SppOutput::SppOutput(const SppOptions& args, PosWriterOptions options)
    : path_(args.out),
      target_(args.out),
      side_(args.nmea, args.kml, "gvins-spp " + args.inputs[0]),
      writer_(target_.stream(), std::move(options)) {}

void SppOutput::write(const SppSolution& sol, const PositionSolution& ps) {
  writer_.write(ps);
  side_.add(ps, NmeaExtras{sol.dop.valid ? std::optional<double>(sol.dop.hdop) : std::nullopt, std::nullopt});
}

int SppOutput::finish(int exitCode) {
  writer_.finish();
  const bool toFile = target_.isFile();
  try {
    target_.finish(exitCode == 0);
    side_.finish(exitCode == 0);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "gvins-spp: error: %s\n", e.what());
    exitCode = 1;
  }
  if (exitCode != 0 && toFile)
    std::fprintf(stderr, "gvins-spp: no output written to '%s' (the run failed)\n", path_.c_str());
  return exitCode;
}

}  // namespace gvins::sppapp
