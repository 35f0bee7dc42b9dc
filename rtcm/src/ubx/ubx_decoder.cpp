#include "gvins/ubx/ubx_decoder.hpp"

#include <cmath>
#include <cstdio>
#include <deque>
#include <tuple>

#include "gvins/base/parse_error.hpp"
#include "gvins/rtcm/message_error.hpp"
#include "gvins/ubx/rawx.hpp"
#include "gvins/ubx/sfrbx.hpp"
#include "gvins/ubx/sfrbx_error.hpp"
#include "gvins/ubx/ubx_signals.hpp"

namespace gvins::ubx {

namespace {

// Phase tracking state of one signal, for the loss-of-lock flags.
struct LockState {
  GpsTime lastPhase;
  std::uint16_t locktime = 0;
  bool halfSubtracted = false;
};

std::string messageName(int type) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%02X-0x%02X", (type >> 8) & 0xFF, type & 0xFF);
  return buf;
}

}  // namespace

struct Decoder::State {
  DecoderOptions opt;
  StreamSplitter splitter;
  DecoderStats stats;
  std::deque<Decoded> out;
  GlonassChannels glonass;
  NavigationAssembler navigation;
  std::map<std::tuple<int, char, char>, LockState> locks;  // (satIndex, band, attr)
  std::optional<GpsTime> lastEpoch;
  std::int64_t rawxEpochs = 0;

  explicit State(DecoderOptions o) : opt(std::move(o)), splitter(opt.maxPayload) {}

  void drain() {
    StreamFrame f;
    while (splitter.next(f)) {
      if (f.kind != StreamKind::Ubx) continue;  // NMEA and RTCM are only counted
      const Frame u = f.ubx();
      decode(u.msgClass, u.msgId, u.payload, u.offset);
    }
    stats.stream = splitter.stats();
  }

  void decode(std::uint8_t cls, std::uint8_t id, std::span<const std::uint8_t> p, std::int64_t offset) {
    const int type = (cls << 8) | id;
    ++stats.messages[type];
    try {
      if (cls == kClassRxm && id == kIdRawx) {
        rawx(parseRawx(p));
      } else if (cls == kClassRxm && id == kIdSfrbx) {
        ++stats.sfrbx;
        if (!opt.decodeNavigation) return;
        const SfrbxMessage msg = parseSfrbx(p);
        // Before the first RAWX epoch the assembler gets "time not known yet" (GpsTime{}): it keeps
        // what it cannot date until a later message brings a time.
        if (!lastEpoch) ++stats.sfrbxUndated;
        NavDataUpdate u = navigation.add(msg, lastEpoch.value_or(GpsTime{}));
        if (!u.empty()) {
          stats.ephemerides += static_cast<std::int64_t>(u.kepler.size() + u.glonass.size());
          out.emplace_back(std::move(u));
        }
      } else if (cls == kClassNav && id == kIdNavPvt) {
        out.emplace_back(parseNavPvt(p));
      } else if (cls == kClassNav && id == kIdNavClock) {
        out.emplace_back(parseNavClock(p));
      } else if (cls == kClassNav && id == kIdNavTimeGps) {
        const NavTimeGps t = parseNavTimeGps(p);
        if (t.leapValid()) stats.leapSeconds = t.leapS;
        out.emplace_back(t);
      } else if (cls == kClassEsf && id == kIdEsfRaw) {
        for (const ImuSample& s : parseEsfRaw(p)) {
          out.emplace_back(s);
          ++stats.imuSamples;
        }
      } else if (cls == kClassEsf && id == kIdEsfMeas) {
        out.emplace_back(parseEsfMeas(p));
        ++stats.imuSamples;
      } else {
        return;  // counted only
      }
      ++stats.decoded;
    } catch (const rtcm::MessageError& e) {
      malformed(offset, type, e.field(), e.what());
    } catch (const SfrbxError& e) {
      malformed(offset, type, e.field(), e.what());
    }
  }

  void malformed(std::int64_t offset, int type, const std::string& field, const std::string& what) {
    ++stats.malformed;
    if (opt.strict) throw ParseError(opt.streamName, offset, messageName(type) + " " + field, what);
    if (stats.issues.size() < opt.maxIssues) stats.issues.push_back({offset, type, field, what});
  }

