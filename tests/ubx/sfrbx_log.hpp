// Test helper: runs every RXM-SFRBX message of a UBX log through parseSfrbx and a
// NavigationAssembler, with the receive time of the latest RXM-RAWX epoch (its rcvTow R8 at byte 0
// and week U2 at byte 8, u-blox interface description UBX-RXM-RAWX) or, in logs without RAWX, of
// the latest NAV-TIMEGPS (iTOW U4 ms at 0, fTOW I4 ns at 4, week I2 at 8).
#pragma once

#include <cstring>
#include <filesystem>
#include <functional>
#include <vector>

#include "gvins/ubx/navigation_assembler.hpp"
#include "gvins/ubx/ubx_framer.hpp"
#include "independent_ubx_scan.hpp"

namespace gvins::ubx::testing {

struct DecodedLog {
  std::vector<KeplerEphemeris> kepler;
  std::vector<GlonassEphemeris> glonass;
  std::vector<NavDataUpdate> updates;
  NavigationAssembler assembler;
  std::size_t sfrbx = 0;
};

/// `mutate` (optional) changes each message before the assembler sees it.
inline DecodedLog decodeLog(const std::filesystem::path& path,
                            const std::function<void(SfrbxMessage&)>& mutate = {}) {
  DecodedLog out;
  const std::vector<std::uint8_t> bytes = readBytes(path);
  Framer framer;
  framer.feed(bytes);
  framer.finish();
  Frame f;
  GpsTime receiveTime;
  while (framer.next(f)) {
    if (f.type() == 0x0215 && f.payload.size() >= 16) {
      double tow = 0.0;
      std::memcpy(&tow, f.payload.data(), 8);  // little-endian host assumed (x86, ARM)
      const int week = f.payload[8] | (f.payload[9] << 8);
      receiveTime = GpsTime::fromWeekTow(week, tow);
    } else if (f.type() == 0x0120 && f.payload.size() >= 16) {
      const std::uint32_t itow = f.payload[0] | (f.payload[1] << 8) | (f.payload[2] << 16) |
                                 (static_cast<std::uint32_t>(f.payload[3]) << 24);
      const int week = f.payload[8] | (f.payload[9] << 8);
      receiveTime = GpsTime::fromWeekTow(week, itow * 1e-3);
    } else if (f.type() == 0x0213) {
      ++out.sfrbx;
      SfrbxMessage m = parseSfrbx(f.payload);
      if (mutate) mutate(m);
      NavDataUpdate u = out.assembler.add(m, receiveTime);
      out.kepler.insert(out.kepler.end(), u.kepler.begin(), u.kepler.end());
      out.glonass.insert(out.glonass.end(), u.glonass.begin(), u.glonass.end());
      if (!u.empty()) out.updates.push_back(std::move(u));
    }
  }
  return out;
}

}  // namespace gvins::ubx::testing
