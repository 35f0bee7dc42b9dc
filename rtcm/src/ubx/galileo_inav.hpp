// Galileo I/NAV (E1-B and E5b-I) nominal page pairs from UBX-RXM-SFRBX: CRC-24Q check, word types
// 1-5 into an ephemeris, NeQuick coefficients from word type 5. Not installed.
#pragma once

#include <array>
#include <optional>
#include <unordered_map>

#include "gvins/ubx/navigation_assembler.hpp"
#include "nav_bits.hpp"

namespace gvins::ubx::detail {

/// The 128-bit word of an I/NAV even/odd page pair delivered as eight 32-bit words (even part in
/// words 0-3, odd part in words 4-7, each 120 bits left-aligned; a ninth word is padding). std::nullopt when the layout is
/// not an even-odd nominal pair; `crcOk` false when the CRC-24Q over the pair fails.
struct InavWord {
  NavBits data;  // 128 bits: word type (6) first
  bool crcOk = false;
};
std::optional<InavWord> inavWord(const std::vector<std::uint32_t>& words);

class GalileoInavDecoder {
 public:
  void add(const SfrbxMessage& msg, SatId sat, const GpsTime& receiveTime, NavDataUpdate& out,
           NavigationCounts& counts);

 private:
  struct Partial {
    std::array<std::optional<NavBits>, 5> word;  // word types 1-5
    std::array<bool, 5> fromE5b{};               // the word came from E5b-I (else E1-B)
    int lastIod = -1;
    std::uint32_t lastToe = 0xffffffff;
  };
  std::unordered_map<SatId, Partial> sats_;
};

}  // namespace gvins::ubx::detail
