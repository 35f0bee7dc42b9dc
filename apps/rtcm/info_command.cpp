// gvins-rtcm info FILE|- [--date YYYY-MM-DD]
#include <iostream>
#include <string>

#include "commands.hpp"
#include "gvins/base/command_line.hpp"
#include "stream_summary.hpp"

namespace gvins::rtcm_app {

int runInfo(int argc, char** argv) {
  std::string path;
  std::optional<GpsTime> date;
  CommandLine cl("gvins-rtcm info", kUsage, argc, argv, 2);
  while (cl.next()) {
    if (cl.is("--date")) date = dateOption(cl);
    else if (path.empty()) path = cl.operand();
    else {
      cl.operand();  // an unknown option is reported as such
      cl.error("more than one input");
    }
  }
  if (path.empty()) cl.error("no input (FILE or -)");
  rtcm::DecoderOptions opt;
  opt.referenceTime = referenceFor(path, date);
  opt.streamName = path;
  rtcm::Decoder dec(opt);
  std::FILE* in = openInput(path);
  decodeAll(in, dec, [](const rtcm::Decoded&) {});
  if (in != stdin) std::fclose(in);
  printSummary(std::cout, dec, path == "-" ? "<stdin>" : path);
  return 0;
}

}  // namespace gvins::rtcm_app
