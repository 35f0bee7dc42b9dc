// SSR message encoding (RTCM 10403.3 section 3.5.12): the inverse of decode_ssr.cpp, field by
// field in the order of ssr_layout.hpp. Every value is range-checked before it is written, so a
// value that does not fit its field throws std::invalid_argument naming the field instead of
// wrapping.
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "gvins/rtcm/bit_writer.hpp"
#include "gvins/rtcm/encoder.hpp"
#include "ssr_layout.hpp"

namespace gvins::rtcm {
namespace {

using ssr::SystemLayout;

[[noreturn]] void fail(const std::string& field, const std::string& what) {
  throw std::invalid_argument(field + ": " + what);
}

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

/// v in units of `lsb`, rounded; throws unless it fits a two's complement field of `bits`.
std::int64_t scaled(double v, double lsb, int bits, const char* field) {
  if (!std::isfinite(v)) fail(field, "value is not finite");
  const double q = std::round(v / lsb);
  const double lim = std::ldexp(1.0, bits - 1);
  if (q < -lim || q > lim - 1) {
    fail(field, "value " + num(v) + " is outside [" + num(-lim * lsb) + ", " + num((lim - 1) * lsb) +
                    "] (" + std::to_string(bits) + " bits of " + num(lsb) + ")");
  }
  return static_cast<std::int64_t>(q);
}

/// An integer field of `bits` unsigned bits; throws unless 0 <= v < 2^bits.
std::uint64_t unsignedField(long long v, int bits, const char* field) {
  if (v < 0 || v >= (1LL << bits)) {
    fail(field, "value " + std::to_string(v) + " does not fit " + std::to_string(bits) + " unsigned bits");
  }
  return static_cast<std::uint64_t>(v);
}

/// A time in seconds that must be whole (the SSR epoch time has a resolution of 1 s).
long long wholeSeconds(double t, const char* field) {
  const double r = std::round(t);
  if (std::abs(t - r) > 1e-6) fail(field, "epoch " + num(t) + " s is not a whole second");
  return static_cast<long long>(r);
}

void writeEpoch(BitWriter& w, const SystemLayout& L, const GpsTime& epoch) {
  long long v = 0;
  if (L.system == System::Glonass) {
    // Seconds of the GLONASS day (Moscow time, UTC + 3 h).
    const CalendarTime c = gpstToGlonass(epoch);
    v = wholeSeconds(c.hour * 3600.0 + c.minute * 60.0 + c.second, L.epochField) % 86400;
  } else if (L.system == System::BeiDou) {
    int week = 0;
    double sow = 0.0;
    gpstToBdt(epoch, week, sow);
    v = wholeSeconds(sow, L.epochField) % 604800;
  } else {
    v = wholeSeconds(epoch.tow(), L.epochField) % 604800;
  }
  w.u(L.epochBits, unsignedField(v, L.epochBits, L.epochField), L.epochField);
}

std::uint64_t updateIntervalIndex(double seconds) {
  for (std::size_t i = 0; i < kSsrUpdateIntervals.size(); ++i) {
    if (std::abs(kSsrUpdateIntervals[i] - seconds) < 1e-9) return i;
  }
  fail("DF391 SSR update interval",
       num(seconds) + " s is not one of 1, 2, 5, 10, 15, 30, 60, 120, 240, 300, 600, 900, 1800, 3600, 7200, 10800");
}

void writeOrbit(BitWriter& w, const SystemLayout& L, const SsrOrbitCorrection& o) {
  w.u(L.iodBits, unsignedField(o.issueOfData, L.iodBits, L.iodField), L.iodField);
  if (L.iod2Bits > 0) w.u(L.iod2Bits, unsignedField(o.iodCrc, L.iod2Bits, L.iod2Field), L.iod2Field);
  w.s(22, scaled(o.rac.x(), ssr::kRadialLsb, 22, "DF365 delta radial"), "DF365 delta radial");
  w.s(20, scaled(o.rac.y(), ssr::kAlongCrossLsb, 20, "DF366 delta along-track"), "DF366 delta along-track");
  w.s(20, scaled(o.rac.z(), ssr::kAlongCrossLsb, 20, "DF367 delta cross-track"), "DF367 delta cross-track");
  w.s(21, scaled(o.racRate.x(), ssr::kRadialRateLsb, 21, "DF368 dot delta radial"), "DF368 dot delta radial");
  w.s(19, scaled(o.racRate.y(), ssr::kAlongCrossRateLsb, 19, "DF369 dot delta along-track"),
      "DF369 dot delta along-track");
  w.s(19, scaled(o.racRate.z(), ssr::kAlongCrossRateLsb, 19, "DF370 dot delta cross-track"),
      "DF370 dot delta cross-track");
}

void writeClock(BitWriter& w, const SsrClockCorrection& c) {
  w.s(22, scaled(c.c0, ssr::kC0Lsb, 22, "DF376 delta clock C0"), "DF376 delta clock C0");
  w.s(21, scaled(c.c1, ssr::kC1Lsb, 21, "DF377 delta clock C1"), "DF377 delta clock C1");
  w.s(27, scaled(c.c2, ssr::kC2Lsb, 27, "DF378 delta clock C2"), "DF378 delta clock C2");
}

std::vector<std::uint8_t> encode(const SsrMessage& m) {
  const SsrHeader& h = m.header;
  const SystemLayout* layout = ssr::layoutOf(h.system);
  if (!layout) fail("DF002 message number", "no SSR messages are encoded for " + std::string(systemName(h.system)));
  const SystemLayout& L = *layout;
  const int type = ssr::messageNumber(h.system, h.kind);
  if (h.messageType != 0 && h.messageType != type) {
    fail("DF002 message number", "header says " + std::to_string(h.messageType) + ", but " +
                                     std::string(systemName(h.system)) + " and this kind are " + std::to_string(type));
  }
  if (m.satellites.size() > 63) {
    fail("DF387 number of satellites", std::to_string(m.satellites.size()) + " satellites exceed 63");
  }

  BitWriter w;
  w.u(12, static_cast<std::uint64_t>(type), "DF002 message number");
  writeEpoch(w, L, h.epoch);
  w.u(4, updateIntervalIndex(h.updateInterval), "DF391 SSR update interval");
  w.flag(h.multipleMessage);  // DF388
  if (ssr::hasOrbit(h.kind)) w.flag(h.regionalDatum);  // DF375
  w.u(4, unsignedField(h.iodSsr, 4, "DF413 IOD SSR"), "DF413 IOD SSR");
  w.u(16, unsignedField(h.providerId, 16, "DF414 SSR provider ID"), "DF414 SSR provider ID");
  w.u(4, unsignedField(h.solutionId, 4, "DF415 SSR solution ID"), "DF415 SSR solution ID");
  w.u(6, m.satellites.size(), "DF387 number of satellites");

  for (const SsrSatellite& s : m.satellites) {
    if (s.sat.system != h.system || !s.sat.valid()) {
      fail(L.satField, "satellite " + s.sat.str() + " is not a valid " + std::string(systemName(h.system)) +
                           " satellite");
    }
    const std::string name = s.sat.str();
    w.u(L.satBits, unsignedField(s.sat.prn, L.satBits, L.satField), L.satField);
    auto need = [&](bool has, const char* what) {
      if (!has) fail(what, name + " has none in a " + std::to_string(type) + " message");
    };
    switch (h.kind) {
      case SsrKind::kOrbit:
        need(s.orbit.has_value(), "orbit correction");
        writeOrbit(w, L, *s.orbit);
        break;
      case SsrKind::kClock:
        need(s.clock.has_value(), "clock correction");
        writeClock(w, *s.clock);
        break;
      case SsrKind::kCombined:
        need(s.orbit.has_value(), "orbit correction");
        need(s.clock.has_value(), "clock correction");
        writeOrbit(w, L, *s.orbit);
        writeClock(w, *s.clock);
        break;
      case SsrKind::kUra:
        need(s.uraIndex.has_value(), "DF389 SSR URA");
        w.u(6, unsignedField(*s.uraIndex, 6, "DF389 SSR URA"), "DF389 SSR URA");
        break;
      case SsrKind::kHighRateClock:
        need(s.highRateClock.has_value(), "DF390 high rate clock correction");
        w.s(22, scaled(*s.highRateClock, ssr::kHighRateClockLsb, 22, "DF390 high rate clock correction"),
            "DF390 high rate clock correction");
        break;
      case SsrKind::kCodeBias:
        if (s.codeBiases.size() > 31) {
          fail("DF379 number of code biases", name + ": " + std::to_string(s.codeBiases.size()) + " biases exceed 31");
        }
        w.u(5, s.codeBiases.size(), "DF379 number of code biases");
        for (const auto& [code, bias] : s.codeBiases) {
          const auto id = ssr::signalIdentifier(h.system, code);
          if (!id) fail(L.signalField, name + ": signal " + code.str() + " has no identifier");
          w.u(5, static_cast<std::uint64_t>(*id), L.signalField);
          w.s(14, scaled(bias, ssr::kCodeBiasLsb, 14, "DF383 code bias"), "DF383 code bias");
        }
        break;
    }
  }
  if (w.bytes().size() > 1023) {
    fail("message length", std::to_string(w.bytes().size()) + " bytes exceed 1023: split the satellites over several messages");
  }
  return Encoder::frame(w.bytes());
}

}  // namespace

std::vector<std::uint8_t> Encoder::ssr(const SsrMessage& m) const {
  try {
    return encode(m);
  } catch (const MessageError& e) {
    // BitWriter's own range checks (not expected after the checks above): same contract.
    throw std::invalid_argument(e.what());
  }
}

}  // namespace gvins::rtcm
