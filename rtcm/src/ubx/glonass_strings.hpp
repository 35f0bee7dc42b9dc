// GLONASS L1/L2 OF navigation strings 1-4 (and N4 of string 5) from UBX-RXM-SFRBX with the
// Hamming (85,77) check; almanac strings are ignored. Not installed.
#pragma once

#include <array>
#include <optional>
#include <unordered_map>

#include "gvins/ubx/navigation_assembler.hpp"
#include "nav_bits.hpp"

namespace gvins::ubx::detail {

/// The 85 bits of a string (bit 85 of the ICD, the idle bit, first) when its check bits agree
/// (GLONASS ICD 5.1, 4.7); std::nullopt otherwise.
std::optional<NavBits> glonassString(const std::vector<std::uint32_t>& words);

class GlonassDecoder {
 public:
  void add(const SfrbxMessage& msg, SatId sat, const GpsTime& receiveTime, NavDataUpdate& out,
           NavigationCounts& counts);

 private:
  struct Partial {
    std::array<std::optional<NavBits>, 4> string;
    std::array<GpsTime, 4> received;
    int lastTb = -1;
    std::optional<int> n4;  // of the latest string 5
  };
  std::unordered_map<SatId, Partial> sats_;
};

}  // namespace gvins::ubx::detail
