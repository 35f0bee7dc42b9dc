// libFuzzer target: the RTCM 3 decoder. Input byte 0 selects the mode: even = a byte stream (CRC
// checked, so mostly framing and resynchronisation), odd = one message payload handed straight
// to the message decoders (past the CRC gate). Bit 1 selects strict mode (ParseError expected),
// the next bits the chunk size. Nothing may crash, hang or leak; malformed content must surface
// as a recorded issue or a ParseError (naming the stream, byte offset and field) only.
#include <cstdint>
#include <cstdlib>

#include "gvins/base/parse_error.hpp"
#include "gvins/rtcm/decoder.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::uint8_t mode = data[0];
  gvins::rtcm::DecoderOptions opt;
  opt.referenceTime = gvins::GpsTime::fromWeekTow(2100, 302400.0);
  opt.strict = (mode & 2) != 0;
  gvins::rtcm::Decoder dec(opt);
  try {
    if (mode & 1) {
      dec.decodeMessage({data + 1, size - 1}, 0);
      // Twice, so that state from the first (tracks, ranges, open epoch) is exercised.
      dec.decodeMessage({data + 1, size - 1}, 0);
    } else {
      const std::size_t chunk = (static_cast<std::size_t>(mode >> 2) + 1) * 3;
      for (std::size_t i = 1; i < size; i += chunk) {
        dec.feed({data + i, std::min(chunk, size - i)});
        while (dec.poll()) {
        }
      }
    }
    dec.finish();
    while (dec.poll()) {
    }
  } catch (const gvins::ParseError& e) {
    if (!opt.strict) std::abort();  // only strict mode may throw
    // The error names the stream, the frame's byte offset and the field.
    if (e.file() != opt.streamName || e.line() < 0 || e.line() >= static_cast<std::int64_t>(size) ||
        e.field().empty())
      std::abort();
  }
  if (dec.stats().issues.size() > opt.maxIssues) std::abort();
  for (const gvins::rtcm::DecodeIssue& i : dec.stats().issues) {
    if (i.field.empty() || i.what.empty() || i.offset < 0 || i.offset >= static_cast<std::int64_t>(size)) std::abort();
  }
  return 0;
}
