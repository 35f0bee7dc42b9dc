// GPS and QZSS LNAV subframes 1-3 (ephemeris) and subframe 4 page 18 (Klobuchar) from
// UBX-RXM-SFRBX, with the IS-GPS-200 parity check. Not installed.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <unordered_map>

#include "gvins/ubx/navigation_assembler.hpp"
#include "nav_bits.hpp"

namespace gvins::ubx::detail {

/// IS-GPS-200 20.3.5.2 parity of ten 30-bit words as u-blox delivers them (data bits already
/// non-inverted). Returns the 240 data bits, or std::nullopt when any word fails its parity.
std::optional<NavBits> lnavDataBits(const std::vector<std::uint32_t>& words);

class GpsLnavDecoder {
 public:
  void add(const SfrbxMessage& msg, SatId sat, const GpsTime& receiveTime, NavDataUpdate& out,
           NavigationCounts& counts);

 private:
  struct Partial {
    std::array<std::optional<NavBits>, 3> subframe;  // subframes 1-3, data bits only
    int lastIodc = -1;                               // of the last record emitted
    std::uint32_t lastToe = 0xffffffff;
  };
  std::unordered_map<SatId, Partial> sats_;
};

}  // namespace gvins::ubx::detail
