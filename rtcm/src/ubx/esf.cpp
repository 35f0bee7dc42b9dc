#include "gvins/ubx/esf.hpp"

#include <numbers>
#include <string>

#include "payload_reader.hpp"

namespace gvins::ubx {

namespace {

// Adds one data word (24-bit signed value, 6-bit type) to a sample; unknown types are ignored.
void addWord(ImuSample& s, std::uint32_t word) {
  std::int32_t v = static_cast<std::int32_t>(word & 0xFFFFFFu);
  if (v & 0x800000) v -= 0x1000000;  // sign-extend 24 bits
  const unsigned type = (word >> 24) & 0x3Fu;
  const double gyro = v * (1.0 / 4096.0) * std::numbers::pi / 180.0;  // deg/s * 2^-12 -> rad/s
  const double acc = v * (1.0 / 1024.0);                              // m/s^2 * 2^-10
  switch (type) {
    case 14: s.gyro[0] = gyro; s.present |= 1; break;
    case 13: s.gyro[1] = gyro; s.present |= 2; break;
    case 5: s.gyro[2] = gyro; s.present |= 4; break;
    case 16: s.accel[0] = acc; s.present |= 8; break;
    case 17: s.accel[1] = acc; s.present |= 16; break;
    case 18: s.accel[2] = acc; s.present |= 32; break;
    case 12: s.temperature = v * 1e-2; s.present |= 64; break;
    default: break;
  }
}

}  // namespace

std::vector<ImuSample> parseEsfRaw(std::span<const std::uint8_t> payload) {
  const detail::PayloadReader r(payload);
  if (payload.size() < 4 || (payload.size() - 4) % 8 != 0) {
    throw rtcm::MessageError("ESF-RAW length", std::to_string(payload.size()) + " bytes is not 4 + 8*N");
  }
  std::vector<ImuSample> out;
  for (std::size_t o = 4; o + 8 <= payload.size(); o += 8) {
    const std::uint32_t word = r.u4(o, "data");
    const std::uint32_t tag = r.u4(o + 4, "sTtag");
    if (out.empty() || out.back().timeTag != tag) {
      out.emplace_back();
      out.back().timeTag = tag;
    }
    addWord(out.back(), word);
  }
  return out;
}

ImuSample parseEsfMeas(std::span<const std::uint8_t> payload) {
  const detail::PayloadReader r(payload);
  ImuSample s;
  s.timeTag = r.u4(0, "timeTag");
  const std::uint16_t flags = r.u2(4, "flags");
  r.need(6, 2, "id");
  const std::size_t n = (flags >> 11) & 0x1Fu;
  r.need(8, 4 * n, "numMeas");
  for (std::size_t i = 0; i < n; ++i) addWord(s, r.u4(8 + 4 * i, "data"));
  return s;
}

}  // namespace gvins::ubx
