// Framing, dispatch, error handling, time resolution and epoch assembly of the RTCM 3 decoder.
#include <algorithm>
#include <cmath>
#include <ctime>

#include "decoder_state.hpp"
#include "gvins/base/parse_error.hpp"
#include "gvins/rtcm/message_types.hpp"
#include "ssr_layout.hpp"

namespace gvins::rtcm {
namespace {

GpsTime hostClockGpst() {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  CalendarTime c;
  c.year = tm.tm_year + 1900;
  c.month = tm.tm_mon + 1;
  c.day = tm.tm_mday;
  c.hour = tm.tm_hour;
  c.minute = tm.tm_min;
  c.second = tm.tm_sec;
  return utcToGpst(c);
}

// Epoch times of different messages of one epoch agree to the millisecond resolution of the
// time fields.
constexpr double kSameEpoch = 5e-4;

void closeEpoch(Decoder::State& s) {
  if (!s.open) return;
  ObsEpoch& e = *s.open;
  if (!s.stats.firstEpoch || e.time < *s.stats.firstEpoch) s.stats.firstEpoch = e.time;
  if (!s.stats.lastEpoch || e.time > *s.stats.lastEpoch) s.stats.lastEpoch = e.time;
  ++s.stats.epochs;
  s.lastClosed = e.time;
  s.lastClosedHasOthers = s.openHasOthers;
  s.out.emplace_back(std::move(e));
  s.open.reset();
}

}  // namespace

// ---- helpers ----------------------------------------------------------------------------------

std::uint8_t lossOfLock(Decoder::State& s, SatId sat, ObsCode code, const GpsTime& t,
                        LockTimeKind kind, int indicator) {
  SignalTrack& tr = track(s, sat, code);
  const std::int64_t minMs = lockTimeMinMs(kind, indicator);
  const std::int64_t maxMs = lockTimeMaxMs(kind, indicator);
  bool lost = false;
  if (tr.valid) {
    const double dt = t - tr.last;
    if (dt > 0.0) {
      lost = lockLost(tr.lockMinMs, minMs, maxMs, std::llround(dt * 1000.0));
    } else if (dt < 0.0) {
      lost = true;  // time went backwards: nothing can be assumed about continuity
    }
  } else if (s.lastClosed && t - *s.lastClosed > 0.0) {
    // First observation of a signal in a running stream (a rising satellite, a new signal): its
    // phase starts a new ambiguity for every user, so it is flagged whatever the lock time says.
    lost = true;
  } else {
    // First epoch of the stream: only a lock shorter than the indicator's first step is known to
    // have just started.
    lost = minMs == 0;
  }
  tr.last = t;
  tr.lockMinMs = minMs;
  tr.valid = true;
  if (lost) {
    tr.rolloverCycles = 0.0;
    tr.hasRawDiff = false;
  }
  return lost ? 1 : 0;
}

void noteRange(Decoder::State& s, SatId sat, const GpsTime& t, double metres) {
  s.ranges[static_cast<std::size_t>(satIndex(sat))] = {t, metres, true};
}

std::optional<double> resolveRange(const Decoder::State& s, SatId sat, const GpsTime& t, double modulo, double unit) {
  const Decoder::State::RangeTrack& rt = s.ranges[static_cast<std::size_t>(satIndex(sat))];
  if (!rt.valid || std::abs(t - rt.t) > 120.0) return std::nullopt;
  return modulo + unit * std::round((rt.metres - modulo) / unit);
}

void mergeSignal(SatObs& so, const SignalObs& sig) {
  SignalObs* have = so.find(sig.code);
  if (!have) {
    so.signals.push_back(sig);
    return;
  }
  if (!have->hasCode() && sig.hasCode()) have->setCode(sig.pseudorange);
  if (!have->hasPhase() && sig.hasPhase()) {
    have->setPhase(sig.carrierPhase);
    have->lli |= sig.lli;
  }
  if (!have->hasDoppler() && sig.hasDoppler()) have->setDoppler(sig.doppler);
  if (!have->hasSnr() && sig.hasSnr()) have->setSnr(sig.snr);
}

GpsTime resolveTow(const Decoder::State& s, double towSeconds) {
  return nearestTow(towSeconds, s.ref);
}

GpsTime resolveGlonassTimeOfDay(const Decoder::State& s, double todSeconds) {
  // Moscow time of day of the reference: GPST - (GPST-UTC) + 3 h (GLONASS ICD 5.1, 3.3.3).
  const std::int64_t leap = leapSecondsAtGpst(s.ref);
  const std::int64_t glo = s.ref.wholeSeconds() - leap + 10800;
  const double refTod = static_cast<double>(((glo % 86400) + 86400) % 86400) + s.ref.fraction();
  double d = todSeconds - refTod;
  if (d >= 43200.0) d -= 86400.0;
  if (d < -43200.0) d += 86400.0;
  return s.ref + d;
}

GpsTime checkBeidouStamp(Decoder::State& s, const GpsTime& asBdt, bool& asBdtKept) {
  asBdtKept = false;
  const GpsTime asGpst = asBdt + kBdtMinusGpst;  // the same TOW read as GPST
  auto matches = [&](const GpsTime& t) {
    if (s.open && s.openHasOthers && std::abs(t - s.open->time) < 1e-3) return true;
    return !s.open && s.lastClosed && s.lastClosedHasOthers && std::abs(t - *s.lastClosed) < 1e-3;
  };
  const bool bdt = matches(asBdt), gpst = matches(asGpst);
  if (bdt) s.beidouInGpst = false;
  if (gpst && !bdt) s.beidouInGpst = true;
  // Once seen, the stamping is assumed for BeiDou messages that have no other epoch to compare
  // with (e.g. sent before the other systems' messages of their epoch).
  if ((gpst && !bdt) || (!bdt && s.beidouInGpst)) {
    ++s.stats.beidouGpstEpochs;
    return asGpst;
  }
  asBdtKept = true;
  return asBdt;
}

void addObservations(Decoder::State& s, System system, const GpsTime& t, bool more,
                     std::vector<SatObs>& sats, bool beidouAsBdt) {
  // A BeiDou-only epoch read as BDT that lies exactly 14 s after the first other system's
  // message: the BeiDou time was GPST (its message came first in the epoch). Retime it.
  if (system != System::BeiDou && s.open && !s.openHasOthers && s.openBeidouAsBdt > 0 &&
      std::abs(s.open->time + kBdtMinusGpst - t) < 1e-3) {
    s.open->time = t;
    s.beidouInGpst = true;
    s.stats.beidouGpstEpochs += s.openBeidouAsBdt;
    s.openBeidouAsBdt = 0;
  }
  if (s.open && std::abs(t - s.open->time) > kSameEpoch) closeEpoch(s);
  if (!s.open) {
    s.open.emplace();
    s.open->time = t;
    s.openHasOthers = false;
    s.openBeidouAsBdt = 0;
  }
  if (system == System::BeiDou && beidouAsBdt) ++s.openBeidouAsBdt;
  if (system != System::BeiDou) s.openHasOthers = true;
  for (SatObs& so : sats) {
    if (so.signals.empty()) continue;
    SatObs* have = s.open->find(so.sat);
    if (!have) {
      s.open->sats.push_back(std::move(so));
      continue;
    }
    for (const SignalObs& sig : so.signals) mergeSignal(*have, sig);
  }
  s.ref = t;
  if (!more) closeEpoch(s);
}

void learnAbsoluteTime(Decoder::State& s, const GpsTime& t) {
  if (s.refAbsolute) return;
  s.refAbsolute = true;
  if (std::abs(t - s.ref) > 86400.0) s.ref = t;
}

// ---- Decoder ----------------------------------------------------------------------------------

Decoder::Decoder(DecoderOptions options) : s_(std::make_unique<State>()) {
  s_->opt = std::move(options);
  s_->channels = s_->opt.glonassChannels;
  if (s_->opt.referenceTime) {
    s_->ref = *s_->opt.referenceTime;
    s_->refAbsolute = true;
  } else {
    s_->ref = hostClockGpst();
  }
}

Decoder::~Decoder() = default;
Decoder::Decoder(Decoder&&) noexcept = default;
Decoder& Decoder::operator=(Decoder&&) noexcept = default;

void Decoder::feed(std::span<const std::uint8_t> bytes) {
  s_->framer.feed(bytes);
  Frame f;
  while (s_->framer.next(f)) decodeMessage(f.payload, f.offset);
  s_->stats.framing = s_->framer.stats();
}

void Decoder::finish() {
  s_->framer.finish();
  Frame f;
  while (s_->framer.next(f)) decodeMessage(f.payload, f.offset);
  s_->stats.framing = s_->framer.stats();
  closeEpoch(*s_);
}

std::optional<Decoded> Decoder::poll() {
  if (s_->out.empty()) return std::nullopt;
  Decoded d = std::move(s_->out.front());
  s_->out.pop_front();
  return d;
}

void Decoder::decodeMessage(std::span<const std::uint8_t> payload, std::int64_t offset) {
  State& s = *s_;
  s.offset = offset;
  if (payload.size() < 2) {
    ++s.stats.messages[-1];
    ++s.stats.unsupported;
    return;
  }
  const int type = (payload[0] << 4) | (payload[1] >> 4);
  s.type = type;
  ++s.stats.messages[type];
  if (!isDecodedType(type)) {
    ++s.stats.unsupported;
    return;
  }
  BitReader r(payload);
  r.skip(12, "DF002 message number");
  try {
    if (type >= 1001 && type <= 1004) {
      decodeLegacyGps(s, r, type);
    } else if (type >= 1009 && type <= 1012) {
      decodeLegacyGlonass(s, r, type);
    } else if (type == 1005 || type == 1006) {
      decodeStationPosition(s, r, type);
    } else if (type == 1007 || type == 1008 || type == 1033) {
      decodeAntenna(s, r, type);
    } else if (type == 1019) {
      decodeGpsEphemeris(s, r);
    } else if (type == 1020) {
      decodeGlonassEphemeris(s, r);
    } else if (type == 1042) {
      decodeBeidouEphemeris(s, r);
    } else if (type == 1044) {
      decodeQzssEphemeris(s, r);
    } else if (type == 1045 || type == 1046) {
      decodeGalileoEphemeris(s, r, type == 1046);
    } else if (type == 1230) {
      decodeGlonassBiases(s, r);
    } else if (ssr::messageKind(type)) {
      decodeSsr(s, r, type);
    } else if (const auto k = msmKind(type)) {
      decodeMsm(s, r, k->system, k->msm);
    }
    ++s.stats.decoded;
  } catch (const MessageError& e) {
    ++s.stats.malformed;
    const std::string what = "message " + std::to_string(type) + " in frame at byte " +
                             std::to_string(offset) + ": " + e.what();
    if (s.opt.strict) throw ParseError(s.opt.streamName, offset, e.field(), what);
    if (s.stats.issues.size() < s.opt.maxIssues) {
      s.stats.issues.push_back(DecodeIssue{offset, type, e.field(), what});
    }
  }
}

const DecoderStats& Decoder::stats() const { return s_->stats; }
const StationInfo& Decoder::station() const { return s_->station; }
const std::optional<StationPosition>& Decoder::stationPosition() const { return s_->stationPos; }
const GlonassChannels& Decoder::glonassChannels() const { return s_->channels; }
const std::optional<GlonassCodePhaseBiases>& Decoder::glonassBiases() const { return s_->biases; }
GpsTime Decoder::referenceTime() const { return s_->ref; }
bool Decoder::referenceIsAbsolute() const { return s_->refAbsolute; }

}  // namespace gvins::rtcm
