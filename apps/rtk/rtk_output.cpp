#include "rtk_output.hpp"

#include <cstdio>

#include "gvins/base/constants.hpp"

namespace gvins::rtkapp {
namespace {

PosWriterOptions posOptions(const RtkOptions& args, const RtkConfig& cfg) {
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
  return popt;
}

}  // namespace

std::string systemsText(const std::array<bool, kNumSystems>& s) {
  std::string t;
  for (int i = 0; i < kNumSystems; ++i) {
    if (s[static_cast<std::size_t>(i)]) t += systemLetter(static_cast<System>(i));
  }
  return t.empty() ? "-" : t;
}

RtkOutput::RtkOutput(const RtkOptions& args, const RtkConfig& cfg)
    : path_(args.out), pos_(args.out), side_(args.nmea, args.kml, "gvins-rtk " + args.inputs[0]),
      options_(posOptions(args, cfg)) {}

void RtkOutput::write(const RtkSolution& sol, const BaseLocation& base) {
  if (!writer_) {
    if (base.position) {
      char buf[200];
      std::snprintf(buf, sizeof buf, "%.4f %.4f %.4f (%s)", (*base.position)[0], (*base.position)[1], (*base.position)[2],
                    base.source.c_str());
      options_.headerFields.emplace_back("ref pos", buf);
    }
    writer_ = std::make_unique<PosWriter>(pos_.stream(), options_);
  }
  writer_->write(sol.toPositionSolution());
  side_.add(sol.toPositionSolution(), NmeaExtras{sol.hdop, std::nullopt});
}

int RtkOutput::finish(int exitCode) {
  if (!writer_) writer_ = std::make_unique<PosWriter>(pos_.stream(), options_);
  writer_->finish();
  const bool toFile = pos_.isFile();
  try {
    pos_.finish(exitCode == 0);
    side_.finish(exitCode == 0);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "gvins-rtk: error: %s\n", e.what());
    exitCode = 1;
  }
  if (exitCode != 0 && toFile) std::fprintf(stderr, "gvins-rtk: no output written to '%s' (the run failed)\n", path_.c_str());
  return exitCode;
}

}  // namespace gvins::rtkapp
