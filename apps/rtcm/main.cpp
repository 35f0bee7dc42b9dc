// gvins-rtcm: RTCM 3 streams from files, pipes and NTRIP casters.
#include <iostream>
#include <string>
#include <string_view>

#include "commands.hpp"
#include "gvins/base/command_line.hpp"
#include "gvins/base/parse_error.hpp"
#include "gvins/rtcm/ntrip_error.hpp"
#include "stream_summary.hpp"

namespace gvins::rtcm_app {

const std::string_view kUsage =
    "usage: gvins-rtcm <command> ...\n"
    "  info FILE|- [--date YYYY-MM-DD]\n"
    "      one row per message type (type, count, description), then time span, station,\n"
    "      ephemerides, CRC failures and malformed messages. Without --date the date comes from\n"
    "      the stream (1020 with N4, 1042, 1045/1046) or else from the host clock.\n"
    "  to-rinex FILE|- --date YYYY-MM-DD -o PREFIX\n"
    "      writes PREFIX.obs (RINEX 3.04 observations) and PREFIX.nav (RINEX 3.04 navigation);\n"
    "      --date is any day within a few days of the data (RTCM times carry no date)\n"
    "  ntrip URL -o FILE|- [--duration S] [--frames N] [--version 1|2] [--timeout S] [--gga NMEA]\n"
    "      records an NTRIP stream byte for byte; URL = ntrip://user:pass@host[:port]/MOUNT\n"
    "      (port 2101 by default); --frames stops right after the N-th frame, --duration after\n"
    "      S seconds; --timeout (default 10 s connect, 15 s data) gives up on a silent caster\n"
    "  from-products NAV... SP3... [CLK...] [ATX...] -o FILE [--interval S]\n"
    "      an SSR correction stream (combined orbit/clock 1060/1066/1243/1249/1261 every S s,\n"
    "      default 5) that turns the broadcast records of NAV into the products' states, over the\n"
    "      products' span; for testing real-time (SSR) processing: gvins-replay/gvins-spp --ssr\n"
    "exit status: 0 ok, 1 error (file, decoding, NTRIP), 2 usage\n";

}  // namespace gvins::rtcm_app

int main(int argc, char** argv) {
  using namespace gvins::rtcm_app;
  if (argc < 2 || std::string(argv[1]) == "-h" || std::string(argv[1]) == "--help") {
    std::cerr << kUsage;
    return argc < 2 ? 2 : 0;
  }
  const std::string cmd = argv[1];
  try {
    if (cmd == "info") return runInfo(argc, argv);
    if (cmd == "to-rinex") return runToRinex(argc, argv);
    if (cmd == "ntrip") return runNtrip(argc, argv);
    if (cmd == "from-products") return runFromProducts(argc, argv);
    gvins::usageError("gvins-rtcm", "unknown command '" + cmd + "'");
  } catch (const gvins::rtcm::NtripError& e) {
    std::cerr << "\ngvins-rtcm: NTRIP: " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "gvins-rtcm: " << e.what() << "\n";
    return 1;
  }
}
