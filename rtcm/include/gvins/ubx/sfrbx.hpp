// u-blox UBX-RXM-SFRBX (class 0x02, id 0x13): one broadcast navigation subframe, page or string
// as the receiver demodulated it (u-blox F9 HPG 1.32 interface description, UBX-RXM-SFRBX).
// Payload: gnssId U1, svId U1, sigId U1 (reserved in protocol < 27), freqId U1 (GLONASS channel
// + 7), numWords U1, chn U1, version U1 (0x02), reserved U1, then numWords little-endian U4 words.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace gvins::ubx {

/// u-blox gnssId values (interface description, "GNSS identifiers").
enum class UbxGnss : std::uint8_t { Gps = 0, Sbas = 1, Galileo = 2, BeiDou = 3, Imes = 4, Qzss = 5, Glonass = 6, Navic = 7 };

struct SfrbxMessage {
  std::uint8_t gnssId = 0, svId = 0, sigId = 0, freqId = 0;
  std::vector<std::uint32_t> words;  ///< the data words as received (host order)
  std::uint8_t channel = 0;          ///< chn: tracking channel
  std::uint8_t version = 0;          ///< message version (0x02 for the documented layout)
};

/// Parses an SFRBX payload (without UBX header and checksum). Throws gvins::ubx::SfrbxError naming
/// the field: a payload shorter than the 8-byte header ("length"), numWords that disagree with the
/// payload length ("numWords"), a version other than 1 or 2 ("version").
SfrbxMessage parseSfrbx(std::span<const std::uint8_t> payload);

}  // namespace gvins::ubx
