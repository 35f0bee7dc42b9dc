// libFuzzer target for the SP3 reader. Any input either parses or throws ParseError; what parses
// is interpolated by PreciseEphemeris and written again, and the written file must parse again
// with the same satellites and epochs.
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <string_view>

#include "gvins/ephemeris/precise_ephemeris.hpp"
#include "gvins/ephemeris/sp3.hpp"

#include "../fuzz/parse_error_check.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  gvins::Sp3Data sp3;
  try {
    sp3 = gvins::parseSp3(text, "fuzz.sp3");
  } catch (const gvins::ParseError& e) {
    gvins::fuzz::checkParseError(e, "fuzz.sp3", text);
    return 0;
  }
  gvins::PreciseEphemeris pe(gvins::PreciseEphemerisOptions{4, 330.0, 100.0});
  pe.add(sp3);
  volatile double sink = 0.0;
  const auto [first, last] = pe.span();
  for (const gvins::SatId sat : pe.satellites()) {
    for (double f : {0.0, 0.3, 0.5, 1.0}) {
      const gvins::GpsTime t = first + f * (last - first);
      if (const auto st = pe.satelliteState(sat, t)) sink = sink + st->position.x() + st->clockBias;
    }
  }
  std::ostringstream out;
  gvins::writeSp3(out, sp3);
  try {
    const gvins::Sp3Data back = gvins::parseSp3(out.str(), "fuzz-written.sp3");
    if (back.epochs.size() != sp3.epochs.size() || back.satellites.size() != sp3.satellites.size()) std::abort();
  } catch (const gvins::ParseError&) {
    std::abort();  // the writer produced something its own reader rejects
  }
  return 0;
}
