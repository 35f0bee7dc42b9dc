// BeiDou D1 navigation message (MEO/IGSO, on B1I/B2I/B3I) subframes 1-3 from UBX-RXM-SFRBX, with
// the BCH(15,11,1) check. D2 (GEO) pages are counted as unknown. Not installed.
#pragma once

#include <array>
#include <optional>
#include <unordered_map>

#include "gvins/ubx/navigation_assembler.hpp"
#include "nav_bits.hpp"

namespace gvins::ubx::detail {

/// The 224 information bits of a D1/D2 subframe (26 of word 1, 22 of each further word) after the
/// BCH(15,11,1) check of BDS-SIS-ICD-B1I 3.0, 5.1.3; std::nullopt when a code word fails.
std::optional<NavBits> beidouInfoBits(const std::vector<std::uint32_t>& words);

class BeidouD1Decoder {
 public:
  void add(const SfrbxMessage& msg, SatId sat, const GpsTime& receiveTime, NavDataUpdate& out,
           NavigationCounts& counts);

 private:
  struct Partial {
    std::array<std::optional<NavBits>, 3> subframe;
    int lastAode = -1;
    std::uint32_t lastToc = 0xffffffff;
  };
  std::unordered_map<SatId, Partial> sats_;
};

}  // namespace gvins::ubx::detail
