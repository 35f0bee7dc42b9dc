// u-blox UBX transport layer (u-blox F9 HPG 1.32 / X20 HPG 2.00 interface descriptions, section
// "UBX protocol / UBX frame structure"): finds frames in a byte stream fed in chunks of any size.
//
// A frame is: sync chars 0xB5 0x62, message class (1 byte), message id (1 byte), payload length
// (2 bytes, little-endian), the payload, and an 8-bit Fletcher checksum CK_A CK_B computed over
// class, id, length and payload. The framer checks all of it; on a length above the limit or a
// checksum failure it drops one byte and searches for the next sync pair, so garbage, truncated
// and corrupted frames cost at most the bytes they occupy. Memory is bounded (one maximum-size
// frame plus the caller's last chunk). The design mirrors gvins::rtcm::Framer.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace gvins::ubx {

/// One frame whose checksum checked. `payload` points into the framer's buffer and stays valid
/// until the next call of feed() or finish().
struct Frame {
  std::uint8_t msgClass = 0;
  std::uint8_t msgId = 0;
  std::span<const std::uint8_t> payload;  ///< message bytes, without header and checksum
  std::int64_t offset = 0;                ///< byte offset of the first sync char in the stream
  /// Class and id as one number (class << 8 | id), e.g. 0x0215 for RXM-RAWX.
  int type() const { return (msgClass << 8) | msgId; }
  /// Bytes the frame occupies in the stream (payload + 8).
  std::size_t size() const { return payload.size() + 8; }
};

struct FramerStats {
  std::int64_t bytes = 0;             ///< bytes fed
  std::int64_t frames = 0;            ///< frames with a good checksum
  std::int64_t checksumFailures = 0;  ///< candidate frames (sane length) whose checksum failed
  std::int64_t oversizeLengths = 0;   ///< sync pairs followed by a length above the limit
  std::int64_t skippedBytes = 0;      ///< bytes outside good frames (garbage, corrupted frames)
  std::int64_t truncatedFrames = 0;   ///< frame started but stream ended before its end
};

/// Outcome of checking the bytes at one position for a UBX frame.
enum class FrameCheck {
  NotSync,      ///< the bytes do not start with 0xB5 0x62
  NeedMore,     ///< a frame may start here but more bytes are needed to tell
  Oversize,     ///< length field above the limit
  BadChecksum,  ///< complete candidate whose checksum failed
  Good,         ///< a complete frame; `size` holds its length in bytes
};

/// Checks whether `bytes` starts with a complete UBX frame whose payload is at most `maxPayload`
/// bytes. On Good, `size` is the frame length (payload + 8). Shared by the Framer and the
/// mixed-stream splitter.
FrameCheck checkFrame(std::span<const std::uint8_t> bytes, std::size_t maxPayload,
                      std::size_t& size);

/// 8-bit Fletcher checksum of the UBX protocol over `data` (class, id, length and payload):
/// CK_A += byte, CK_B += CK_A, both modulo 256. Returns CK_A | CK_B << 8.
std::uint16_t fletcher8(std::span<const std::uint8_t> data);

class Framer {
 public:
  static constexpr std::uint8_t kSync1 = 0xB5;
  static constexpr std::uint8_t kSync2 = 0x62;
  /// Default payload limit: a RXM-RAWX with the maximum 255 measurements has 16 + 32 * 255 =
  /// 8176 bytes, the largest message a receiver streams in normal operation.
  static constexpr std::size_t kDefaultMaxPayload = 8192;

  explicit Framer(std::size_t maxPayload = kDefaultMaxPayload) : maxPayload_(maxPayload) {}

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
  std::size_t maxPayload() const { return maxPayload_; }
  /// Stream offset of the next byte the framer will examine.
  std::int64_t position() const { return base_ + static_cast<std::int64_t>(pos_); }

 private:
  void skipOne();
  std::size_t maxPayload_;
  std::vector<std::uint8_t> buf_;
  std::size_t pos_ = 0;    // first unexamined byte in buf_
  std::int64_t base_ = 0;  // stream offset of buf_[0]
  bool eof_ = false;
  bool truncatedCounted_ = false;
  FramerStats stats_;
};

}  // namespace gvins::ubx
