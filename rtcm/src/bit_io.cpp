#include <string>

#include "gvins/rtcm/bit_reader.hpp"
#include "gvins/rtcm/bit_writer.hpp"

namespace gvins::rtcm {

void BitReader::need(std::size_t bits, const char* field) const {
  if (bits > bits_ - pos_) {
    throw MessageError(field, "message too short: needs " + std::to_string(pos_ + bits) +
                                  " bits, has " + std::to_string(bits_));
  }
}

void BitWriter::put(int bits, std::uint64_t v) {
  for (int k = bits - 1; k >= 0; --k) {
    if ((bits_ & 7) == 0) buf_.push_back(0);
    // A field wider than 64 bits (e.g. a zero-filled block) has zeros above bit 63.
    if (k < 64 && ((v >> k) & 1u)) buf_.back() |= static_cast<std::uint8_t>(0x80u >> (bits_ & 7));
    ++bits_;
  }
}

void BitWriter::u(int bits, std::uint64_t v, const char* field) {
  if (bits < 64 && (v >> bits) != 0) {
    throw MessageError(field, "value " + std::to_string(v) + " does not fit " +
                                  std::to_string(bits) + " bits");
  }
  put(bits, v);
}

void BitWriter::s(int bits, std::int64_t v, const char* field) {
  const std::int64_t lim = std::int64_t{1} << (bits - 1);
  if (bits < 64 && (v < -lim || v >= lim)) {
    throw MessageError(field, "value " + std::to_string(v) + " does not fit a signed " +
                                  std::to_string(bits) + "-bit field");
  }
  put(bits, static_cast<std::uint64_t>(v) & (bits == 64 ? ~0ull : ((1ull << bits) - 1)));
}

void BitWriter::sm(int bits, std::int64_t v, const char* field) {
  const std::int64_t lim = std::int64_t{1} << (bits - 1);
  const std::int64_t mag = v < 0 ? -v : v;
  if (mag >= lim) {
    throw MessageError(field, "value " + std::to_string(v) + " does not fit a sign-magnitude " +
                                  std::to_string(bits) + "-bit field");
  }
  put(1, v < 0 ? 1u : 0u);
  put(bits - 1, static_cast<std::uint64_t>(mag));
}

}  // namespace gvins::rtcm
