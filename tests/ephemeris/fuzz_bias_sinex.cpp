// libFuzzer target for the Bias-SINEX reader. Any input either parses or throws ParseError; what
// parses must hold finite values in ns/cyc entries with valid satellites and [start, end)
// intervals, and the lookups must find every satellite code OSB at its start time.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include "gvins/ephemeris/bias_sinex.hpp"

#include "../fuzz/parse_error_check.hpp"

namespace {

void check(bool ok) {
  if (!ok) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  gvins::BiasSinexData bia;
  try {
    bia = gvins::parseBiasSinex(text, "fuzz.bia");
  } catch (const gvins::ParseError& e) {
    gvins::fuzz::checkParseError(e, "fuzz.bia", text);
    return 0;
  }
  volatile double sink = 0.0;
  for (const gvins::BiasEntry& e : bia.entries) {
    check(std::isfinite(e.value) && std::isfinite(e.sigma) && e.sigma >= 0.0);
    check(e.unit == "ns" || (e.unit == "cyc" && e.phase));
    check(e.openEnd || e.start < e.end);
    check(e.satellite || !e.station.empty());
    check((e.type == gvins::BiasType::kOsb) == !e.obs2.has_value() || e.type == gvins::BiasType::kIsb);
    if (!e.satellite) continue;
    check(e.satellite->valid());
    const gvins::SatId sat = *e.satellite;
    const gvins::GpsTime before = e.start - 1.0;
    const auto osb = bia.codeOsb(sat, e.obs1, e.start);
    if (e.type == gvins::BiasType::kOsb && !e.phase && e.station.empty()) check(osb.has_value());
    if (osb) check(std::isfinite(*osb));
    if (e.obs2) {
      const auto ab = bia.codeDsb(sat, e.obs1, *e.obs2, e.start);
      const auto ba = bia.codeDsb(sat, *e.obs2, e.obs1, before);
      if (e.type == gvins::BiasType::kDsb && !e.phase && e.station.empty()) check(ab.has_value());
      if (ab) sink = sink + *ab;
      if (ba) sink = sink + *ba;
    }
    if (!e.openEnd) sink = sink + bia.codeOsb(sat, e.obs1, e.end).value_or(0.0);
  }
  return 0;
}
