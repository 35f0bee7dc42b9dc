// RTCM 3 transport layer (RTCM 10403.3, section 4): finds frames in a byte stream fed in chunks of
// any size (file reads, pipe reads, socket receives alike).
//
// A frame is: preamble 0xD3, 6 reserved bits (0), 10-bit message length N (0..1023), N message
// bytes, 24-bit CRC-24Q over everything before it. The framer checks all of it; on a bad header
// or a CRC failure it drops one byte and searches for the next preamble, so garbage, truncated
// frames and corrupted frames cost at most the bytes they occupy. Memory is bounded (one
// maximum-size frame plus the caller's last chunk).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace gvins::rtcm {

/// One frame whose CRC checked. `payload` points into the framer's buffer and stays valid until
/// the next call of feed() or finish().
struct Frame {
  std::span<const std::uint8_t> payload;  ///< message bytes, without header and CRC
  std::int64_t offset = 0;                ///< byte offset of the preamble in the stream
  /// Message number (DF002, the first 12 bits), or -1 for a frame shorter than 2 bytes.
  int type() const {
    return payload.size() < 2 ? -1 : (payload[0] << 4) | (payload[1] >> 4);
  }
  /// Bytes the frame occupies in the stream (payload + 6).
  std::size_t size() const { return payload.size() + 6; }
};

struct FramerStats {
  std::int64_t bytes = 0;           ///< bytes fed
  std::int64_t frames = 0;          ///< frames with a good CRC
  std::int64_t crcFailures = 0;     ///< candidate frames (good header) whose CRC failed
  std::int64_t badHeaders = 0;      ///< preamble bytes followed by non-zero reserved bits
  std::int64_t skippedBytes = 0;    ///< bytes outside good frames (garbage, corrupted frames)
  std::int64_t truncatedFrames = 0; ///< frame started but stream ended before its end
};

/// Outcome of checking the bytes at one position for an RTCM frame.
enum class FrameCheck {
  NotPreamble,  ///< the first byte is not 0xD3
  NeedMore,     ///< a frame may start here but more bytes are needed to tell
  BadHeader,    ///< reserved bits not zero
  BadCrc,       ///< complete candidate whose CRC failed
  Good,         ///< a complete frame; `size` holds its length in bytes (payload + 6)
};

/// Checks whether `bytes` starts with a complete RTCM frame. Shared by the Framer and the mixed
/// UBX/RTCM/NMEA stream splitter (gvins/ubx/stream_splitter.hpp).
FrameCheck checkFrame(std::span<const std::uint8_t> bytes, std::size_t& size);

class Framer {
 public:
  static constexpr std::uint8_t kPreamble = 0xD3;
  static constexpr std::size_t kMaxPayload = 1023;

  /// Appends bytes to the internal buffer. Frames returned by next() before are invalidated.
  void feed(std::span<const std::uint8_t> bytes);
  /// Extracts the next good frame; false when more bytes are needed.
  bool next(Frame& frame);
  /// Marks the end of the stream: next() then gives up waiting for incomplete frames (the first
  /// one counts as truncated), keeps searching the remaining bytes for complete frames, and
  /// counts what is left as skipped. Call next() until it returns false after finish(). Feeding
  /// again starts a new stream whose offsets continue.
  void finish() { eof_ = true; }

  const FramerStats& stats() const { return stats_; }
  /// Stream offset of the next byte the framer will examine.
  std::int64_t position() const { return base_ + static_cast<std::int64_t>(pos_); }

 private:
  void truncated();
  std::vector<std::uint8_t> buf_;
  std::size_t pos_ = 0;      // first unexamined byte in buf_
  std::int64_t base_ = 0;    // stream offset of buf_[0]
  bool eof_ = false;
  bool truncatedCounted_ = false;
  FramerStats stats_;
};

}  // namespace gvins::rtcm
