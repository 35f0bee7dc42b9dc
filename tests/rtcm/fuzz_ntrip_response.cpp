// libFuzzer target: the NTRIP response parser (status line, headers, ICY, chunked transfer
// coding) on arbitrary caster answers, fed in pieces. Only NtripError may come out.
#include <cstdint>
#include <vector>

#include "gvins/rtcm/ntrip_error.hpp"
#include "gvins/rtcm/ntrip_response.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::size_t chunk = static_cast<std::size_t>(data[0] % 64) + 1;
  gvins::rtcm::NtripResponse r("FUZZ");
  std::vector<std::uint8_t> payload;
  try {
    for (std::size_t i = 1; i < size; i += chunk) r.feed({data + i, std::min(chunk, size - i)}, payload);
    r.end();
  } catch (const gvins::rtcm::NtripError&) {
  }
  return 0;
}
