// Multiple Signal Messages MSM1-MSM7 (RTCM 10403.3 section 3.5.12; header table 3.5-78,
// satellite data table 3.5-79, signal data table 3.5-80 and the field definitions DF393-DF420).
#include <array>
#include <bit>
#include <cmath>

#include "decoder_state.hpp"
#include "gvins/base/constants.hpp"
#include "gvins/rtcm/msm_signals.hpp"

namespace gvins::rtcm {
namespace {

constexpr double kLightMs = constants::kSpeedOfLight * 1e-3;  // metres per millisecond
constexpr double kP10 = 1.0 / 1024.0;                       // 2^-10
constexpr double kP24 = 1.0 / 16777216.0;                   // 2^-24
constexpr double kP29 = kP24 / 32.0;                        // 2^-29
constexpr double kP31 = kP29 / 4.0;                         // 2^-31

struct Layout {
  bool intMs, ext, rate;         // satellite data: DF397, extended info, DF399
  bool pr, ph, lock, cnr, drate; // signal data present
  bool high;                     // MSM6/7 extended resolution fields
  int satBits, cellBits;
};

Layout layoutOf(int msm) {
  switch (msm) {
    case 1: return {false, false, false, true, false, false, false, false, false, 10, 15};
    case 2: return {false, false, false, false, true, true, false, false, false, 10, 27};
    case 3: return {false, false, false, true, true, true, false, false, false, 10, 42};
    case 4: return {true, false, false, true, true, true, true, false, false, 18, 48};
    case 5: return {true, true, true, true, true, true, true, true, false, 36, 63};
    case 6: return {true, false, false, true, true, true, true, false, true, 18, 65};
    default: return {true, true, true, true, true, true, true, true, true, 36, 80};
  }
}

}  // namespace

void decodeMsm(Decoder::State& s, BitReader& r, System system, int msm) {
  const Layout L = layoutOf(msm);
  r.skip(12, "DF003 reference station ID");
  GpsTime t;
  bool beidouAsBdt = false;
  if (system == System::Glonass) {
    const int dow = static_cast<int>(r.u(3, "DF416 GLONASS day of week"));
    const std::uint64_t tod = r.u(27, "DF034 GLONASS epoch time");
    if (tod > 86400999u) throw MessageError("DF034 GLONASS epoch time", "time of day " + std::to_string(tod) + " ms is beyond a day");
    (void)dow;  // 7 = unknown; the day is resolved from the reference time instead
    t = resolveGlonassTimeOfDay(s, static_cast<double>(tod) * 1e-3);
  } else {
    const std::uint64_t tow = r.u(30, system == System::BeiDou ? "DF427 BeiDou epoch time" : "DF004 epoch time");
    if (tow >= 604800000u) throw MessageError("epoch time", "time of week " + std::to_string(tow) + " ms is beyond a week");
    if (system == System::BeiDou) {
      t = checkBeidouStamp(s, resolveTow(s, static_cast<double>(tow) * 1e-3 - kBdtMinusGpst), beidouAsBdt);
    } else {
      t = resolveTow(s, static_cast<double>(tow) * 1e-3);
    }
  }
  const bool more = r.flag("DF393 multiple message bit");
  r.skip(3 + 7 + 2 + 2 + 1 + 3, "DF409-DF418");
  const std::uint64_t satMask = r.u(64, "DF394 satellite mask");
  const std::uint64_t sigMask = r.u(32, "DF395 signal mask");
  const int nsat = std::popcount(satMask);
  const int nsig = std::popcount(sigMask);
  if (nsat * nsig > 64) {
    throw MessageError("DF396 cell mask", std::to_string(nsat) + " satellites x " + std::to_string(nsig) + " signals exceed 64 cells");
  }
  const std::uint64_t cellMask = r.u(nsat * nsig, "DF396 cell mask");
  const int ncell = std::popcount(cellMask);
  r.need(static_cast<std::size_t>(nsat * L.satBits + ncell * L.cellBits), "satellite and signal data");

  // Satellite and signal IDs in mask order (ID 1 is the most significant bit).
  std::array<int, 64> satIds{};
  std::array<int, 32> sigIds{};
  for (int i = 0, n = 0; i < 64; ++i) if ((satMask >> (63 - i)) & 1u) satIds[n++] = i + 1;
  for (int i = 0, n = 0; i < 32; ++i) if ((sigMask >> (31 - i)) & 1u) sigIds[n++] = i + 1;

  // Satellite data, field by field.
  std::array<int, 64> intMs{}, ext{}, rate{};
  std::array<int, 64> mod{};
  if (L.intMs) for (int i = 0; i < nsat; ++i) intMs[i] = static_cast<int>(r.u(8, "DF397 rough range integer ms"));
  if (L.ext) for (int i = 0; i < nsat; ++i) ext[i] = static_cast<int>(r.u(4, "extended satellite information"));
  for (int i = 0; i < nsat; ++i) mod[i] = static_cast<int>(r.u(10, "DF398 rough range modulo 1 ms"));
  if (L.rate) for (int i = 0; i < nsat; ++i) rate[i] = static_cast<int>(r.s(14, "DF399 rough phase range rate"));

  // Signal data, field by field over the cells.
  std::array<std::int64_t, 64> fpr{}, fph{}, fdr{};
  std::array<int, 64> lock{}, half{}, cnr{};
  if (L.pr) for (int c = 0; c < ncell; ++c) fpr[c] = L.high ? r.s(20, "DF405 fine pseudorange") : r.s(15, "DF400 fine pseudorange");
  if (L.ph) for (int c = 0; c < ncell; ++c) fph[c] = L.high ? r.s(24, "DF406 fine phase range") : r.s(22, "DF401 fine phase range");
  if (L.lock) {
    for (int c = 0; c < ncell; ++c) lock[c] = static_cast<int>(L.high ? r.u(10, "DF407 lock time indicator") : r.u(4, "DF402 lock time indicator"));
    for (int c = 0; c < ncell; ++c) half[c] = static_cast<int>(r.u(1, "DF420 half-cycle ambiguity"));
  }
  if (L.cnr) for (int c = 0; c < ncell; ++c) cnr[c] = static_cast<int>(L.high ? r.u(10, "DF408 CNR") : r.u(6, "DF403 CNR"));
  if (L.drate) for (int c = 0; c < ncell; ++c) fdr[c] = r.s(15, "DF404 fine phase range rate");

  const std::int64_t invalidPr = L.high ? -524288 : -16384;    // DF405 0x80000 / DF400 0x4000
  const std::int64_t invalidPh = L.high ? -8388608 : -2097152; // DF406 0x800000 / DF401 0x200000
  const double prUnit = L.high ? kP29 : kP24;
  const double phUnit = L.high ? kP31 : kP29;
  const LockTimeKind lockKind = L.high ? LockTimeKind::MsmExt : LockTimeKind::Msm;

  std::vector<SatObs> sats;
  sats.reserve(static_cast<std::size_t>(nsat));
  int cell = 0;
  for (int i = 0; i < nsat; ++i) {
    const std::optional<SatId> sat = msmSatellite(system, satIds[i]);
    SatObs so;
    double roughMs = 0.0;
    bool roughOk = L.intMs ? intMs[i] != 255 : true;  // DF397 255: rough range invalid
    if (sat) {
      so.sat = *sat;
      if (L.intMs) {
        roughMs = intMs[i] + mod[i] * kP10;
        if (roughOk) noteRange(s, *sat, t, roughMs * kLightMs);
      } else if (const auto full = resolveRange(s, *sat, t, mod[i] * kP10 * kLightMs, kLightMs)) {
        roughMs = *full / kLightMs;  // MSM1-3: whole milliseconds from the last full range
      } else {
        roughOk = false;
      }
      if (system == System::Glonass && L.ext && ext[i] <= 13) s.channels.set(sat->prn, ext[i] - 7);
    }
    std::optional<int> channel;
    if (sat && system == System::Glonass) channel = s.channels.get(sat->prn);
    for (int j = 0; j < nsig; ++j) {
      if (!((cellMask >> (nsat * nsig - 1 - (i * nsig + j))) & 1u)) continue;
      const int c = cell++;
      if (!sat) {
        ++s.stats.unknownSatellites;
        continue;
      }
      const std::optional<ObsCode> code = msmSignalCode(system, sigIds[j]);
      if (!code) {
        ++s.stats.unknownSignals;
        continue;
      }
      if (!roughOk) {
        if (!L.intMs) ++s.stats.unresolvedRanges;
        continue;
      }
      SignalObs o;
      o.code = *code;
      const std::optional<double> lambda = carrierWavelength(system, code->band, channel);
      if (L.pr && fpr[c] != invalidPr) o.setCode((roughMs + static_cast<double>(fpr[c]) * prUnit) * kLightMs);
      if (L.ph && fph[c] != invalidPh) {
        if (lambda) o.setPhase((roughMs + static_cast<double>(fph[c]) * phUnit) * kLightMs / *lambda);
        else ++s.stats.glonassNoChannel;
      }
      if (L.drate && rate[i] != -8192 && fdr[c] != -16384 && lambda) {  // DF399 0x2000, DF404 0x4000
        o.setDoppler(-(rate[i] + static_cast<double>(fdr[c]) * 1e-4) / *lambda);
      }
      if (L.cnr && cnr[c] > 0) o.setSnr(L.high ? cnr[c] * 0.0625 : static_cast<double>(cnr[c]));
      if (L.lock) {
        o.lli = lossOfLock(s, *sat, *code, t, lockKind, lock[c]);
        if (half[c]) o.lli |= 2;
      }
      if (o.present & (SignalObs::kCode | SignalObs::kPhase)) so.signals.push_back(o);
    }
    if (sat && !so.signals.empty()) sats.push_back(std::move(so));
  }
  addObservations(s, system, t, more, sats, beidouAsBdt);
}

}  // namespace gvins::rtcm
