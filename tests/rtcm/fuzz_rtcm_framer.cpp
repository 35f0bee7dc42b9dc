// libFuzzer target: the RTCM 3 framer on arbitrary bytes fed in arbitrary chunks. Every frame it
// returns must carry a valid CRC and lie inside the input; the counters must add up.
#include <cstdint>
#include <cstdlib>
#include <vector>

#include "gvins/rtcm/crc24q.hpp"
#include "gvins/rtcm/framer.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  // The first byte chooses the chunk size (1..256) so that chunk boundaries fall everywhere.
  const std::size_t chunk = static_cast<std::size_t>(data[0]) + 1;
  gvins::rtcm::Framer f;
  gvins::rtcm::Frame fr;
  std::int64_t frameBytes = 0;
  auto check = [&] {
    std::vector<std::uint8_t> whole{0xD3, static_cast<std::uint8_t>(fr.payload.size() >> 8),
                                    static_cast<std::uint8_t>(fr.payload.size() & 0xFF)};
    whole.insert(whole.end(), fr.payload.begin(), fr.payload.end());
    const std::uint32_t crc = gvins::rtcm::crc24q(whole);
    const std::uint8_t* tail = data + 1 + fr.offset + 3 + static_cast<std::int64_t>(fr.payload.size());
    if (fr.offset < 0 || fr.offset + static_cast<std::int64_t>(fr.size()) > static_cast<std::int64_t>(size - 1)) std::abort();
    if (((static_cast<std::uint32_t>(tail[0]) << 16) | (static_cast<std::uint32_t>(tail[1]) << 8) | tail[2]) != crc) std::abort();
    frameBytes += static_cast<std::int64_t>(fr.size());
  };
  for (std::size_t i = 1; i < size; i += chunk) {
    f.feed({data + i, std::min(chunk, size - i)});
    while (f.next(fr)) check();
  }
  f.finish();
  while (f.next(fr)) check();
  const auto& st = f.stats();
  if (st.bytes != static_cast<std::int64_t>(size - 1)) std::abort();
  if (frameBytes + st.skippedBytes != st.bytes) std::abort();  // every byte is a frame's or skipped
  return 0;
}
