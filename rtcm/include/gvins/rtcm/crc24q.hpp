// CRC-24Q, the parity of every RTCM 3 frame (RTCM 10403.3, section 4.2): generator polynomial
// 0x1864CFB, initial value 0, no reflection, no final XOR, computed over preamble, header and
// message.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

namespace gvins::rtcm {

/// CRC-24Q of `data`, continuing from `crc` (0 for a new computation). Table driven.
std::uint32_t crc24q(std::span<const std::uint8_t> data, std::uint32_t crc = 0);

}  // namespace gvins::rtcm
