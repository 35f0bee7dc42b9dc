// BeiDou D2 navigation message (GEO satellites C01-C05, C59-C63, on B1I/B2I/B3I): the ephemeris
// of subframe 1 pages 1-10 from UBX-RXM-SFRBX, with the BCH(15,11,1) check (beidou_ephemeris.hpp).
// Subframes 2-5 (integrity, differential corrections, almanac) are not decoded. Not installed.
#pragma once

#include <array>
#include <optional>
#include <unordered_map>

#include "gvins/ubx/navigation_assembler.hpp"
#include "nav_bits.hpp"

namespace gvins::ubx::detail {

class BeidouD2Decoder {
 public:
  void add(const SfrbxMessage& msg, SatId sat, NavDataUpdate& out, NavigationCounts& counts);

 private:
  struct Partial {
    std::array<std::optional<NavBits>, 10> page;  ///< subframe 1 pages 1-10
    int lastAode = -1;
    std::uint32_t lastToc = 0xffffffff;
  };
  void emit(Partial& p, SatId sat, NavDataUpdate& out, NavigationCounts& counts);
  std::unordered_map<SatId, Partial> sats_;
};

}  // namespace gvins::ubx::detail
