// The command line of gvins-rtk (post-processing and live mode) and how it sets the RTK and SPP
// configuration on top of the defaults and of a --config YAML file.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "gvins/gnss/rtk_config.hpp"
#include "gvins/gnss/spp_config.hpp"

namespace gvins::rtkapp {

/// The options as given (unset optionals leave the configuration's value).
struct RtkOptions {
  std::string config, out;
  std::string nmea, kml;
  std::string roverStream, baseStream, latencyLog;
  double baseWait = 0.0, maxOutage = 0.0;
  std::vector<std::string> inputs;
  std::optional<Eigen::Vector3d> baseXyz, truth;
  std::optional<RtkMode> mode;
  std::optional<RtkDynamics> dynamics;
  std::optional<AmbiguityMode> armode;
  std::optional<AmbiguityValidation> validation;
  std::optional<std::string> systems, arSystems;
  std::optional<double> ratio, elmask, maxAge, maxFailureRate;
  std::optional<int> freq;
  bool combined = false;
  bool noPartial = false, noInterpolation = false, xyz = false, noVelocity = false, strict = false, quiet = false;
  int timeDecimals = 3;

  /// Live mode: rover and base from streams.
  bool live() const { return !roverStream.empty(); }
};

/// Parses argv; usage errors print a message and exit with 2, --help prints the usage and exits.
RtkOptions parseRtkOptions(int argc, char** argv);

/// Configuration: defaults, the --config YAML file, then the command line. Returns 0, or the
/// exit status of a bad configuration file (2, message printed).
int applyRtkOptions(const RtkOptions& args, RtkConfig& cfg, SppConfig& sppCfg);

/// "gvins-rtk: error: MESSAGE" on stderr.
void printRtkError(const std::string& message);

}  // namespace gvins::rtkapp
