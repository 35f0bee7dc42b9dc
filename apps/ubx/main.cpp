// gvins-ubx: u-blox UBX logs (RXM-RAWX raw observations, mixed with NMEA and RTCM 3 or not).
#include <cstdio>
#include <iostream>
#include <string>

#include "commands.hpp"
#include "gvins/base/command_line.hpp"

namespace {

constexpr const char* kUsage =
    "usage: gvins-ubx <command> ...\n"
    "  info FILE|-\n"
    "      one row per UBX message (class-id, count, name), NMEA/RTCM 3 counts of a mixed stream,\n"
    "      time span and epochs, signals per system, SFRBX navigation messages per gnssId/sigId\n"
    "      (BeiDou GEO apart; decoded or not), checksum failures and malformed\n"
    "      messages\n"
    "  to-rinex FILE|- -o PREFIX [--max-phase-sigma CYC]\n"
    "      writes PREFIX.obs (RINEX 3.04) with every RXM-RAWX signal and PREFIX.nav (RINEX 3.04)\n"
    "      with the ephemerides of RXM-SFRBX; --max-phase-sigma leaves out phases whose reported\n"
    "      standard deviation is larger (RTKLIB's convbin: 0.02)\n"
    "  to-pos FILE|- -o OUT.pos\n"
    "      the receiver's own solutions (NAV-PVT) as an RTKLIB .pos file: GPST, latitude,\n"
    "      longitude, ellipsoidal height, Q (1 RTK fixed, 2 RTK float, 4 differential, 5 single),\n"
    "      satellites, sigmas from hAcc/vAcc, velocity with sigmas from sAcc; epochs without a 3D\n"
    "      fix are left out and counted (docs/ubx.md)\n"
    "exit status: 0 ok, 1 error (file, decoding), 2 usage\n";

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::cerr << kUsage;
    return 2;
  }
  const std::string cmd = argv[1];
  if (cmd == "-h" || cmd == "--help") {
    std::fputs(kUsage, stdout);
    return 0;
  }
  gvins::CommandLine cl("gvins-ubx", kUsage, argc, argv, 2);
  try {
    if (cmd == "info") return gvins::ubx_app::runInfo(cl);
    if (cmd == "to-rinex") return gvins::ubx_app::runToRinex(cl);
    if (cmd == "to-pos") return gvins::ubx_app::runToPos(cl);
  } catch (const std::exception& e) {
    std::cerr << "gvins-ubx: " << e.what() << "\n";
    return 1;
  }
  cl.error("unknown command '" + cmd + "'");
}
