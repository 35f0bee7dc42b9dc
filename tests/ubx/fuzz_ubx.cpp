// libFuzzer target: the UBX framer and the UBX decoder (mixed-stream splitter, RAWX, NAV, ESF,
// SFRBX hand-off; seed walk_cnav.bin: a RAWX epoch and GPS CNAV frames of the walk log) on
// arbitrary bytes fed in arbitrary chunks. Every frame the framer returns must
// carry a valid checksum and lie inside the input; the counters must add up; the decoder must
// neither crash nor hang and must account for every byte. Every NAV-PVT delivered must have
// its fields in range, a solution kind that agrees with its flags, and a GPST (the week rules of
// gvins-ubx to-pos) within half a week of the time it was resolved against.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <variant>
#include <vector>

#include "gvins/ubx/ubx_decoder.hpp"
#include "gvins/ubx/ubx_framer.hpp"

namespace {

void checkNavPvt(const gvins::ubx::NavPvt& p, const std::optional<gvins::GpsTime>& rawx) {
  using gvins::ubx::NavPvtSolution;
  if (p.iTow >= 604800000u || std::abs(p.latDeg) > 90.0 || std::abs(p.lonDeg) > 180.0) std::abort();
  const NavPvtSolution s = gvins::ubx::navPvtSolution(p);
  if (s != NavPvtSolution::None && !p.fixOk()) std::abort();
  if ((s == NavPvtSolution::RtkFixed) != (s != NavPvtSolution::None && s != NavPvtSolution::TwoD && p.carrierSolution() == 2))
    std::abort();
  if ((s == NavPvtSolution::TwoD) != (p.fixOk() && p.fixType == 2)) std::abort();
  const auto utc = gvins::ubx::navPvtUtcAsGpst(p);
  for (const auto& near : {rawx, utc}) {
    if (!near) continue;
    const gvins::GpsTime t = gvins::ubx::timeOfWeekNear(p.iTow * 1e-3, *near);
    if (!(std::abs(t - *near) <= 302400.0 + 1e-3)) std::abort();
    if (std::abs(t.tow() - p.iTow * 1e-3) > 1e-6) std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  // The first byte chooses the chunk size (1..256) so that chunk boundaries fall everywhere.
  const std::size_t chunk = static_cast<std::size_t>(data[0]) + 1;
  const std::uint8_t* in = data + 1;
  const std::size_t n = size - 1;

  gvins::ubx::Framer f;
  gvins::ubx::Frame fr;
  std::int64_t frameBytes = 0;
  auto check = [&] {
    if (fr.offset < 0 || fr.offset + static_cast<std::int64_t>(fr.size()) > static_cast<std::int64_t>(n)) std::abort();
    const std::uint8_t* p = in + fr.offset;
    if (p[0] != 0xB5 || p[1] != 0x62 || p[2] != fr.msgClass || p[3] != fr.msgId) std::abort();
    const std::uint16_t ck = gvins::ubx::fletcher8({p + 2, fr.payload.size() + 4});
    if (p[fr.size() - 2] != (ck & 0xFF) || p[fr.size() - 1] != (ck >> 8)) std::abort();
    frameBytes += static_cast<std::int64_t>(fr.size());
  };
  gvins::ubx::Decoder dec;
  std::int64_t epochs = 0;
  auto drain = [&] {
    while (auto d = dec.poll()) {
      if (const auto* e = std::get_if<gvins::ObsEpoch>(&*d)) {
        if (e->sats.empty()) std::abort();
        ++epochs;
      } else if (const auto* p = std::get_if<gvins::ubx::NavPvt>(&*d)) {
        checkNavPvt(*p, dec.lastEpochTime());
      }
    }
  };
  for (std::size_t i = 0; i < n; i += chunk) {
    const std::span<const std::uint8_t> piece(in + i, std::min(chunk, n - i));
    f.feed(piece);
    while (f.next(fr)) check();
    dec.feed(piece);
    drain();
  }
  f.finish();
  while (f.next(fr)) check();
  dec.finish();
  drain();
  const auto& st = f.stats();
  if (st.bytes != static_cast<std::int64_t>(n)) std::abort();
  if (frameBytes + st.skippedBytes != st.bytes) std::abort();  // every byte is a frame's or skipped
  const auto& ds = dec.stats();
  if (ds.stream.bytes != static_cast<std::int64_t>(n) || ds.epochs != epochs) std::abort();
  // Every malformed message noted names its frame's offset and the field.
  for (const auto& i : ds.issues) {
    if (i.field.empty() || i.what.empty() || i.offset < 0 || i.offset >= static_cast<std::int64_t>(n)) std::abort();
  }
  return 0;
}
