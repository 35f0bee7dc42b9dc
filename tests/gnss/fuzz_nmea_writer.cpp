// libFuzzer target: NMEA GGA/RMC sentences of arbitrary solutions (any doubles: NaN, inf, huge,
// negative ages, times far from now). Every sentence must be one line "$...*HH\r\n" of printable
// ASCII with a correct checksum and bounded length.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>

#include "gvins/gnss/nmea_writer.hpp"

namespace {

double take(const std::uint8_t*& p, std::size_t& n) {
  double v = 0.0;
  if (n >= sizeof v) {
    std::memcpy(&v, p, sizeof v);
    p += sizeof v;
    n -= sizeof v;
  }
  return v;
}

void check(const std::string& s) {
  if (s.size() < 8 || s.size() > 120 || s[0] != '$' || s.substr(s.size() - 2) != "\r\n") std::abort();
  const std::size_t star = s.size() - 5;
  if (s[star] != '*') std::abort();
  unsigned x = 0;
  for (std::size_t i = 1; i < star; ++i) {
    if (s[i] < 0x20 || s[i] > 0x7e || s[i] == '$' || s[i] == '*') std::abort();
    x ^= static_cast<unsigned char>(s[i]);
  }
  if (std::strtoul(s.substr(star + 1, 2).c_str(), nullptr, 16) != x) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::uint8_t* p = data;
  std::size_t n = size;
  gvins::PositionSolution s;
  const double t = take(p, n);
  // Times within +-1000 years of the GPS epoch (the calendar conversions' domain).
  if (std::isfinite(t)) s.time = gvins::GpsTime::fromSeconds(static_cast<std::int64_t>(std::fmod(t, 3.0e10)), 0.0);
  for (int i = 0; i < 3; ++i) s.position[i] = take(p, n);
  s.age = take(p, n);
  const double q = take(p, n);
  s.quality = static_cast<gvins::SolutionQuality>(std::isfinite(q) ? static_cast<int>(std::fabs(std::fmod(q, 7.0))) : 0);
  // fmod first: q * 1000 may overflow to infinity, and fmod(inf) is NaN, whose cast is undefined.
  s.numSatellites = static_cast<int>(std::isfinite(q) ? std::fmod(q, 1.0) * 1000.0 : 0);
  if (n >= 24) {
    Eigen::Vector3d v;
    for (int i = 0; i < 3; ++i) v[i] = take(p, n);
    s.velocity = v;
  }
  gvins::NmeaExtras e;
  e.hdop = take(p, n);
  e.stationId = static_cast<int>(size);
  check(gvins::nmeaGga(s, e));
  check(gvins::nmeaRmc(s));
  return 0;
}
