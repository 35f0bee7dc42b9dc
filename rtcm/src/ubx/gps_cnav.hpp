// GPS and QZSS CNAV messages (L2C and L5) from UBX-RXM-SFRBX: the CRC-24Q check of every message
// and the group delays, inter-signal corrections and clock of message type 30. Not installed.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "gvins/ubx/navigation_assembler.hpp"
#include "nav_bits.hpp"

namespace gvins::ubx::detail {

/// The 300 bits of a CNAV message as u-blox delivers them in RXM-SFRBX: ten words, each holding
/// 32 message bits most significant bit first, the last word 12 (its 20 low bits are padding).
/// With crcOk whether the CRC-24Q (IS-GPS-200N 30.3.5: over bits 1-276, parity in bits 277-300)
/// holds. std::nullopt unless there are ten words.
struct CnavMessage {
  NavBits bits;
  bool crcOk = false;
};
std::optional<CnavMessage> cnavMessage(const std::vector<std::uint32_t>& words);

/// Decodes message type 30 (IS-GPS-200N figure 30-3, IS-GPS-705J figure 20-3) into
/// CnavGroupDelays. `time` is the message's end (its TOW count) as a GPST instant.
CnavGroupDelays cnavType30(const NavBits& bits, SatId sat, const GpsTime& time);

class GpsCnavDecoder {
 public:
  void add(const SfrbxMessage& msg, SatId sat, const GpsTime& receiveTime, NavDataUpdate& out,
           NavigationCounts& counts);

 private:
  struct Undated {
    NavBits bits;
    SatId sat;
    double tow = 0.0;  // s of week at the message's end
  };
  // Messages type 30 seen before any receive time (the latest per satellite): dated by their TOW
  // once a time is known.
  std::vector<Undated> undated_;
};

}  // namespace gvins::ubx::detail
