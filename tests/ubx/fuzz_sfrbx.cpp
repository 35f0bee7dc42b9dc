// libFuzzer target: parseSfrbx and NavigationAssembler. The input is a sequence of records, each a
// 2-byte little-endian length and that many payload bytes; byte 0 selects whether a receive time
// is known (bit 0) and how far it advances per record (other bits). parseSfrbx may throw only
// SfrbxError; the assembler must never throw, and every record it emits must be finite (BeiDou:
// D2 records only for GEO satellites; CNAV group delays in range and dated). Seed geo_beidou_d2.bin:
// the D2 pages of test_sfrbx_d2.cpp; walk_gps_cnav.bin: 24 GPS CNAV messages of the walk log
// (types 10, 11, 30, 33 on L2 CM and L5 I).
#include <cmath>
#include <cstdint>
#include <cstdlib>

#include "gvins/ubx/navigation_assembler.hpp"
#include "gvins/ubx/sfrbx_error.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::uint8_t mode = data[0];
  gvins::ubx::NavigationAssembler assembler;
  gvins::GpsTime t = (mode & 1) ? gvins::GpsTime::fromWeekTow(2381, 63000.0) : gvins::GpsTime{};
  const double step = static_cast<double>(mode >> 1) * 0.5;
  std::size_t i = 1;
  while (i + 2 <= size) {
    const std::size_t len = data[i] | (static_cast<std::size_t>(data[i + 1]) << 8);
    i += 2;
    const std::size_t n = std::min(len, size - i);
    gvins::ubx::SfrbxMessage msg;
    try {
      msg = gvins::ubx::parseSfrbx({data + i, n});
    } catch (const gvins::ubx::SfrbxError&) {
      i += n;
      continue;
    }
    i += n;
    const gvins::ubx::NavDataUpdate u = assembler.add(msg, t);
    for (const auto& e : u.kepler) {
      if (!std::isfinite(e.sqrtA) || !std::isfinite(e.af0) || !std::isfinite(e.toe - t)) std::abort();
      // BeiDou: D2 records for GEO satellites only, D1 for the others.
      if (e.sat.system == gvins::System::BeiDou &&
          (e.message == gvins::NavMessage::BeiDouD2) != gvins::isBeiDouGeo(e.sat)) std::abort();
    }
    // CNAV type 30: GPS/QZSS only, dated within half a week of the receive time, every delay
    // inside the 13-bit range of 2^-35 s (|value| <= 4095 units; -4096 means "not available").
    for (const auto& c : u.cnav) {
      if (c.sat.system != gvins::System::Gps && c.sat.system != gvins::System::Qzss) std::abort();
      if (!(mode & 1) || !(std::abs(c.time - t) <= 302400.0) || !std::isfinite(c.af0)) std::abort();
      for (const auto& v : {c.tgd, c.iscL1ca, c.iscL2c, c.iscL5i5, c.iscL5q5})
        if (v && !(std::abs(*v) <= std::ldexp(4095.0, -35))) std::abort();
    }
    for (const auto& g : u.glonass)
      if (!std::isfinite(g.position.norm()) || !std::isfinite(g.tauN)) std::abort();
    if (mode & 1) t += step;
  }
  const gvins::ubx::NavigationCounts c = assembler.total();
  if (c.parityFailures + c.crcFailures + c.unknownMessages + c.skipped > c.messages) std::abort();
  return 0;
}
