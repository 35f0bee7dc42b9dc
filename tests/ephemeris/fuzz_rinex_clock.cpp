// libFuzzer target for the RINEX clock reader. Any input either parses or throws ParseError; what
// parses is added to PreciseEphemeris and written again (3.04 layout), and the written file must
// parse again with the same number of satellite records.
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <string_view>

#include "gvins/ephemeris/precise_ephemeris.hpp"
#include "gvins/ephemeris/rinex_clock.hpp"

#include "../fuzz/parse_error_check.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  gvins::ClockData clk;
  try {
    clk = gvins::parseRinexClock(text, "fuzz.clk");
  } catch (const gvins::ParseError& e) {
    gvins::fuzz::checkParseError(e, "fuzz.clk", text);
    return 0;
  }
  gvins::PreciseEphemeris pe;
  pe.add(clk);
  std::size_t records = 0;
  for (const auto& [sat, recs] : clk.satellites) records += recs.size();
  for (double version : {3.04, 3.00}) {
    clk.version = version;
    std::ostringstream out;
    gvins::writeRinexClock(out, clk);
    try {
      const gvins::ClockData back = gvins::parseRinexClock(out.str(), "fuzz-written.clk");
      std::size_t n = 0;
      for (const auto& [sat, recs] : back.satellites) n += recs.size();
      if (n != records) std::abort();
    } catch (const gvins::ParseError&) {
      std::abort();  // the writer produced something its own reader rejects
    }
  }
  return 0;
}
