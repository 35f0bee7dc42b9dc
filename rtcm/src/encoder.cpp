// Frame, station position and MSM4/MSM7 encoding (RTCM 10403.3 sections 3.5.3 and 3.5.12, the
// inverse of decode_station.cpp and decode_msm.cpp).
#include <algorithm>
#include <bit>
#include <cmath>

#include "gvins/base/constants.hpp"
#include "gvins/rtcm/bit_writer.hpp"
#include "gvins/rtcm/crc24q.hpp"
#include "gvins/rtcm/encoder.hpp"
#include "gvins/rtcm/lock_time.hpp"
#include "gvins/rtcm/message_types.hpp"
#include "gvins/rtcm/msm_signals.hpp"

namespace gvins::rtcm {
namespace {

constexpr double kLightMs = constants::kSpeedOfLight * 1e-3;

std::uint32_t trackKey(SatId sat, ObsCode code) {
  return (static_cast<std::uint32_t>(satIndex(sat)) << 16) |
         (static_cast<std::uint32_t>(static_cast<unsigned char>(code.band)) << 8) |
         static_cast<unsigned char>(code.attr);
}

/// round(v) if it fits a signed field of `bits` and is not the invalid pattern, else the
/// invalid pattern -2^(bits-1).
std::int64_t fitSigned(double v, int bits) {
  const double lim = std::ldexp(1.0, bits - 1);
  const double r = std::round(v);
  if (!(r > -lim && r < lim)) return static_cast<std::int64_t>(-lim);
  return static_cast<std::int64_t>(r);
}

struct Cell {
  const SignalObs* sig;
  int sigId;
};

struct SatEntry {
  const SatObs* obs;
  int satId;
  std::vector<Cell> cells;  // sorted by signal ID
};

/// Resolutions and field sizes of MSM4 or MSM7.
struct MsmFormat {
  bool high;  // MSM7
  LockTimeKind lockKind;
  double prUnit, phUnit;  // ms
  int prBits, phBits;
  int satBits, cellBits;  // bits per satellite and per cell
};

MsmFormat msmFormat(int msmType) {
  const bool high = msmType == 7;
  return {high,
          high ? LockTimeKind::MsmExt : LockTimeKind::Msm,
          high ? std::ldexp(1.0, -29) : std::ldexp(1.0, -24),
          high ? std::ldexp(1.0, -31) : std::ldexp(1.0, -29),
          high ? 20 : 15,
          high ? 24 : 22,
          high ? 36 : 18,
          high ? 80 : 48};
}

/// The satellites of `sys` with at least one signal that has an MSM signal ID and a code or
/// phase, by satellite ID, each with its signals by signal ID (the first of a repeated ID).
std::vector<SatEntry> msmSatellites(const ObsEpoch& epoch, System sys) {
  std::vector<SatEntry> sats;
  for (const SatObs& so : epoch.sats) {
    if (so.sat.system != sys) continue;
    SatEntry e{&so, msmSatelliteId(so.sat), {}};
    if (e.satId < 1 || e.satId > 64) continue;
    for (const SignalObs& sig : so.signals) {
      if (!(sig.present & (SignalObs::kCode | SignalObs::kPhase))) continue;
      const std::optional<int> id = msmSignalId(sys, sig.code);
      if (!id) continue;
      if (std::none_of(e.cells.begin(), e.cells.end(), [&](const Cell& c) { return c.sigId == *id; })) {
        e.cells.push_back({&sig, *id});
      }
    }
    if (e.cells.empty()) continue;
    std::sort(e.cells.begin(), e.cells.end(), [](const Cell& a, const Cell& b) { return a.sigId < b.sigId; });
    sats.push_back(std::move(e));
  }
  std::sort(sats.begin(), sats.end(), [](const SatEntry& a, const SatEntry& b) { return a.satId < b.satId; });
  return sats;
}

/// The 30-bit epoch time field of `sys`: GLONASS day of week and time of day in Moscow time,
/// BeiDou time of week in BDT, otherwise GPS time of week (ms).
std::uint64_t msmEpochTime(System sys, GpsTime t) {
  if (sys == System::Glonass) {
    const CalendarTime m = gpstToGlonass(t);
    const std::int64_t days = daysFromCivil(m.year, m.month, m.day);
    const int dow = static_cast<int>(((days + 4) % 7 + 7) % 7);  // 1970-01-01 was a Thursday
    const std::int64_t tod = std::llround((m.hour * 3600.0 + m.minute * 60.0 + m.second) * 1000.0);
    return (static_cast<std::uint64_t>(dow) << 27) | static_cast<std::uint64_t>(tod % 86400000);
  }
  if (sys == System::BeiDou) {
    int wk = 0;
    double tow = 0.0;
    gpstToBdt(t, wk, tow);
    return static_cast<std::uint64_t>(std::llround(tow * 1000.0) % 604800000);
  }
  return static_cast<std::uint64_t>(std::llround(t.tow() * 1000.0) % 604800000);
}

/// The end of the message that starts at sats[first]: as many satellites as fit within 64 cells
/// and 1023 bytes, at least one. `sigMask` becomes the message's signal mask.
std::size_t msmGroupEnd(const std::vector<SatEntry>& sats, std::size_t first, const MsmFormat& f,
                        std::uint32_t& sigMask) {
  sigMask = 0;
  std::size_t last = first;
  int ncell = 0;
  for (; last < sats.size(); ++last) {
    std::uint32_t m = sigMask;
    for (const Cell& c : sats[last].cells) m |= 1u << (32 - c.sigId);
    const int nsat = static_cast<int>(last - first + 1);
    const int nsig = std::popcount(m);
    const int cells = ncell + static_cast<int>(sats[last].cells.size());
    const int bits = 169 + nsat * nsig + nsat * f.satBits + cells * f.cellBits;
    if (nsat * nsig > 64 || bits > 1023 * 8) break;
    sigMask = m;
    ncell = cells;
  }
  if (last == first) {  // a single satellite always fits (at most 32 signals x 80 bits)
    for (const Cell& c : sats[first].cells) sigMask |= 1u << (32 - c.sigId);
    last = first + 1;
  }
  return last;
}

std::optional<int> glonassChannel(System sys, SatId sat, const GlonassChannels& channels) {
  if (sys != System::Glonass) return std::nullopt;
  return channels.get(sat.prn);
}

/// Rough range and rate of one satellite of a message.
struct SatRough {
  int intMs = 255;  // DF397, 255 = invalid
  int mod = 0;      // DF398
  int ext = 15;     // MSM7 extended information: GLONASS channel + 7, 15 = unknown
  int rate = -8192;  // DF399, -8192 = invalid
  double range = 0.0;  // ms, the rough range as sent
  bool ok = false;     // a valid rough range: the fine values are sent against it
};

/// Per satellite of a message: the rough range from the first pseudorange (else the first phase)
/// rounded to 1/1024 ms and, for MSM7, the rough rate from the first Doppler.
std::vector<SatRough> msmRoughRanges(std::span<const SatEntry> group, System sys, const GlonassChannels& channels,
                                     bool high) {
  std::vector<SatRough> out(group.size());
  for (std::size_t i = 0; i < group.size(); ++i) {
    SatRough& r = out[i];
    const std::optional<int> ch = glonassChannel(sys, group[i].obs->sat, channels);
    if (sys == System::Glonass && ch) r.ext = *ch + 7;
    double refMs = -1.0;
    for (const Cell& c : group[i].cells) {
      if (c.sig->hasCode()) {
        refMs = c.sig->pseudorange / kLightMs;
        break;
      }
    }
    if (refMs < 0) {
      for (const Cell& c : group[i].cells) {
        const auto lam = carrierWavelength(sys, c.sig->code.band, ch);
        if (c.sig->hasPhase() && lam) {
          refMs = c.sig->carrierPhase * *lam / kLightMs;
          break;
        }
      }
    }
    const double r1024 = std::round(refMs * 1024.0);
    if (!(refMs > 0.0) || r1024 >= 255.0 * 1024.0) continue;
    const auto units = static_cast<std::int64_t>(r1024);
    r.ok = true;
    r.intMs = static_cast<int>(units / 1024);
    r.mod = static_cast<int>(units % 1024);
    r.range = static_cast<double>(units) / 1024.0;
    if (!high) continue;
    for (const Cell& c : group[i].cells) {
      const auto lam = carrierWavelength(sys, c.sig->code.band, ch);
      if (c.sig->hasDoppler() && lam) {
        const double rr = std::round(-c.sig->doppler * *lam);
        if (std::abs(rr) < 8191.0) r.rate = static_cast<int>(rr);
        break;
      }
    }
  }
  return out;
}

/// Field values of one cell.
struct CellOut {
  std::int64_t pr, ph, dr;
  int lock, half, cnr;
  bool phaseMoved;  // the phase was moved by whole cycles (lock restarts)
};

/// Fine pseudorange, phase and phase-range rate of one signal against its satellite's rough
/// values, half-cycle flag and C/N0 (the lock time is the caller's). A phase out of reach of the
/// fine field is moved next to the rough range by whole cycles: `phaseOffset` is updated.
CellOut msmFineValues(const SignalObs& sig, const SatRough& r, const MsmFormat& f, std::optional<double> lam,
                      double& phaseOffset) {
  CellOut co{-(std::int64_t{1} << (f.prBits - 1)), -(std::int64_t{1} << (f.phBits - 1)), -16384, 0, 0, 0, false};
  if (r.ok) {
    if (sig.hasCode()) co.pr = fitSigned((sig.pseudorange / kLightMs - r.range) / f.prUnit, f.prBits);
    if (sig.hasPhase() && lam) {
      auto finePh = [&]() { return ((sig.carrierPhase + phaseOffset) * *lam / kLightMs - r.range) / f.phUnit; };
      const double lim = std::ldexp(1.0, f.phBits - 1) - 1.0;
      if (std::abs(finePh()) >= lim) {
        phaseOffset = std::round((r.range * kLightMs / *lam) - sig.carrierPhase);
        co.phaseMoved = true;
      }
      co.ph = fitSigned(finePh(), f.phBits);
    }
    if (f.high && sig.hasDoppler() && lam && r.rate != -8192) {
      co.dr = fitSigned((-sig.doppler * *lam - r.rate) / 1e-4, 15);
    }
  }
  co.half = (sig.lli & 2) ? 1 : 0;
  if (sig.hasSnr()) {
    const double v = std::round(f.high ? sig.snr * 16.0 : sig.snr);
    co.cnr = static_cast<int>(std::clamp(v, 0.0, f.high ? 1023.0 : 63.0));
  }
  return co;
}

/// Header fields of one MSM message.
struct MsmHeader {
  System sys;
  int msmType;
  int stationId;
  std::uint64_t timeField;
  std::uint32_t sigMask;
  std::vector<int> sigIds;
};

/// The payload of one MSM message: header, satellite data and signal data.
std::vector<std::uint8_t> msmPayload(const MsmHeader& h, const MsmFormat& f, std::span<const SatEntry> group,
                                     const std::vector<SatRough>& rough, std::uint64_t cellMask,
                                     const std::vector<CellOut>& cells) {
  const bool high = f.high;
  const int nsat = static_cast<int>(group.size());
  const int nsig = static_cast<int>(h.sigIds.size());
  BitWriter w;
  w.u(12, static_cast<std::uint64_t>(msmMessageNumber(h.sys, h.msmType)), "DF002 message number");
  w.u(12, static_cast<std::uint64_t>(h.stationId), "DF003 reference station ID");
  w.u(30, h.timeField, "epoch time");
  w.u(1, 1, "DF393 multiple message bit");  // cleared on the epoch's last message (framedEpoch)
  w.u(3, 0, "DF409 IODS");
  w.u(7, 0, "DF001 reserved");
  w.u(2, 0, "DF411 clock steering");
  w.u(2, 0, "DF412 external clock");
  w.u(1, 0, "DF417 smoothing");
  w.u(3, 0, "DF418 smoothing interval");
  std::uint64_t satMask = 0;
  for (int i = 0; i < nsat; ++i) satMask |= std::uint64_t{1} << (64 - group[i].satId);
  w.u(64, satMask, "DF394 satellite mask");
  w.u(32, h.sigMask, "DF395 signal mask");
  w.u(nsat * nsig, cellMask, "DF396 cell mask");
  for (const SatRough& r : rough) w.u(8, static_cast<std::uint64_t>(r.intMs), "DF397 rough range integer ms");
  if (high) for (const SatRough& r : rough) w.u(4, static_cast<std::uint64_t>(r.ext), "extended satellite information");
  for (const SatRough& r : rough) w.u(10, static_cast<std::uint64_t>(r.mod), "DF398 rough range modulo 1 ms");
  if (high) for (const SatRough& r : rough) w.s(14, r.rate, "DF399 rough phase range rate");
  for (const CellOut& c : cells) w.s(f.prBits, c.pr, "fine pseudorange");
  for (const CellOut& c : cells) w.s(f.phBits, c.ph, "fine phase range");
  for (const CellOut& c : cells) w.u(high ? 10 : 4, static_cast<std::uint64_t>(c.lock), "lock time indicator");
  for (const CellOut& c : cells) w.u(1, static_cast<std::uint64_t>(c.half), "DF420 half-cycle ambiguity");
  for (const CellOut& c : cells) w.u(high ? 10 : 6, static_cast<std::uint64_t>(c.cnr), "CNR");
  if (high) for (const CellOut& c : cells) w.s(15, c.dr, "DF404 fine phase range rate");
  return w.bytes();
}

/// The frames of an epoch's messages, the multiple-message bit cleared on the last.
std::vector<std::uint8_t> framedEpoch(std::vector<std::vector<std::uint8_t>>& payloads) {
  std::vector<std::uint8_t> out;
  for (std::size_t k = 0; k < payloads.size(); ++k) {
    std::vector<std::uint8_t>& p = payloads[k];
    if (k + 1 == payloads.size()) p[6] &= static_cast<std::uint8_t>(~0x02u);  // DF393 is bit 54
    const std::vector<std::uint8_t> fr = Encoder::frame(p);
    out.insert(out.end(), fr.begin(), fr.end());
  }
  return out;
}

}  // namespace

std::vector<std::uint8_t> Encoder::frame(std::span<const std::uint8_t> payload) {
  if (payload.size() > 1023) {
    throw MessageError("message length", std::to_string(payload.size()) + " bytes exceed 1023");
  }
  std::vector<std::uint8_t> f;
  f.reserve(payload.size() + 6);
  f.push_back(0xD3);
  f.push_back(static_cast<std::uint8_t>(payload.size() >> 8));
  f.push_back(static_cast<std::uint8_t>(payload.size() & 0xFF));
  f.insert(f.end(), payload.begin(), payload.end());
  const std::uint32_t crc = crc24q(f);
  f.push_back(static_cast<std::uint8_t>(crc >> 16));
  f.push_back(static_cast<std::uint8_t>(crc >> 8));
  f.push_back(static_cast<std::uint8_t>(crc));
  return f;
}

std::vector<std::uint8_t> Encoder::stationPosition(const StationPosition& p) const {
  BitWriter w;
  const bool h = p.antennaHeight.has_value();
  w.u(12, h ? 1006 : 1005, "DF002 message number");
  w.u(12, static_cast<std::uint64_t>(p.stationId), "DF003 reference station ID");
  w.u(6, static_cast<std::uint64_t>(p.itrfYear), "DF021 ITRF realization year");
  w.flag(p.gps);
  w.flag(p.glonass);
  w.flag(p.galileo);
  w.flag(!p.physicalStation);
  w.s(38, std::llround(p.arp.x() * 1e4), "DF025 antenna reference point ECEF-X");
  w.flag(p.singleOscillator);
  w.u(1, 0, "DF001 reserved");
  w.s(38, std::llround(p.arp.y() * 1e4), "DF026 antenna reference point ECEF-Y");
  w.u(2, static_cast<std::uint64_t>(p.quarterCycle), "DF364 quarter cycle indicator");
  w.s(38, std::llround(p.arp.z() * 1e4), "DF027 antenna reference point ECEF-Z");
  if (h) {
    const double v = std::round(*p.antennaHeight * 1e4);
    if (v < 0) throw MessageError("DF028 antenna height", "negative height");
    w.u(16, static_cast<std::uint64_t>(v), "DF028 antenna height");
  }
  return frame(w.bytes());
}

std::vector<std::uint8_t> Encoder::msm(const ObsEpoch& epoch, int msmType) {
  if (msmType != 4 && msmType != 7) throw MessageError("MSM type", "only MSM4 and MSM7 are encoded");
  const MsmFormat f = msmFormat(msmType);
  const GpsTime t = epoch.time;

  // Payloads of all messages of the epoch; framed at the end once the last one is known.
  std::vector<std::vector<std::uint8_t>> payloads;

  static constexpr System kOrder[] = {System::Gps, System::Glonass, System::Galileo, System::Sbas,
                                      System::Qzss, System::BeiDou};
  for (System sys : kOrder) {
    std::vector<SatEntry> sats = msmSatellites(epoch, sys);
    if (sats.empty()) continue;

    // Continuity of lock: a signal absent from the previous epoch of its system restarts lock.
    const int si = systemIndex(sys);
    const bool havePrev = haveEpoch_[si];
    const GpsTime prevEpoch = lastEpoch_[si];
    lastEpoch_[si] = t;
    haveEpoch_[si] = true;

    MsmHeader header{sys, msmType, stationId_, msmEpochTime(sys, t), 0, {}};
    std::size_t first = 0;
    while (first < sats.size()) {
      const std::size_t last = msmGroupEnd(sats, first, f, header.sigMask);
      const std::span<const SatEntry> group(sats.data() + first, last - first);
      first = last;
      header.sigIds.clear();
      for (int id = 1; id <= 32; ++id) if (header.sigMask & (1u << (32 - id))) header.sigIds.push_back(id);
      const std::vector<SatRough> rough = msmRoughRanges(group, sys, channels_, f.high);

      // Per cell values, the lock time of each signal kept across epochs.
      const int nsat = static_cast<int>(group.size());
      const int nsig = static_cast<int>(header.sigIds.size());
      std::vector<CellOut> cells;
      std::uint64_t cellMask = 0;
      for (int i = 0; i < nsat; ++i) {
        const SatObs& so = *group[i].obs;
        const std::optional<int> ch = glonassChannel(sys, so.sat, channels_);
        for (int j = 0; j < nsig; ++j) {
          const auto it = std::find_if(group[i].cells.begin(), group[i].cells.end(),
                                       [&](const Cell& c) { return c.sigId == header.sigIds[j]; });
          if (it == group[i].cells.end()) continue;
          cellMask |= std::uint64_t{1} << (nsat * nsig - 1 - (i * nsig + j));
          const SignalObs& sig = *it->sig;
          Track& tr = tracks_[trackKey(so.sat, sig.code)];
          const bool fresh = !havePrev || tr.last != prevEpoch || (sig.lli & 1) || tr.last == GpsTime{};
          if (fresh) {
            tr.lockStart = t;
            tr.phaseOffset = 0.0;
          }
          CellOut co = msmFineValues(sig, rough[i], f, carrierWavelength(sys, sig.code.band, ch), tr.phaseOffset);
          if (co.phaseMoved) tr.lockStart = t;  // moving the phase restarts lock
          tr.last = t;
          co.lock = lockTimeIndicator(f.lockKind, std::llround((t - tr.lockStart) * 1000.0));
          cells.push_back(co);
        }
      }
      payloads.push_back(msmPayload(header, f, group, rough, cellMask, cells));
    }
  }
  return framedEpoch(payloads);
}

}  // namespace gvins::rtcm
