// libFuzzer target for the RINEX navigation reader. Any input either parses or throws ParseError;
// what parses is pushed through the ephemeris store, the satellite state computations and the
// RINEX 3.04 writer, whose output must parse again.
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <string_view>

#include "gvins/ephemeris/ephemeris_store.hpp"

#include "../fuzz/parse_error_check.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  gvins::NavData nav;
  try {
    nav = gvins::parseRinexNav(text, "fuzz.nav");
  } catch (const gvins::ParseError& e) {
    gvins::fuzz::checkParseError(e, "fuzz.nav", text);
    return 0;
  }
  gvins::EphemerisStore store;
  store.add(nav);
  gvins::EphemerisSelection any;
  any.allowUnhealthy = true;
  volatile double sink = 0.0;
  for (const auto& e : nav.kepler) {
    for (double dt : {-600.0, 0.0, 900.0}) {
      const gvins::GpsTime t = e.toe + dt;
      sink = sink + gvins::keplerSatelliteState(e, t).position.x();
      if (const auto st = store.satelliteState(e.sat, t, any)) sink = sink + st->clockBias;
      sink = sink + store.groupDelay(e.sat, gvins::ObsCode('1', 'C'), t, any);
    }
  }
  for (const auto& g : nav.glonass) {
    sink = sink + gvins::glonassSatelliteState(g, g.toe + 900.0).position.y();
    if (const auto st = store.satelliteState(g.sat, g.toe, any)) sink = sink + st->clockBias;
  }
  std::ostringstream out;
  gvins::writeRinexNav(out, nav, "fuzz");
  try {
    const gvins::NavData back = gvins::parseRinexNav(out.str(), "fuzz-written.nav");
    if (back.kepler.size() + back.glonass.size() > nav.kepler.size() + nav.glonass.size()) std::abort();
  } catch (const gvins::ParseError&) {
    std::abort();  // the writer produced something its own reader rejects
  }
  return 0;
}
