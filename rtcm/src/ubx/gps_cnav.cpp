// GPS/QZSS CNAV decoding: IS-GPS-200N appendix III (L2C) and IS-GPS-705J 20.3.3 (L5), the same
// messages: 300 bits, preamble 10001011b (bits 1-8), PRN (9-14), message type ID (15-20), message
// TOW count (21-37, 6 s units: the start of the next message, 30.3.3.1.1.1), alert flag (38), CRC
// (277-300; 30.3.5, the CRC-24Q of RTCM 3). Type 30 (figure 30-3 / 20-3): the clock of types 30-37
// (top 39-49, URA_NED0..2 50-60, toc 61-71, af0 72-97, af1 98-117, af2 118-127; table 30-III) and
// T_GD 128-140, ISC_L1C/A 141-153, ISC_L2C 154-166, ISC_L5I5 167-179, ISC_L5Q5 180-192, each
// 13 bits two's complement of 2^-35 s, the value 1000000000000b meaning "not available"
// (30.3.3.3.1.1). QZSS: IS-QZSS-PNT-005, the same layout. Bit positions below count from 0.
#include "gps_cnav.hpp"

#include "gvins/rtcm/crc24q.hpp"
#include "../broadcast_times.hpp"

namespace gvins::ubx::detail {
namespace {

constexpr int kMessageBits = 300;
constexpr int kCrcBits = 24;
constexpr double kMaxTowCount = 100800.0;  // 17-bit TOW count in 6 s units: < one week

std::optional<double> groupDelayField(const NavBits& b, int pos) {
  const std::int64_t v = b.s(pos, 13);
  if (v == -4096) return std::nullopt;  // 1000000000000b: not available
  return scaled(v, -35);
}

}  // namespace

std::optional<CnavMessage> cnavMessage(const std::vector<std::uint32_t>& words) {
  if (words.size() != 10) return std::nullopt;
  CnavMessage m;
  for (std::uint32_t w : words) m.bits.push(w, 32);
  // CRC input: 4 zero bits (which leave a zero-initialised CRC unchanged) and message bits 1-276:
  // 280 bits = 35 bytes.
  NavBits crcIn;
  crcIn.push(0, 4);
  crcIn.append(m.bits, 0, kMessageBits - kCrcBits);
  const std::uint32_t crc = rtcm::crc24q(std::span<const std::uint8_t>(crcIn.bytes().data(), 35));
  m.crcOk = crc == m.bits.u(kMessageBits - kCrcBits, kCrcBits);
  return m;
}

CnavGroupDelays cnavType30(const NavBits& b, SatId sat, const GpsTime& time) {
  CnavGroupDelays c;
  c.sat = sat;
  c.time = time;
  c.toc = rtcm::nearWeek(GpsTime::fromWeekTow(time.week(), static_cast<double>(b.u(60, 11)) * 300.0), time);
  c.af0 = scaled(b.s(71, 26), -35);
  c.af1 = scaled(b.s(97, 20), -48);
  c.af2 = scaled(b.s(117, 10), -60);
  c.tgd = groupDelayField(b, 127);
  c.iscL1ca = groupDelayField(b, 140);
  c.iscL2c = groupDelayField(b, 153);
  c.iscL5i5 = groupDelayField(b, 166);
  c.iscL5q5 = groupDelayField(b, 179);
  return c;
}

void GpsCnavDecoder::add(const SfrbxMessage& msg, SatId sat, const GpsTime& receiveTime, NavDataUpdate& out,
                         NavigationCounts& counts) {
  const bool dated = receiveTime.week() >= kFirstValidWeek;
  if (dated) {
    for (const Undated& u : undated_) {
      out.cnav.push_back(cnavType30(u.bits, u.sat, nearestTow(u.tow, receiveTime)));
      ++counts.groupDelays;
    }
    undated_.clear();
  }
  const std::optional<CnavMessage> m = cnavMessage(msg.words);
  if (!m) {
    ++counts.unknownMessages;
    return;
  }
  if (!m->crcOk) {
    ++counts.crcFailures;
    return;
  }
  const NavBits& b = m->bits;
  const double towCount = static_cast<double>(b.u(20, 17));
  // The PRN field must name the satellite the receiver tagged (GPS: PRN 1-63; QZSS numbers its
  // satellites differently in the field and is not checked).
  const bool prnOk = sat.system != System::Gps || static_cast<int>(b.u(8, 6)) == sat.prn;
  if (b.u(0, 8) != 0x8b || !prnOk || towCount >= kMaxTowCount) {
    ++counts.unknownMessages;
    return;
  }
  if (b.u(14, 6) != 30) return;  // other types: ephemeris, clock with EOP/UTC/almanac, not needed
  const double tow = towCount * 6.0;
  if (!dated) {  // the latest of each satellite
    std::erase_if(undated_, [&](const Undated& u) { return u.sat == sat; });
    undated_.push_back({b, sat, tow});
    return;
  }
  out.cnav.push_back(cnavType30(b, sat, nearestTow(tow, receiveTime)));
  ++counts.groupDelays;
}

}  // namespace gvins::ubx::detail
