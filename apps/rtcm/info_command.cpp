// gvins-rtcm info FILE|- [--date YYYY-MM-DD]
#include <iostream>
#include <vector>

#include "commands.hpp"
#include "stream_summary.hpp"

namespace gvins::rtcm_app {

int runInfo(const std::vector<std::string>& args) {
  std::string path;
  std::optional<GpsTime> date;
  for (std::size_t i = 0; i < args.size(); ++i) {
    requireValue(args, i, {"-o", "--date", "--interval"});
    if (args[i] == "--date") date = parseDate(args[++i]);
    else if (args[i].size() > 1 && args[i][0] == '-') throw UsageError("info: unknown option '" + args[i] + "'");
    else if (path.empty()) path = args[i];
    else throw UsageError("info: more than one input");
  }
  if (path.empty()) throw UsageError("info: no input (FILE or -)");
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
