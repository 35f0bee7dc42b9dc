// The live mode of gvins-rtk (rtkrcv-like): rover and base from streams (stream paths of
// gvins/rtcm/stream_url.hpp), every rover epoch solved as soon as it is complete with the same
// RtkSolver and configuration as post-processing, the solution written at once.
#pragma once

#include <optional>
#include <string>

#include <Eigen/Core>

#include "gvins/ephemeris/ephemeris_store.hpp"
#include "gvins/gnss/pos_writer.hpp"
#include "gvins/gnss/rtk_config.hpp"
#include "gvins/gnss/spp_config.hpp"

namespace gvins::rtklive {

struct LiveOptions {
  std::string rover, base;      ///< stream paths
  std::string out = "-";        ///< .pos output: a file, - (standard output), tcpsvr://:PORT or tcpcli://HOST:PORT
  std::string nmea;             ///< NMEA GGA+RMC output, the same kinds of path (empty: none)
  std::string latencyLog;       ///< CSV of per-epoch latency and base age (empty: none)
  /// s a rover epoch may wait for the base epoch after it (as post-processing pairs them);
  /// 0: solve at once with the latest base (real-time).
  double baseWait = 0.0;
  double maxOutage = 0.0;       ///< s without a connection after which a stream ends (0: never)
  std::optional<Eigen::Vector3d> baseXyz;
  PosWriterOptions pos;
  bool strict = false, quiet = false;
};

/// Runs until both streams end or SIGINT/SIGTERM; prints the summary. Returns the exit code.
int runLive(const LiveOptions& opt, const RtkConfig& cfg, const SppConfig& sppCfg, EphemerisStore& nav);

}  // namespace gvins::rtklive