  // Loss-of-lock flags of one phase (see the header comment).
  std::uint8_t lockFlags(SatId sat, ObsCode code, const RawxMeasurement& m, const GpsTime& t, bool clockReset) {
    const auto key = std::make_tuple(satIndex(sat), code.band, code.attr);
    auto it = locks.find(key);
    bool slip = clockReset;
    if (it == locks.end()) {
      slip |= rawxEpochs > 1 || m.locktime == 0;
      it = locks.emplace(key, LockState{}).first;
    } else {
      const LockState& prev = it->second;
      const double gapMs = (t - prev.lastPhase) * 1000.0;
      slip |= m.locktime < prev.locktime;
      slip |= static_cast<double>(m.locktime) < gapMs - 0.5;  // re-acquired since the last phase
      slip |= m.halfCycleSubtracted() != prev.halfSubtracted;
    }
    it->second = LockState{t, m.locktime, m.halfCycleSubtracted()};
    std::uint8_t lli = 0;
    if (slip) {
      lli |= 1;
      ++stats.slips;
    }
    if (!m.halfCycleValid()) {
      lli |= 2;
      ++stats.halfCycleUnresolved;
    }
    return lli;
  }

  void rawx(const RawxMessage& msg) {
    if (msg.week == 0) throw rtcm::MessageError("week", "week 0 (receiver time not yet known)");
    ++rawxEpochs;
    const GpsTime t = GpsTime::fromWeekTow(msg.week, msg.rcvTow);
    if (msg.leapSecondsKnown()) stats.leapSeconds = msg.leapS;
    if (msg.clockReset()) ++stats.clockResets;
    stats.measurements += static_cast<std::int64_t>(msg.meas.size());
    ObsEpoch e;
    e.time = t;
    std::int64_t delivered = 0;
    for (const RawxMeasurement& m : msg.meas) {
      const auto sat = satelliteOf(m.gnssId, m.svId);
      if (!sat) {
        ++stats.unknownSatellites;
        continue;
      }
      const auto code = obsCodeOf(m.gnssId, m.sigId);
      if (!code) {
        ++stats.unknownSignals;
        ++stats.unknownSignalIds[{m.gnssId, m.sigId}];
        continue;
      }
      if (sat->system == System::Glonass && m.freqId <= 13) glonass.set(sat->prn, m.freqId - 7);
      SignalObs s;
      s.code = *code;
      if (m.prValid() && std::isfinite(m.prMes) && m.prMes > 0.0) s.setCode(m.prMes);
      bool phaseOk = m.cpValid() && std::isfinite(m.cpMes) && m.cpMes != 0.0;
      if (phaseOk && opt.maxPhaseStdDev && m.phaseStdDev() > *opt.maxPhaseStdDev + 1e-9) {
        phaseOk = false;
        ++stats.noisyPhases;
      }
      if (phaseOk) {
        s.setPhase(m.cpMes);
        s.lli = lockFlags(*sat, *code, m, t, msg.clockReset());
      }
      if (std::isfinite(m.doMes) && (s.hasCode() || s.hasPhase())) s.setDoppler(m.doMes);
      if (m.cno > 0 && (s.hasCode() || s.hasPhase())) s.setSnr(m.cno);
      if (s.present == 0) continue;
      SatObs& so = e.add(*sat);
      if (so.find(s.code)) continue;  // a second block of one signal (e.g. B1I D1 and D2): first wins
      so.signals.push_back(s);
      ++stats.signalIds[{m.gnssId, m.sigId}];
      ++delivered;
    }
    std::erase_if(e.sats, [](const SatObs& so) { return so.signals.empty(); });
    lastEpoch = t;
    if (e.sats.empty()) {
      ++stats.emptyEpochs;
      return;
    }
    if (!stats.firstEpoch) stats.firstEpoch = t;
    stats.lastEpoch = t;
    ++stats.epochs;
    stats.signalsDelivered += delivered;
    out.emplace_back(std::move(e));
  }
};

Decoder::Decoder(DecoderOptions options) : s_(std::make_unique<State>(std::move(options))) {}
Decoder::~Decoder() = default;
Decoder::Decoder(Decoder&&) noexcept = default;
Decoder& Decoder::operator=(Decoder&&) noexcept = default;

void Decoder::feed(std::span<const std::uint8_t> bytes) {
  s_->splitter.feed(bytes);
  s_->drain();
}

void Decoder::finish() {
  s_->splitter.finish();
  s_->drain();
}

std::optional<Decoded> Decoder::poll() {
  if (s_->out.empty()) return std::nullopt;
  Decoded d = std::move(s_->out.front());
  s_->out.pop_front();
  return d;
}

void Decoder::decodeMessage(std::uint8_t msgClass, std::uint8_t msgId, std::span<const std::uint8_t> payload,
                            std::int64_t offset) {
  s_->decode(msgClass, msgId, payload, offset);
}

const DecoderStats& Decoder::stats() const { return s_->stats; }
const GlonassChannels& Decoder::glonassChannels() const { return s_->glonass; }
NavigationCounts Decoder::navigationCounts() const { return s_->navigation.total(); }
const NavigationAssembler& Decoder::navigationAssembler() const { return s_->navigation; }
std::optional<GpsTime> Decoder::lastEpochTime() const { return s_->lastEpoch; }

}  // namespace gvins::ubx
