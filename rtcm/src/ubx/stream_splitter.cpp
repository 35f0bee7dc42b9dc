#include "gvins/ubx/stream_splitter.hpp"

#include "gvins/rtcm/framer.hpp"

namespace gvins::ubx {

namespace {

int hexValue(std::uint8_t c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}

bool isStart(std::uint8_t c) { return c == Framer::kSync1 || c == rtcm::Framer::kPreamble || c == '$'; }

}  // namespace

Frame StreamFrame::ubx() const {
  Frame f;
  f.msgClass = bytes[2];
  f.msgId = bytes[3];
  f.payload = bytes.subspan(6, bytes.size() - 8);
  f.offset = offset;
  return f;
}

void StreamSplitter::feed(std::span<const std::uint8_t> bytes) {
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

StreamSplitter::Check StreamSplitter::checkNmea(std::span<const std::uint8_t> b, std::size_t& size) const {
  // NMEA 0183: '$', address and fields of printable ASCII (0x20..0x7E), '*', two hex digits.
  std::uint8_t sum = 0;
  for (std::size_t i = 1; i < b.size(); ++i) {
    const std::uint8_t c = b[i];
    if (c == '*') {
      if (i < 6) return Check::Bad;  // shorter than "$GPxxx"
      if (i + 3 > b.size()) return Check::NeedMore;
      const int hi = hexValue(b[i + 1]), lo = hexValue(b[i + 2]);
      if (hi < 0 || lo < 0) return Check::Bad;
      if (((hi << 4) | lo) != sum) return Check::BadChecksum;
      // Take the CR LF terminator along when it is there (wait for it unless the stream ended).
      std::size_t end = i + 3;
      if (end == b.size() && !eof_) return Check::NeedMore;
      if (end < b.size() && b[end] == '\r') {
        ++end;
        if (end == b.size() && !eof_) return Check::NeedMore;
        if (end < b.size() && b[end] == '\n') ++end;
      }
      size = end;
      return Check::Good;
    }
    if (c < 0x20 || c > 0x7E || c == '$' || i >= kMaxNmea) return Check::Bad;
    sum ^= c;
  }
  return Check::NeedMore;
}

bool StreamSplitter::next(StreamFrame& frame) {
  const std::size_t n = buf_.size();
  while (pos_ < n) {
    const std::uint8_t* p = buf_.data() + pos_;
    if (!isStart(p[0])) {
      std::size_t next = pos_ + 1;
      while (next < n && !isStart(buf_[next])) ++next;
      stats_.skippedBytes += static_cast<std::int64_t>(next - pos_);
      pos_ = next;
      continue;
    }
    const std::span<const std::uint8_t> rest(p, n - pos_);
    std::size_t size = 0;
    Check c = Check::NotStart;
    StreamKind kind = StreamKind::Ubx;
    if (p[0] == Framer::kSync1) {
      switch (checkFrame(rest, maxUbxPayload_, size)) {
        case FrameCheck::NotSync: c = Check::NotStart; break;
        case FrameCheck::NeedMore: c = Check::NeedMore; break;
        case FrameCheck::Oversize: ++stats_.ubxOversize; c = Check::Bad; break;
        case FrameCheck::BadChecksum: ++stats_.ubxChecksumFailures; c = Check::Bad; break;
        case FrameCheck::Good: c = Check::Good; break;
      }
    } else if (p[0] == rtcm::Framer::kPreamble) {
      kind = StreamKind::Rtcm;
      switch (rtcm::checkFrame(rest, size)) {
        case rtcm::FrameCheck::NotPreamble:
        case rtcm::FrameCheck::BadHeader: c = Check::NotStart; break;
        case rtcm::FrameCheck::NeedMore: c = Check::NeedMore; break;
        case rtcm::FrameCheck::BadCrc: ++stats_.rtcmCrcFailures; c = Check::Bad; break;
        case rtcm::FrameCheck::Good: c = Check::Good; break;
      }
    } else {
      kind = StreamKind::Nmea;
      c = checkNmea(rest, size);
      if (c == Check::BadChecksum) ++stats_.nmeaChecksumFailures;
    }
    if (c == Check::NeedMore) {
      if (!eof_) return false;
      if (!truncatedCounted_) ++stats_.truncatedFrames;
      truncatedCounted_ = true;
      skipOne();
      continue;
    }
    if (c != Check::Good) {
      skipOne();
      continue;
    }
    frame.kind = kind;
    frame.bytes = rest.first(size);
    frame.offset = base_ + static_cast<std::int64_t>(pos_);
    pos_ += size;
    switch (kind) {
      case StreamKind::Ubx: ++stats_.ubxFrames; break;
      case StreamKind::Rtcm: ++stats_.rtcmFrames; break;
      case StreamKind::Nmea: ++stats_.nmeaSentences; break;
    }
    return true;
  }
  return false;
}

void StreamSplitter::skipOne() {
  ++stats_.skippedBytes;
  ++pos_;
}

}  // namespace gvins::ubx
