#include "gvins/rtcm/framer.hpp"

#include <algorithm>
#include <cstring>

#include "gvins/rtcm/crc24q.hpp"

namespace gvins::rtcm {

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
    if (n - pos_ < 3) {  // need the header
      if (!eof_) return false;
      truncated();
      continue;
    }
    if ((p[1] & 0xFCu) != 0) {       // reserved bits must be zero (RTCM 10403.3, table 4-1)
      ++stats_.badHeaders;
      ++stats_.skippedBytes;
      ++pos_;
      continue;
    }
    const std::size_t len = (static_cast<std::size_t>(p[1] & 0x03u) << 8) | p[2];
    const std::size_t total = len + 6;
    if (n - pos_ < total) {  // wait for the rest
      if (!eof_) return false;
      truncated();
      continue;
    }
    const std::uint32_t crc = crc24q({p, len + 3});
    const std::uint32_t got = (static_cast<std::uint32_t>(p[len + 3]) << 16) |
                              (static_cast<std::uint32_t>(p[len + 4]) << 8) | p[len + 5];
    if (crc != got) {
      ++stats_.crcFailures;
      ++stats_.skippedBytes;
      ++pos_;
      continue;
    }
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
