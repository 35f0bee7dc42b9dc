// Splits a byte stream that mixes UBX, RTCM 3 and NMEA 0183 (as a u-blox receiver's port or log
// does) into whole frames of each kind, telling them apart by content:
//   UBX:  0xB5 0x62, class, id, length, payload, Fletcher checksum (gvins::ubx::checkFrame);
//   RTCM: 0xD3, zero reserved bits, length, message, CRC-24Q (gvins::rtcm::checkFrame);
//   NMEA: '$', printable ASCII, '*', two hex digits of the XOR of the characters between '$' and
//         '*' (NMEA 0183 v4.11, 5.2.1), then CR LF (included in the frame when present).
// Anything else, and candidates whose check fails, is skipped one byte at a time so that the
// next frame is found (resynchronisation). Fed in chunks of any size; memory is bounded by one
// maximum-size frame plus the caller's last chunk.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "gvins/ubx/ubx_framer.hpp"

namespace gvins::ubx {

enum class StreamKind : std::uint8_t { Ubx, Rtcm, Nmea };

/// One whole frame of a mixed stream. `bytes` (header and checksum included) points into the
/// splitter's buffer and stays valid until the next feed() or finish().
struct StreamFrame {
  StreamKind kind = StreamKind::Ubx;
  std::span<const std::uint8_t> bytes;
  std::int64_t offset = 0;  ///< byte offset of the first byte in the stream
  /// The UBX frame (class, id, payload); only for kind == Ubx.
  Frame ubx() const;
  /// The RTCM message (without header and CRC); only for kind == Rtcm.
  std::span<const std::uint8_t> rtcmPayload() const { return bytes.subspan(3, bytes.size() - 6); }
};

struct SplitterStats {
  std::int64_t bytes = 0;
  std::int64_t ubxFrames = 0, rtcmFrames = 0, nmeaSentences = 0;
  std::int64_t ubxChecksumFailures = 0;  ///< complete UBX candidates with a wrong checksum
  std::int64_t ubxOversize = 0;          ///< UBX sync pairs followed by a length above the limit
  std::int64_t rtcmCrcFailures = 0;      ///< complete RTCM candidates with a wrong CRC
  std::int64_t nmeaChecksumFailures = 0; ///< '$...*hh' whose checksum is wrong
  std::int64_t skippedBytes = 0;         ///< bytes outside good frames
  std::int64_t truncatedFrames = 0;      ///< a frame started but the stream ended first
};

class StreamSplitter {
 public:
  /// Longest NMEA sentence accepted (the standard's 82 characters, with room for proprietary
  /// sentences such as u-blox PUBX).
  static constexpr std::size_t kMaxNmea = 256;

  explicit StreamSplitter(std::size_t maxUbxPayload = Framer::kDefaultMaxPayload)
      : maxUbxPayload_(maxUbxPayload) {}

  void feed(std::span<const std::uint8_t> bytes);
  /// Extracts the next good frame of any kind; false when more bytes are needed.
  bool next(StreamFrame& frame);
  /// End of stream, as rtcm::Framer::finish().
  void finish() { eof_ = true; }
  const SplitterStats& stats() const { return stats_; }

 private:
  enum class Check { NotStart, NeedMore, Bad, BadChecksum, Good };
  Check checkNmea(std::span<const std::uint8_t> bytes, std::size_t& size) const;
  void skipOne();
  std::size_t maxUbxPayload_;
  std::vector<std::uint8_t> buf_;
  std::size_t pos_ = 0;
  std::int64_t base_ = 0;
  bool eof_ = false;
  bool truncatedCounted_ = false;
  SplitterStats stats_;
};

}  // namespace gvins::ubx
