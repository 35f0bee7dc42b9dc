#include "gvins/rtcm/ssr_file.hpp"

#include <algorithm>
#include <fstream>
#include <span>
#include <variant>

#include "gvins/base/parse_error.hpp"
#include "gvins/rtcm/encoder.hpp"

namespace gvins::rtcm {

SsrFile readSsrFile(const std::string& path, const GpsTime& reference) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ParseError(path, 0, "", "cannot open file");
  DecoderOptions o;
  o.referenceTime = reference;
  o.streamName = path;
  Decoder decoder(o);
  SsrFile out;
  std::vector<std::uint8_t> buf(1 << 16);
  auto drain = [&] {
    while (auto d = decoder.poll())
      if (auto* s = std::get_if<SsrMessage>(&*d)) out.messages.push_back(std::move(*s));
  };
  for (;;) {
    in.read(reinterpret_cast<char*>(buf.data()), static_cast<std::streamsize>(buf.size()));
    const auto n = in.gcount();
    if (n > 0) decoder.feed(std::span<const std::uint8_t>(buf.data(), static_cast<std::size_t>(n)));
    drain();
    if (n <= 0 || !in) break;
  }
  decoder.finish();
  drain();
  out.stats = decoder.stats();
  std::int64_t frames = 0;
  for (const auto& [type, count] : out.stats.messages) frames += count;
  if (frames == 0) throw ParseError(path, 0, "RTCM 3", "no RTCM 3 frame in the file");
  return out;
}

std::vector<std::uint8_t> encodeSsrFrames(const std::vector<SsrMessage>& messages) {
  // 26 satellites of the longest record (BeiDou combined: 6 + 10 + 24 + 121 + 70 = 231 bits) are
  // 751 bytes; code-bias records of up to 31 biases (11 + 31 * 19 bits) would need fewer.
  const Encoder encoder;
  std::vector<std::uint8_t> out;
  for (const SsrMessage& m : messages) {
    std::size_t perFrame = 26;
    if (m.header.kind == SsrKind::kCodeBias) {
      std::size_t maxBiases = 1;
      for (const SsrSatellite& s : m.satellites) maxBiases = std::max(maxBiases, s.codeBiases.size());
      perFrame = std::max<std::size_t>(1, 7000 / (11 + 19 * maxBiases));
    }
    for (std::size_t i = 0; i < m.satellites.size() || i == 0; i += perFrame) {
      SsrMessage part;
      part.header = m.header;
      const std::size_t end = std::min(m.satellites.size(), i + perFrame);
      part.satellites.assign(m.satellites.begin() + static_cast<std::ptrdiff_t>(i),
                             m.satellites.begin() + static_cast<std::ptrdiff_t>(end));
      part.header.multipleMessage = m.header.multipleMessage || end < m.satellites.size();
      const std::vector<std::uint8_t> frame = encoder.ssr(part);
      out.insert(out.end(), frame.begin(), frame.end());
      if (m.satellites.empty()) break;
    }
  }
  return out;
}

}  // namespace gvins::rtcm
