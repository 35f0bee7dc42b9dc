// SSR messages of RTCM 10403.3 section 3.5.12 (orbit, clock, code bias, combined, URA and
// high-rate clock corrections of GPS, GLONASS, Galileo, QZSS and BeiDou; field layout in
// ssr_layout.hpp) into gvins::SsrMessage, one per RTCM message.
#include <string>

#include "decoder_state.hpp"
#include "ssr_layout.hpp"

namespace gvins::rtcm {
namespace {

using ssr::SystemLayout;

/// The header's epoch time resolved to GPST near the decoder's reference.
GpsTime readEpoch(const Decoder::State& s, BitReader& r, const SystemLayout& L) {
  const std::uint64_t v = r.u(L.epochBits, L.epochField);
  if (L.system == System::Glonass) {
    // Seconds of the GLONASS day (Moscow time, UTC + 3 h); 86400 only during a leap second.
    if (v > 86400u) throw MessageError(L.epochField, "time of day " + std::to_string(v) + " s is beyond a day");
    return resolveGlonassTimeOfDay(s, static_cast<double>(v));
  }
  if (v >= 604800u) throw MessageError(L.epochField, "time of week " + std::to_string(v) + " s is beyond a week");
  // BeiDou: seconds of the BDT week (BDT = GPST - 14 s).
  const double tow = static_cast<double>(v) - (L.system == System::BeiDou ? kBdtMinusGpst : 0.0);
  return resolveTow(s, tow);
}

SatId readSatellite(BitReader& r, const SystemLayout& L) {
  const int id = static_cast<int>(r.u(L.satBits, L.satField));
  const SatId sat(L.system, id);
  if (!sat.valid()) {
    throw MessageError(L.satField, std::string(systemName(L.system)) + " satellite ID " + std::to_string(id) +
                                       " is not " + std::to_string(minPrn(L.system)) + "-" +
                                       std::to_string(maxPrn(L.system)));
  }
  return sat;
}

/// Throws unless `bits` more bits are there, naming the count that asked for them.
void needFor(const BitReader& r, std::size_t bits, const char* countField, const std::string& what) {
  if (bits > r.remaining()) {
    throw MessageError(countField, what + " need " + std::to_string(bits) + " bits, the message has " +
                                       std::to_string(r.remaining()) + " left");
  }
}

SsrOrbitCorrection readOrbit(BitReader& r, const SystemLayout& L) {
  SsrOrbitCorrection o;
  o.issueOfData = static_cast<int>(r.u(L.iodBits, L.iodField));
  if (L.iod2Bits > 0) o.iodCrc = static_cast<int>(r.u(L.iod2Bits, L.iod2Field));
  o.rac.x() = static_cast<double>(r.s(22, "DF365 delta radial")) * ssr::kRadialLsb;
  o.rac.y() = static_cast<double>(r.s(20, "DF366 delta along-track")) * ssr::kAlongCrossLsb;
  o.rac.z() = static_cast<double>(r.s(20, "DF367 delta cross-track")) * ssr::kAlongCrossLsb;
  o.racRate.x() = static_cast<double>(r.s(21, "DF368 dot delta radial")) * ssr::kRadialRateLsb;
  o.racRate.y() = static_cast<double>(r.s(19, "DF369 dot delta along-track")) * ssr::kAlongCrossRateLsb;
  o.racRate.z() = static_cast<double>(r.s(19, "DF370 dot delta cross-track")) * ssr::kAlongCrossRateLsb;
  return o;
}

SsrClockCorrection readClock(BitReader& r) {
  SsrClockCorrection c;
  c.c0 = static_cast<double>(r.s(22, "DF376 delta clock C0")) * ssr::kC0Lsb;
  c.c1 = static_cast<double>(r.s(21, "DF377 delta clock C1")) * ssr::kC1Lsb;
  c.c2 = static_cast<double>(r.s(27, "DF378 delta clock C2")) * ssr::kC2Lsb;
  return c;
}

}  // namespace

void decodeSsr(Decoder::State& s, BitReader& r, int type) {
  const auto mk = ssr::messageKind(type);
  if (!mk) throw MessageError("DF002 message number", std::to_string(type) + " is not an SSR message");
  const SystemLayout& L = *mk->layout;
  const SsrKind kind = mk->kind;

  SsrMessage m;
  SsrHeader& h = m.header;
  h.messageType = type;
  h.system = L.system;
  h.kind = kind;
  h.epoch = readEpoch(s, r, L);
  h.updateInterval = kSsrUpdateIntervals[r.u(4, "DF391 SSR update interval")];
  h.multipleMessage = r.flag("DF388 multiple message indicator");
  if (ssr::hasOrbit(kind)) h.regionalDatum = r.flag("DF375 satellite reference datum");
  h.iodSsr = static_cast<int>(r.u(4, "DF413 IOD SSR"));
  h.providerId = static_cast<int>(r.u(16, "DF414 SSR provider ID"));
  h.solutionId = static_cast<int>(r.u(4, "DF415 SSR solution ID"));
  const int n = static_cast<int>(r.u(6, "DF387 number of satellites"));

  // Fixed-size satellite blocks: check the whole list against the message length at once.
  std::size_t perSat = static_cast<std::size_t>(L.satBits);
  switch (kind) {
    case SsrKind::kOrbit: perSat += static_cast<std::size_t>(L.iodBits + L.iod2Bits + ssr::kOrbitBits); break;
    case SsrKind::kClock: perSat += ssr::kClockBits; break;
    case SsrKind::kCombined:
      perSat += static_cast<std::size_t>(L.iodBits + L.iod2Bits + ssr::kOrbitBits + ssr::kClockBits);
      break;
    case SsrKind::kUra: perSat += ssr::kUraBits; break;
    case SsrKind::kHighRateClock: perSat += ssr::kHighRateClockBits; break;
    case SsrKind::kCodeBias: perSat += 5; break;  // at least the ID and DF379
  }
  needFor(r, perSat * static_cast<std::size_t>(n), "DF387 number of satellites", std::to_string(n) + " satellites");

  m.satellites.reserve(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    SsrSatellite& sat = m.satellites.emplace_back();
    sat.sat = readSatellite(r, L);
    switch (kind) {
      case SsrKind::kOrbit: sat.orbit = readOrbit(r, L); break;
      case SsrKind::kClock: sat.clock = readClock(r); break;
      case SsrKind::kCombined:
        sat.orbit = readOrbit(r, L);
        sat.clock = readClock(r);
        break;
      case SsrKind::kUra: sat.uraIndex = static_cast<int>(r.u(6, "DF389 SSR URA")); break;
      case SsrKind::kHighRateClock:
        sat.highRateClock = static_cast<double>(r.s(22, "DF390 high rate clock correction")) * ssr::kHighRateClockLsb;
        break;
      case SsrKind::kCodeBias: {
        const int nb = static_cast<int>(r.u(5, "DF379 number of code biases"));
        // The remaining satellites need at least their ID and DF379 each.
        needFor(r, static_cast<std::size_t>(nb) * ssr::kBiasBits + static_cast<std::size_t>(n - 1 - i) * perSat,
                "DF379 number of code biases", sat.sat.str() + ": " + std::to_string(nb) + " code biases");
        for (int k = 0; k < nb; ++k) {
          const int id = static_cast<int>(r.u(5, L.signalField));
          const double bias = static_cast<double>(r.s(14, "DF383 code bias")) * ssr::kCodeBiasLsb;
          if (const auto code = ssr::signalCode(L.system, id)) {
            sat.codeBiases.emplace_back(*code, bias);
          } else {
            ++s.stats.unknownBiasSignals;  // reserved identifier: skipped, not an error
          }
        }
        break;
      }
    }
  }
  // SSR epochs are stream times like the observation epochs: they carry the reference along.
  s.ref = h.epoch;
  ++s.stats.ssrMessages;
  s.out.emplace_back(std::move(m));
}

}  // namespace gvins::rtcm
