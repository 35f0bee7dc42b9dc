#include "gvins/ubx/ubx_framer.hpp"

#include <cstring>

namespace gvins::ubx {

std::uint16_t fletcher8(std::span<const std::uint8_t> data) {
  // u-blox interface description, "UBX checksum": 8-bit Fletcher algorithm (RFC 1145).
  std::uint8_t a = 0, b = 0;
  for (const std::uint8_t v : data) {
    a = static_cast<std::uint8_t>(a + v);
    b = static_cast<std::uint8_t>(b + a);
  }
  return static_cast<std::uint16_t>(a | (b << 8));
}

FrameCheck checkFrame(std::span<const std::uint8_t> bytes, std::size_t maxPayload,
                      std::size_t& size) {
  const std::size_t n = bytes.size();
  if (n == 0 || bytes[0] != Framer::kSync1) return FrameCheck::NotSync;
  if (n < 2) return FrameCheck::NeedMore;
  if (bytes[1] != Framer::kSync2) return FrameCheck::NotSync;
  if (n < 6) return FrameCheck::NeedMore;
  const std::size_t len = bytes[4] | (static_cast<std::size_t>(bytes[5]) << 8);
  if (len > maxPayload) return FrameCheck::Oversize;
  const std::size_t total = len + 8;
  if (n < total) return FrameCheck::NeedMore;
  const std::uint16_t ck = fletcher8(bytes.subspan(2, len + 4));
  if ((ck & 0xFFu) != bytes[len + 6] || (ck >> 8) != bytes[len + 7]) {
    return FrameCheck::BadChecksum;
  }
  size = total;
  return FrameCheck::Good;
}

void Framer::feed(std::span<const std::uint8_t> bytes) {
  // Drop consumed bytes first so that the buffer never holds more than one partial frame plus
  // this chunk.
  if (pos_ > 0) {
    buf_.erase(buf_.begin(), buf_.begin() + static_cast<std::ptrdiff_t>(pos_));
    base_ += static_cast<std::int64_t>(pos_);
    pos_ = 0;
  }
  eof_ = false;
  truncatedCounted_ = false;
  buf_.insert(buf_.end(), bytes.begin(), bytes.end());
  stats_.bytes += static_cast<std::int64_t>(bytes.size());
}

bool Framer::next(Frame& frame) {
  const std::size_t n = buf_.size();
  while (pos_ < n) {
    const std::uint8_t* p = buf_.data() + pos_;
    if (p[0] != kSync1) {
      // Skip quickly to the next sync candidate.
      const void* hit = std::memchr(p, kSync1, n - pos_);
      const std::size_t next =
          hit ? static_cast<std::size_t>(static_cast<const std::uint8_t*>(hit) - buf_.data()) : n;
      stats_.skippedBytes += static_cast<std::int64_t>(next - pos_);
      pos_ = next;
      continue;
    }
    std::size_t total = 0;
    switch (checkFrame({p, n - pos_}, maxPayload_, total)) {
      case FrameCheck::NotSync:
        skipOne();
        continue;
      case FrameCheck::NeedMore:
        if (!eof_) return false;
        // Only the first incomplete candidate of a stream end is a truncated frame: every later
        // candidate lies inside it.
        if (!truncatedCounted_) ++stats_.truncatedFrames;
        truncatedCounted_ = true;
        skipOne();
        continue;
      case FrameCheck::Oversize:
        ++stats_.oversizeLengths;
        skipOne();
        continue;
      case FrameCheck::BadChecksum:
        ++stats_.checksumFailures;
        skipOne();
        continue;
      case FrameCheck::Good:
        break;
    }
    frame.msgClass = p[2];
    frame.msgId = p[3];
    frame.payload = {p + 6, total - 8};
    frame.offset = base_ + static_cast<std::int64_t>(pos_);
    pos_ += total;
    ++stats_.frames;
    return true;
  }
  return false;
}

void Framer::skipOne() {
  ++stats_.skippedBytes;
  ++pos_;
}

}  // namespace gvins::ubx
