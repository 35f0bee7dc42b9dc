// The command line of gvins-spp and how it sets the SPP configuration on top of the defaults
// and of a --config YAML file.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "gvins/gnss/spp_config.hpp"

namespace gvins::sppapp {

/// The options as given (unset optionals leave the configuration's value).
struct SppOptions {
  std::string config;
  std::string out;
  std::string nmea, kml;
  std::string score;
  std::vector<std::string> inputs;
  std::optional<std::string> systems;
  std::optional<double> elmask, snrmask;
  std::optional<int> freq;
  std::optional<IonosphereOption> iono;
  std::optional<TroposphereOption> tropo;
  std::optional<double> smooth;
  std::vector<std::string> ssr;
  bool noFde = false, noVelocity = false, xyz = false, strict = false, quiet = false, dropFailed = false;
  int timeDecimals = 3;
  std::optional<Eigen::Vector3d> truth;
};

/// Parses argv; usage errors print a message and exit with 2, --help prints the usage and exits.
SppOptions parseSppOptions(int argc, char** argv);

/// Configuration: defaults, the --config YAML file, then the command line; a bad configuration
/// file prints its error and exits with 2.
SppConfig sppConfiguration(const SppOptions& args);

/// "gvins-spp: error: MESSAGE" on stderr.
void printSppError(const std::string& message);

}  // namespace gvins::sppapp
