// Legacy RTK observation messages 1001-1004 (GPS/SBAS) and 1009-1012 (GLONASS),
// RTCM 10403.3 section 3.5.1/3.5.2, tables 3.5-2 to 3.5-15.
#include <cmath>

#include "decoder_state.hpp"
#include "gvins/base/constants.hpp"

namespace gvins::rtcm {
namespace {

constexpr double kGpsPrAmbiguity = 299792.458;      // DF014 unit, m (one light-millisecond)
constexpr double kGlonassPrAmbiguity = 599584.916;  // DF044 unit, m (two light-milliseconds)
constexpr std::int64_t kInvalidPhaseRange = -524288;  // DF012/DF018/DF042/DF048: 0x80000
constexpr std::int64_t kInvalidPrDiff = -8192;        // DF017/DF047: 0x2000

// Phase (cycles) from the pseudorange and the phase-range minus pseudorange difference, undoing
// the +-1500 cycle rollovers a reference station applies to keep the difference within the
// field (RTCM 10403.3, DF012 note).
double phaseCycles(Decoder::State& s, SatId sat, ObsCode code, double pr, double diffMetres,
                   double lambda) {
  SignalTrack& tr = track(s, sat, code);
  const double raw = diffMetres / lambda;
  if (tr.hasRawDiff) {
    const double jump = raw - tr.lastRawDiffCycles;
    if (jump < -750.0) tr.rolloverCycles += 1500.0 * std::round(-jump / 1500.0);
    if (jump > 750.0) tr.rolloverCycles -= 1500.0 * std::round(jump / 1500.0);
  }
  tr.lastRawDiffCycles = raw;
  tr.hasRawDiff = true;
  return pr / lambda + raw + tr.rolloverCycles;
}

// 1001/1003/1009/1011 carry the L1 pseudorange modulo one (GPS) or two (GLONASS)
// light-milliseconds; 1002/1004/1010/1012 add the whole part (DF014/DF044). The phase is built on
// the full pseudorange, so without the whole part neither can be delivered: it is taken from the
// satellite's last full range if there is a recent one, else the satellite is dropped and
// counted in DecoderStats::unresolvedRanges.
bool wholeRange(Decoder::State& s, SatId sat, const GpsTime& t, bool extended, double unit, double& pr) {
  if (extended) {
    noteRange(s, sat, t, pr);
    return true;
  }
  if (const auto full = resolveRange(s, sat, t, pr, unit)) {
    pr = *full;
    return true;
  }
  ++s.stats.unresolvedRanges;
  return false;
}

}  // namespace

void decodeLegacyGps(Decoder::State& s, BitReader& r, int type) {
  r.skip(12, "DF003 reference station ID");
  const std::uint64_t towMs = r.u(30, "DF004 GPS epoch time");
  const bool more = r.flag("DF005 synchronous GNSS flag");
  const int nsat = static_cast<int>(r.u(5, "DF006 number of satellites"));
  r.skip(4, "DF007/DF008 smoothing");
  if (towMs >= 604800000u) throw MessageError("DF004 GPS epoch time", "time of week " + std::to_string(towMs) + " ms is beyond a week");
  const bool ext = type == 1002 || type == 1004;
  const bool l2 = type == 1003 || type == 1004;
  const int perSat = 58 + (ext ? 16 : 0) + (l2 ? 43 + (ext ? 8 : 0) : 0);
  r.need(static_cast<std::size_t>(nsat * perSat), "satellite data");

  const GpsTime t = resolveTow(s, static_cast<double>(towMs) * 1e-3);
  const double l1 = *carrierWavelength(System::Gps, '1');
  const double l2w = *carrierWavelength(System::Gps, '2');
  std::vector<SatObs> sats;
  sats.reserve(static_cast<std::size_t>(nsat));
  for (int i = 0; i < nsat; ++i) {
    const int id = static_cast<int>(r.u(6, "DF009 satellite ID"));
    const bool p1 = r.flag("DF010 L1 code indicator");
    const std::uint64_t pr1raw = r.u(24, "DF011 L1 pseudorange");
    const std::int64_t phr1 = r.s(20, "DF012 L1 phaserange - pseudorange");
    const int lock1 = static_cast<int>(r.u(7, "DF013 L1 lock time indicator"));
    int amb = 0, cnr1 = 0, code2 = 0, lock2 = 0, cnr2 = 0;
    std::int64_t prdiff = kInvalidPrDiff, phr2 = kInvalidPhaseRange;
    if (ext) {
      amb = static_cast<int>(r.u(8, "DF014 L1 pseudorange modulus ambiguity"));
      cnr1 = static_cast<int>(r.u(8, "DF015 L1 CNR"));
    }
    if (l2) {
      code2 = static_cast<int>(r.u(2, "DF016 L2 code indicator"));
      prdiff = r.s(14, "DF017 L2-L1 pseudorange difference");
      phr2 = r.s(20, "DF018 L2 phaserange - L1 pseudorange");
      lock2 = static_cast<int>(r.u(7, "DF019 L2 lock time indicator"));
      if (ext) cnr2 = static_cast<int>(r.u(8, "DF020 L2 CNR"));
    }
    // DF009: 1-32 GPS, 40-58 SBAS PRN 120-138.
    SatId sat;
    if (id >= 1 && id <= 32) sat = SatId(System::Gps, id);
    else if (id >= 40 && id <= 58) sat = SatId(System::Sbas, id - 40 + 20);
    else {
      ++s.stats.unknownSatellites;
      continue;
    }
    SatObs so;
    so.sat = sat;
    const bool sbas = sat.system == System::Sbas;
    double pr1 = static_cast<double>(pr1raw) * 0.02 + amb * kGpsPrAmbiguity;
    if (!wholeRange(s, sat, t, ext, kGpsPrAmbiguity, pr1)) continue;
    {
      SignalObs o;
      o.code = ObsCode('1', (p1 && !sbas) ? 'P' : 'C');
      o.setCode(pr1);
      o.lli = lossOfLock(s, sat, o.code, t, LockTimeKind::Legacy, lock1);
      if (phr1 != kInvalidPhaseRange) {
        o.setPhase(phaseCycles(s, sat, o.code, pr1, static_cast<double>(phr1) * 0.0005, l1));
      }
      if (cnr1 > 0) o.setSnr(cnr1 * 0.25);
      so.signals.push_back(o);
    }
    if (l2 && !sbas) {
      // DF016: 0 C/A or L2C, 1 P(Y) direct, 2 P(Y) cross-correlated, 3 correlated P(Y); as RINEX
      // 3 attributes X (L2C M+L), P, D (semi-codeless), W (Z-tracking).
      static constexpr char kAttr[4] = {'X', 'P', 'D', 'W'};
      SignalObs o;
      o.code = ObsCode('2', kAttr[code2]);
      o.lli = lossOfLock(s, sat, o.code, t, LockTimeKind::Legacy, lock2);
      if (prdiff != kInvalidPrDiff) o.setCode(pr1 + static_cast<double>(prdiff) * 0.02);
      if (phr2 != kInvalidPhaseRange) {
        o.setPhase(phaseCycles(s, sat, o.code, pr1, static_cast<double>(phr2) * 0.0005, l2w));
      }
      if (cnr2 > 0) o.setSnr(cnr2 * 0.25);
      if (o.present & (SignalObs::kCode | SignalObs::kPhase)) so.signals.push_back(o);
    }
    sats.push_back(std::move(so));
  }
  addObservations(s, System::Gps, t, more, sats);
}

void decodeLegacyGlonass(Decoder::State& s, BitReader& r, int type) {
  r.skip(12, "DF003 reference station ID");
  const std::uint64_t todMs = r.u(27, "DF034 GLONASS epoch time");
  const bool more = r.flag("DF005 synchronous GNSS flag");
  const int nsat = static_cast<int>(r.u(5, "DF035 number of satellites"));
  r.skip(4, "DF036/DF037 smoothing");
  if (todMs > 86400999u) throw MessageError("DF034 GLONASS epoch time", "time of day " + std::to_string(todMs) + " ms is beyond a day");
  const bool ext = type == 1010 || type == 1012;
  const bool l2 = type == 1011 || type == 1012;
  const int perSat = 64 + (ext ? 15 : 0) + (l2 ? 43 + (ext ? 8 : 0) : 0);
  r.need(static_cast<std::size_t>(nsat * perSat), "satellite data");

  const GpsTime t = resolveGlonassTimeOfDay(s, static_cast<double>(todMs) * 1e-3);
  std::vector<SatObs> sats;
  sats.reserve(static_cast<std::size_t>(nsat));
  for (int i = 0; i < nsat; ++i) {
    const int slot = static_cast<int>(r.u(6, "DF038 satellite ID"));
    const bool p1 = r.flag("DF039 L1 code indicator");
    const int fcn = static_cast<int>(r.u(5, "DF040 frequency channel number"));
    const std::uint64_t pr1raw = r.u(25, "DF041 L1 pseudorange");
    const std::int64_t phr1 = r.s(20, "DF042 L1 phaserange - pseudorange");
    const int lock1 = static_cast<int>(r.u(7, "DF043 L1 lock time indicator"));
    int amb = 0, cnr1 = 0, code2 = 0, lock2 = 0, cnr2 = 0;
    std::int64_t prdiff = kInvalidPrDiff, phr2 = kInvalidPhaseRange;
    if (ext) {
      amb = static_cast<int>(r.u(7, "DF044 L1 pseudorange modulus ambiguity"));
      cnr1 = static_cast<int>(r.u(8, "DF045 L1 CNR"));
    }
    if (l2) {
      code2 = static_cast<int>(r.u(2, "DF046 L2 code indicator"));
      prdiff = r.s(14, "DF047 L2-L1 pseudorange difference");
      phr2 = r.s(20, "DF048 L2 phaserange - L1 pseudorange");
      lock2 = static_cast<int>(r.u(7, "DF049 L2 lock time indicator"));
      if (ext) cnr2 = static_cast<int>(r.u(8, "DF050 L2 CNR"));
    }
    const SatId sat(System::Glonass, slot);
    if (!sat.valid()) {
      ++s.stats.unknownSatellites;
      continue;
    }
    // DF040: channel number + 7; the FDMA channels are -7..+6 (GLONASS ICD 5.1, 3.3.1.1).
    if (fcn <= 13) s.channels.set(slot, fcn - 7);
    const std::optional<int> k = s.channels.get(slot);
    const std::optional<double> lam1 = carrierWavelength(System::Glonass, '1', k);
    const std::optional<double> lam2 = carrierWavelength(System::Glonass, '2', k);
    SatObs so;
    so.sat = sat;
    double pr1 = static_cast<double>(pr1raw) * 0.02 + amb * kGlonassPrAmbiguity;
    if (!wholeRange(s, sat, t, ext, kGlonassPrAmbiguity, pr1)) continue;
    {
      SignalObs o;
      o.code = ObsCode('1', p1 ? 'P' : 'C');
      o.setCode(pr1);
      o.lli = lossOfLock(s, sat, o.code, t, LockTimeKind::Legacy, lock1);
      if (phr1 != kInvalidPhaseRange) {
        if (lam1) o.setPhase(phaseCycles(s, sat, o.code, pr1, static_cast<double>(phr1) * 0.0005, *lam1));
        else ++s.stats.glonassNoChannel;
      }
      if (cnr1 > 0) o.setSnr(cnr1 * 0.25);
      so.signals.push_back(o);
    }
    if (l2 && code2 <= 1) {  // DF046: 0 C/A, 1 P, 2-3 reserved
      SignalObs o;
      o.code = ObsCode('2', code2 == 1 ? 'P' : 'C');
      o.lli = lossOfLock(s, sat, o.code, t, LockTimeKind::Legacy, lock2);
      if (prdiff != kInvalidPrDiff) o.setCode(pr1 + static_cast<double>(prdiff) * 0.02);
      if (phr2 != kInvalidPhaseRange) {
        if (lam2) o.setPhase(phaseCycles(s, sat, o.code, pr1, static_cast<double>(phr2) * 0.0005, *lam2));
        else ++s.stats.glonassNoChannel;
      }
      if (cnr2 > 0) o.setSnr(cnr2 * 0.25);
      if (o.present & (SignalObs::kCode | SignalObs::kPhase)) so.signals.push_back(o);
    } else if (l2) {
      ++s.stats.unknownSignals;
    }
    sats.push_back(std::move(so));
  }
  addObservations(s, System::Glonass, t, more, sats);
}

}  // namespace gvins::rtcm
