// BeiDou D1 navigation message (MEO/IGSO, on B1I/B2I/B3I) subframes 1-3 from UBX-RXM-SFRBX, with
// the BCH(15,11,1) check (beidou_ephemeris.hpp). Not installed.
#pragma once

#include <array>
#include <optional>
#include <unordered_map>

#include "gvins/ubx/navigation_assembler.hpp"
#include "nav_bits.hpp"

namespace gvins::ubx::detail {

class BeidouD1Decoder {
 public:
  void add(const SfrbxMessage& msg, SatId sat, NavDataUpdate& out, NavigationCounts& counts);

 private:
  struct Partial {
    std::array<std::optional<NavBits>, 3> subframe;
    int lastAode = -1;
    std::uint32_t lastToc = 0xffffffff;
  };
  std::unordered_map<SatId, Partial> sats_;
};

}  // namespace gvins::ubx::detail
