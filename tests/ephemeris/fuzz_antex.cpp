// libFuzzer target for the ANTEX reader. Any input either parses or throws ParseError; what parses
// must satisfy the grid invariants (a NOAZI row per ZEN1..ZEN2/DZEN point, one azimuth row per
// DAZI step, finite values), and the satellite and receiver lookups must find what they should.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include "gvins/ephemeris/antex.hpp"

#include "../fuzz/parse_error_check.hpp"

namespace {

void check(bool ok) {
  if (!ok) std::abort();
}

bool finite(const std::vector<double>& v) {
  for (double x : v) {
    if (!std::isfinite(x)) return false;
  }
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  gvins::AntexData atx;
  try {
    atx = gvins::parseAntex(text, "fuzz.atx");
  } catch (const gvins::ParseError& e) {
    gvins::fuzz::checkParseError(e, "fuzz.atx", text);
    return 0;
  }
  volatile double sink = 0.0;
  for (const gvins::AntexAntenna& a : atx.antennas) {
    const auto points = static_cast<std::size_t>(std::round((a.zen2 - a.zen1) / a.dzen)) + 1;
    const std::size_t rows = a.dazi > 0.0 ? static_cast<std::size_t>(std::round(360.0 / a.dazi)) + 1 : 0;
    check(points >= 2 && points <= 1000);
    check(!a.frequencies.empty());
    for (const gvins::AntexFrequency& f : a.frequencies) {
      check(a.frequency(f.system, f.band) == &f);
      check(f.offset.allFinite());
      check(f.noAzimuth.size() == points && finite(f.noAzimuth));
      check(f.byAzimuth.size() == rows);
      for (const auto& r : f.byAzimuth) check(r.size() == points && finite(r));
      sink = sink + f.offset.z() + f.noAzimuth.back();
    }
    if (a.validFrom && a.validUntil) check(*a.validFrom < *a.validUntil);
    if (a.isSatellite()) {
      check(a.satellite->valid());
      // At its VALID FROM (or any time, when open) some antenna of the satellite is valid, and
      // the one returned is valid then too.
      const gvins::GpsTime t = a.validFrom ? *a.validFrom : gvins::GpsTime::fromWeekTow(2300, 0.0);
      if (a.validAt(t)) {
        const gvins::AntexAntenna* s = atx.satellite(*a.satellite, t);
        check(s != nullptr && s->satellite && *s->satellite == *a.satellite && s->validAt(t));
        if (a.validFrom) check(s->validFrom && !(*s->validFrom < *a.validFrom));
      }
      if (a.validUntil) {
        const gvins::AntexAntenna* s = atx.satellite(*a.satellite, *a.validUntil);
        check(s != &a);
      }
    } else {
      const gvins::AntexAntenna* r = atx.receiver(a.type);
      check(r != nullptr && r->type == a.type && !r->isSatellite());
      std::string other = a.type.substr(0, 16);
      other.resize(16, ' ');
      sink = sink + (atx.receiver(other + "ZZZZ") != nullptr ? 1.0 : 0.0);
    }
  }
  return 0;
}
