// libFuzzer target for the RINEX observation reader: any input must either parse or throw
// ParseError. Whatever parses is written back as RINEX 3 and must read again with the same number
// of epochs (writer/reader consistency).
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <string_view>

#include "gvins/base/rinex_obs_reader.hpp"
#include "gvins/base/rinex_obs_writer.hpp"

#include "../fuzz/parse_error_check.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  // First byte selects the reader options; the rest is the file.
  gvins::RinexObsReaderOptions opt;
  opt.skipBadEpochs = data[0] & 1;
  opt.returnSpecialRecords = data[0] & 2;
  const std::string_view text(reinterpret_cast<const char*>(data + 1), size - 1);
  std::ostringstream out;
  std::int64_t epochs = 0;
  try {
    gvins::RinexObsReader r(text, "fuzz.obs", opt);
    gvins::ObsEpoch e;
    gvins::RinexObsHeader h = r.header();
    h.date = "20240101 000000 UTC";
    gvins::RinexObsWriter w(out, h);
    while (r.next(e)) {
      w.write(e, r.eventRecords());
      ++epochs;
    }
    w.finish();
  } catch (const gvins::ParseError& e) {
    gvins::fuzz::checkParseError(e, "fuzz.obs", text);
    return 0;
  }
  // Re-read what was written: it must parse, with the same number of epochs.
  gvins::RinexObsReaderOptions opt2;
  opt2.returnSpecialRecords = opt.returnSpecialRecords;
  const std::string written = out.str();
  gvins::RinexObsReader r2(std::string_view(written), "rewritten.obs", opt2);
  gvins::ObsEpoch e;
  std::int64_t n = 0;
  while (r2.next(e)) ++n;
  if (n != epochs) std::abort();
  return 0;
}
