#include "nav_bits.hpp"

namespace gvins::ubx::detail {

void NavBits::push(std::uint32_t v, int bits) {
  for (int k = bits - 1; k >= 0; --k, ++n_) {
    if (n_ >= kCapacity) return;
    if ((v >> k) & 1u) buf_[static_cast<std::size_t>(n_ >> 3)] |= static_cast<std::uint8_t>(0x80u >> (n_ & 7));
  }
}

std::uint32_t NavBits::u(int pos, int len) const {
  std::uint32_t v = 0;
  for (int k = pos; k < pos + len; ++k) {
    const bool bit = k >= 0 && k < kCapacity && ((buf_[static_cast<std::size_t>(k >> 3)] >> (7 - (k & 7))) & 1u);
    v = (v << 1) | (bit ? 1u : 0u);
  }
  return v;
}

std::int64_t NavBits::s(int pos, int len) const {
  const std::int64_t v = u(pos, len);
  const std::int64_t sign = std::int64_t{1} << (len - 1);
  return (v ^ sign) - sign;
}

std::int64_t NavBits::sm(int pos, int len) const {
  const std::int64_t v = u(pos, len);
  const std::int64_t sign = std::int64_t{1} << (len - 1);
  return (v & sign) ? -(v & (sign - 1)) : v;
}

}  // namespace gvins::ubx::detail
