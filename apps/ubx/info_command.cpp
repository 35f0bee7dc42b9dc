// gvins-ubx info FILE|-
#include <iostream>
#include <variant>

#include "commands.hpp"
#include "stream_summary.hpp"
#include "ubx_summary.hpp"

namespace gvins::ubx_app {

int runInfo(CommandLine& cl) {
  std::string path;
  while (cl.next()) {
    const std::string& a = cl.operand();
    if (!path.empty()) cl.error("info: more than one input");
    path = a;
  }
  if (path.empty()) cl.error("info: no input (FILE or -)");
  ubx::DecoderOptions opt;
  opt.streamName = path;
  ubx::Decoder dec(opt);
  SummaryExtras ex;
  std::FILE* in = rtcm_app::openInput(path);
  decodeAll(in, dec, [&](const ubx::Decoded& item) {
    if (const auto* p = std::get_if<ubx::NavPvt>(&item)) {
      ++ex.navPvt;
      if (p->fixOk()) {
        ++ex.navPvtFixes;
        ex.lastPvt = *p;
      }
    } else if (const auto* c = std::get_if<ubx::NavClock>(&item)) {
      ex.lastClock = *c;
    }
  });
  if (in != stdin) std::fclose(in);
  printSummary(std::cout, dec, ex, path == "-" ? "<stdin>" : path);
  return 0;
}

}  // namespace gvins::ubx_app
