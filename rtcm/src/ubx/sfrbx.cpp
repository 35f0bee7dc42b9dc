#include "gvins/ubx/sfrbx.hpp"

#include <string>

#include "gvins/ubx/sfrbx_error.hpp"

namespace gvins::ubx {

SfrbxMessage parseSfrbx(std::span<const std::uint8_t> payload) {
  // Header layout: u-blox F9 interface description, UBX-RXM-SFRBX (8 bytes, then numWords U4).
  if (payload.size() < 8) {
    throw SfrbxError("length", "payload of " + std::to_string(payload.size()) + " bytes is shorter than the 8-byte header");
  }
  SfrbxMessage m;
  m.gnssId = payload[0];
  m.svId = payload[1];
  m.sigId = payload[2];
  m.freqId = payload[3];
  const std::size_t numWords = payload[4];
  m.channel = payload[5];
  m.version = payload[6];
  if (m.version != 1 && m.version != 2) {
    throw SfrbxError("version", "message version " + std::to_string(m.version) + " is not 1 or 2");
  }
  if (payload.size() != 8 + 4 * numWords) {
    throw SfrbxError("numWords", std::to_string(numWords) + " words need " + std::to_string(8 + 4 * numWords) +
                                     " bytes, the payload has " + std::to_string(payload.size()));
  }
  m.words.resize(numWords);
  for (std::size_t k = 0; k < numWords; ++k) {
    const std::uint8_t* p = payload.data() + 8 + 4 * k;  // little-endian U4
    m.words[k] = static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
                 (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
  }
  return m;
}

}  // namespace gvins::ubx
