#include "gvins/rtcm/framer.hpp"

#include <algorithm>
#include <cstring>

#include "gvins/rtcm/crc24q.hpp"

namespace gvins::rtcm {

FrameCheck checkFrame(std::span<const std::uint8_t> bytes, std::size_t& size) {
  const std::size_t n = bytes.size();
  if (n == 0 || bytes[0] != Framer::kPreamble) return FrameCheck::NotPreamble;
  if (n < 3) return FrameCheck::NeedMore;  // need the header
  // Reserved bits must be zero (RTCM 10403.3, table 4-1).
  if ((bytes[1] & 0xFCu) != 0) return FrameCheck::BadHeader;
  const std::size_t len = (static_cast<std::size_t>(bytes[1] & 0x03u) << 8) | bytes[2];
  const std::size_t total = len + 6;
  if (n < total) return FrameCheck::NeedMore;  // wait for the rest
  const std::uint32_t crc = crc24q(bytes.first(len + 3));
  const std::uint32_t got = (static_cast<std::uint32_t>(bytes[len + 3]) << 16) |
                            (static_cast<std::uint32_t>(bytes[len + 4]) << 8) | bytes[len + 5];
  if (crc != got) return FrameCheck::BadCrc;
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
    if (p[0] != kPreamble) {
      // Skip quickly to the next preamble candidate.
      const void* hit = std::memchr(p, kPreamble, n - pos_);
      const std::size_t next = hit ? static_cast<std::size_t>(static_cast<const std::uint8_t*>(hit) -
                                                               buf_.data())
                                   : n;
      stats_.skippedBytes += static_cast<std::int64_t>(next - pos_);
      pos_ = next;
      continue;
    }
    std::size_t total = 0;
    switch (checkFrame({p, n - pos_}, total)) {
      case FrameCheck::NotPreamble:  // not reached: p[0] is the preamble
      case FrameCheck::NeedMore:
        if (!eof_) return false;
        truncated();
        continue;
      case FrameCheck::BadHeader:
        ++stats_.badHeaders;
        ++stats_.skippedBytes;
        ++pos_;
        continue;
      case FrameCheck::BadCrc:
        ++stats_.crcFailures;
        ++stats_.skippedBytes;
        ++pos_;
        continue;
      case FrameCheck::Good:
        break;
    }
    const std::size_t len = total - 6;
    frame.payload = {p + 3, len};
    frame.offset = base_ + static_cast<std::int64_t>(pos_);
    pos_ += total;
    ++stats_.frames;
    return true;
  }
  return false;
}

void Framer::truncated() {
  // Only the first incomplete candidate of a stream end is a truncated frame: every later
  // candidate lies inside it.
  if (!truncatedCounted_) ++stats_.truncatedFrames;
  truncatedCounted_ = true;
  ++stats_.skippedBytes;
  ++pos_;
}

}  // namespace gvins::rtcm
