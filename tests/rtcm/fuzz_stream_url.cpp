// libFuzzer target: stream path parsing (stream_url.hpp) on arbitrary text. Only StreamError may
// come out; a parsed path must display and parse again to the same kind.
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "gvins/rtcm/stream_url.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const auto u = gvins::rtcm::StreamUrl::parse(text);
    if (u.type != gvins::rtcm::StreamType::Ntrip && gvins::rtcm::StreamUrl::parse(u.display()).type != u.type) std::abort();
  } catch (const gvins::rtcm::StreamError&) {
  }
  return 0;
}
