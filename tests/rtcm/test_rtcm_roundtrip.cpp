// Encoder round trips: MSM4/MSM7 of real observations of all six systems (from RTCM logs and from
// a RINEX file whose values lie off the message grid), 1005/1006 and every
// ephemeris message decode back to the same values within the message resolution; decoded
// ephemerides agree with RTKLIB's navigation file and feed the same EphemerisStore as RINEX.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "gvins/base/constants.hpp"
#include "gvins/base/rinex_obs_reader.hpp"
#include "gvins/ephemeris/ephemeris_store.hpp"
#include "gvins/ephemeris/rinex_nav.hpp"
#include "gvins/rtcm/decoder.hpp"
#include "gvins/rtcm/encoder.hpp"
#include "gvins/rtcm/framer.hpp"
#include "gvins/rtcm/msm_signals.hpp"
#include "independent_frame_scan.hpp"

namespace gvins::rtcm {
namespace {

using testing::dataDir;
using testing::readBytes;

constexpr double kLightMs = constants::kSpeedOfLight * 1e-3;

GpsTime noon(int y, int m, int d) {
  CalendarTime c;
  c.year = y;
  c.month = m;
  c.day = d;
  c.hour = 12;
  return GpsTime::fromCalendar(c);
}

struct Items {
  std::vector<ObsEpoch> epochs;
  std::vector<KeplerEphemeris> kepler;
  std::vector<GlonassEphemeris> glonass;
  std::vector<StationPosition> stations;
};

Items decode(const std::vector<std::uint8_t>& bytes, const GpsTime& ref, Decoder* keep = nullptr) {
  DecoderOptions opt;
  opt.referenceTime = ref;
  Decoder local(opt);
  Decoder& dec = keep ? *keep : local;
  dec.feed(bytes);
  dec.finish();
  Items it;
  while (auto d = dec.poll()) {
    if (auto* e = std::get_if<ObsEpoch>(&*d)) it.epochs.push_back(*e);
    else if (auto* k = std::get_if<KeplerEphemeris>(&*d)) it.kepler.push_back(*k);
    else if (auto* g = std::get_if<GlonassEphemeris>(&*d)) it.glonass.push_back(*g);
    else if (auto* s = std::get_if<StationPosition>(&*d)) it.stations.push_back(*s);
  }
  EXPECT_EQ(dec.stats().malformed, 0);
  return it;
}

struct Source {
  const char* file;
  GpsTime ref;
};

struct RoundTripStats {
  std::int64_t signals = 0;
  double code = 0, phase = 0, doppler = 0, snr = 0;  // max errors: m, m, m/s, dB-Hz
  std::set<int> systems;
};

/// Encodes every epoch as MSM`type`, decodes the stream and compares signal by signal.
/// `name` labels failures; `channels` are the GLONASS FDMA channels of the input.
void roundTripEpochs(const std::vector<ObsEpoch>& inEpochs, const GlonassChannels& channels, const GpsTime& ref,
                     const std::string& name, int type, RoundTripStats& st) {
  ASSERT_FALSE(inEpochs.empty()) << name;
  Encoder enc(1234);
  enc.setGlonassChannels(channels);
  std::vector<std::uint8_t> stream;
  for (const ObsEpoch& e : inEpochs) {
    const auto f = enc.msm(e, type);
    stream.insert(stream.end(), f.begin(), f.end());
  }
  DecoderOptions o;
  o.referenceTime = ref;
  o.glonassChannels = channels;  // MSM4 carries no channel numbers
  Decoder dec(o);
  dec.feed(stream);
  dec.finish();
  std::vector<ObsEpoch> out;
  while (auto d = dec.poll()) {
    if (auto* e = std::get_if<ObsEpoch>(&*d)) out.push_back(*e);
  }
  EXPECT_EQ(dec.stats().malformed, 0);
  EXPECT_EQ(dec.stats().framing.crcFailures, 0);
  ASSERT_EQ(out.size(), inEpochs.size()) << name;

  std::map<std::pair<int, std::string>, GpsTime> lastSeen;  // for the expected loss-of-lock flags
  const ObsEpoch* prev = nullptr;
  for (std::size_t i = 0; i < out.size(); ++i) {
    const ObsEpoch& a = inEpochs[i];
    const ObsEpoch& b = out[i];
    ASSERT_EQ(b.time, a.time);
    for (const SatObs& sa : a.sats) {
      const SatObs* sb = b.find(sa.sat);
      const bool anyMsm = std::any_of(sa.signals.begin(), sa.signals.end(), [&](const SignalObs& s) {
        return msmSignalId(sa.sat.system, s.code).has_value() && (s.present & (SignalObs::kCode | SignalObs::kPhase));
      });
      if (!anyMsm) continue;
      ASSERT_NE(sb, nullptr) << sa.sat.str() << " " << name;
      st.systems.insert(systemIndex(sa.sat.system));
      const std::optional<int> ch = sa.sat.system == System::Glonass ? channels.get(sa.sat.prn) : std::optional<int>();
      for (const SignalObs& ga : sa.signals) {
        if (!msmSignalId(sa.sat.system, ga.code)) continue;
        const SignalObs* gb = sb->find(ga.code);
        ASSERT_NE(gb, nullptr) << sa.sat.str() << " " << ga.code.str();
        ++st.signals;
        const double lam = *carrierWavelength(sa.sat.system, ga.code.band, ch);
        EXPECT_EQ(gb->hasCode(), ga.hasCode()) << name << " " << sa.sat.str() << " " << ga.code.str() << " epoch " << i
                                               << ": " << ga.pseudorange << " -> " << gb->pseudorange;
        if (ga.hasCode()) st.code = std::max(st.code, std::abs(gb->pseudorange - ga.pseudorange));
        EXPECT_EQ(gb->hasPhase(), ga.hasPhase()) << name << " " << sa.sat.str() << " " << ga.code.str();
        if (ga.hasPhase()) st.phase = std::max(st.phase, std::abs(gb->carrierPhase - ga.carrierPhase) * lam);
        if (type == 7 && ga.hasDoppler()) {
          EXPECT_TRUE(gb->hasDoppler());
          st.doppler = std::max(st.doppler, std::abs(gb->doppler - ga.doppler) * lam);
        }
        EXPECT_EQ(gb->hasSnr(), ga.hasSnr() && ga.snr >= (type == 7 ? 1.0 / 32 : 0.5));
        if (gb->hasSnr()) st.snr = std::max(st.snr, std::abs(gb->snr - ga.snr));
        // Loss of lock: flagged where the input flags it, at a signal's first epoch and after a
        // gap; the half-cycle flag passes through.
        const auto key = std::make_pair(satIndex(sa.sat), ga.code.str());
        const auto it = lastSeen.find(key);
        const bool gap = it == lastSeen.end() || !prev || it->second != prev->time;
        const int expectLli = ((ga.lli & 1) || gap ? 1 : 0) | (ga.lli & 2);
        EXPECT_EQ(gb->lli & 3, expectLli) << sa.sat.str() << " " << ga.code.str() << " epoch " << i;
        lastSeen[key] = a.time;
      }
    }
    prev = &a;
  }
}

/// The same for the observation epochs decoded from an RTCM log.
void roundTrip(const Source& src, int type, RoundTripStats& st) {
  Decoder original([&] {
    DecoderOptions o;
    o.referenceTime = src.ref;
    return o;
  }());
  const Items in = decode(readBytes(dataDir() / "rtcm" / src.file), src.ref, &original);
  roundTripEpochs(in.epochs, original.glonassChannels(), src.ref, src.file, type, st);
}

const Source kSources[] = {
    {"rtklib_GMSD7_20121014.rtcm3", noon(2012, 10, 13)},       // GPS, GLONASS, QZSS, BeiDou MSM7
    {"rtklib_testglo.rtcm3", noon(2009, 12, 18)},              // GPS, GLONASS, SBAS legacy 1004/1012
    {"pyrtcm_pygpsdata-NTRIP-USCL00CHL0.log", noon(2024, 3, 13)},  // all systems incl. SBAS MSM, Galileo
    {"pyrtcm_pygpsdata-MIXED-RTCM3.log", noon(2021, 1, 1)},    // Galileo MSM7
};

TEST(RoundTrip, Msm7AllSystems) {
  RoundTripStats st;
  for (const Source& s : kSources) roundTrip(s, 7, st);
  std::cerr << "MSM7: " << st.signals << " signals, systems " << st.systems.size() << ", max |dC| " << st.code
            << " m, |dL| " << st.phase << " m, |dD| " << st.doppler << " m/s, |dS| " << st.snr << " dB-Hz\n";
  EXPECT_EQ(st.systems, (std::set<int>{0, 1, 2, 3, 4, 5}));  // GPS GLONASS Galileo BeiDou QZSS SBAS
  // Half a least significant bit: code 2^-30 ms, phase 2^-32 ms, Doppler 0.00005 m/s, C/N0 1/32.
  EXPECT_LE(st.code, std::ldexp(kLightMs, -30) + 1e-7);  // + rounding of the metre/ms conversions
  EXPECT_LE(st.phase, std::ldexp(kLightMs, -32) + 1e-7);
  EXPECT_LE(st.doppler, 0.00005 + 1e-9);
  EXPECT_LE(st.snr, 1.0 / 32 + 1e-12);
  EXPECT_GT(st.signals, 20000);
}

TEST(RoundTrip, Msm4AllSystems) {
  RoundTripStats st;
  for (const Source& s : kSources) roundTrip(s, 4, st);
  std::cerr << "MSM4: " << st.signals << " signals, max |dC| " << st.code << " m, |dL| " << st.phase
            << " m, |dS| " << st.snr << " dB-Hz\n";
  EXPECT_EQ(st.systems, (std::set<int>{0, 1, 2, 3, 4, 5}));
  EXPECT_LE(st.code, std::ldexp(kLightMs, -25) + 1e-7);  // + rounding of the metre/ms conversions
  EXPECT_LE(st.phase, std::ldexp(kLightMs, -30) + 1e-7);
  EXPECT_LE(st.snr, 0.5 + 1e-12);
}

// The RTCM logs above carry values already on a message grid (an MSM7 Doppler decoded from MSM7
// re-encodes exactly), so they cannot show how the encoder rounds Doppler and MSM7 C/N0. RINEX
// values (code, phase and Doppler to 0.001 m, cycle and Hz) lie off that grid: a real Septentrio
// rover file with GPS, GLONASS, Galileo, BeiDou and QZSS on three bands each, all with Doppler,
// must come back within half a least significant bit of each MSM field (RTCM 10403.3 DF400,
// DF401, DF404/DF405, DF406, DF403/DF408), and the largest errors must come close to that half
// bit (the values really were rounded).
TEST(RoundTrip, RinexObservationsOffTheMessageGrid) {
  RinexObsReader r((dataDir() / "gnss/nagoya_static_2024/rover.obs.gz").string());
  std::vector<ObsEpoch> epochs;
  ObsEpoch e;
  while (epochs.size() < 60 && r.next(e)) epochs.push_back(e);
  ASSERT_EQ(epochs.size(), 60u);
  const double halfCode7 = std::ldexp(kLightMs, -30), halfPhase7 = std::ldexp(kLightMs, -32);
  const double halfCode4 = std::ldexp(kLightMs, -25), halfPhase4 = std::ldexp(kLightMs, -30);
  {
    RoundTripStats st;
    roundTripEpochs(epochs, r.header().glonassChannels, epochs.front().time, "nagoya rover.obs", 7, st);
    std::cerr << "MSM7 from RINEX: " << st.signals << " signals, max |dC| " << st.code << " m, |dL| " << st.phase
              << " m, |dD| " << st.doppler << " m/s, |dS| " << st.snr << " dB-Hz\n";
    EXPECT_EQ(st.systems, (std::set<int>{0, 1, 2, 3, 4}));  // GPS GLONASS Galileo BeiDou QZSS
    EXPECT_GT(st.signals, 60 * 100);
    EXPECT_LE(st.code, halfCode7 + 1e-7);
    EXPECT_LE(st.phase, halfPhase7 + 1e-7);
    EXPECT_LE(st.doppler, 0.00005 + 1e-9);
    EXPECT_LE(st.snr, 1.0 / 32 + 1e-12);
    EXPECT_GT(st.code, 0.8 * halfCode7);
    EXPECT_GT(st.phase, 0.8 * halfPhase7);
    EXPECT_GT(st.doppler, 0.8 * 0.00005);
    EXPECT_GT(st.snr, 0.8 / 32);
  }
  {
    RoundTripStats st;
    roundTripEpochs(epochs, r.header().glonassChannels, epochs.front().time, "nagoya rover.obs", 4, st);
    std::cerr << "MSM4 from RINEX: " << st.signals << " signals, max |dC| " << st.code << " m, |dL| " << st.phase
              << " m, |dS| " << st.snr << " dB-Hz\n";
    EXPECT_EQ(st.systems, (std::set<int>{0, 1, 2, 3, 4}));
    EXPECT_LE(st.code, halfCode4 + 1e-7);
    EXPECT_LE(st.phase, halfPhase4 + 1e-7);
    EXPECT_LE(st.snr, 0.5 + 1e-12);
    EXPECT_GT(st.code, 0.8 * halfCode4);
    EXPECT_GT(st.phase, 0.8 * halfPhase4);
    EXPECT_GT(st.snr, 0.4);
  }
}

TEST(RoundTrip, PhaseFarFromCodeIsShiftedByWholeCyclesAndFlagged) {
  // A phase 20000 cycles (3.8 km) away from the range cannot be sent as a fine value (+-1171 m):
  // the encoder moves it
  // by whole cycles, restarts lock (the decoder flags it) and keeps the same shift while lock lasts.
  ObsEpoch e;
  e.time = GpsTime::fromWeekTow(2200, 1000.0);
  SatObs& s = e.add(SatId(System::Gps, 5));
  SignalObs g;
  g.code = ObsCode('1', 'C');
  g.setCode(21e6);
  const double lam = *carrierWavelength(System::Gps, '1');
  g.setPhase(21e6 / lam + 20000.25);
  s.signals.push_back(g);
  Encoder enc;
  std::vector<std::uint8_t> stream;
  for (int k = 0; k < 3; ++k) {
    ObsEpoch ek = e;
    ek.time = e.time + k;
    ek.sats[0].signals[0].setCode(21e6 + 100.0 * k);
    ek.sats[0].signals[0].setPhase(21e6 / lam + 20000.25 + 100.0 * k / lam);
    const auto f = enc.msm(ek, 7);
    stream.insert(stream.end(), f.begin(), f.end());
  }
  const Items out = decode(stream, e.time);
  ASSERT_EQ(out.epochs.size(), 3u);
  double firstShift = 0.0;
  for (int k = 0; k < 3; ++k) {
    const SignalObs& d = out.epochs[static_cast<std::size_t>(k)].sats[0].signals[0];
    const double shift = d.carrierPhase - (21e6 / lam + 20000.25 + 100.0 * k / lam);
    if (k == 0) firstShift = std::round(shift);
    EXPECT_NEAR(shift, firstShift, 1e-3);                           // whole cycles, kept while locked
    EXPECT_LT(std::abs(d.carrierPhase * lam - d.pseudorange), 1171.0);  // now within the fine field
    EXPECT_EQ(d.lli & 1, k == 0 ? 1 : 0);
  }
  EXPECT_LT(firstShift, -15000.0);
}

TEST(RoundTrip, StationPosition) {
  for (const char* f : {"go-gnss_frames/1005_frame.bin", "go-gnss_frames/1006_frame.bin", "rtklib_testglo.rtcm3"}) {
    const auto bytes = readBytes(dataDir() / "rtcm" / f);
    const Items in = decode(bytes, noon(2020, 1, 1));
    ASSERT_FALSE(in.stations.empty());
    Encoder enc;
    const auto frame = enc.stationPosition(in.stations[0]);
    // The encoder reproduces the original frame byte for byte.
    Framer fr;
    fr.feed(bytes);
    Frame orig;
    while (fr.next(orig) && orig.type() != in.stations[0].messageType) {
    }
    EXPECT_EQ(std::vector<std::uint8_t>(frame.begin() + 3, frame.end() - 3),
              std::vector<std::uint8_t>(orig.payload.begin(), orig.payload.end()))
        << f;
  }
}

void expectSameKepler(const KeplerEphemeris& a, const KeplerEphemeris& b) {
  EXPECT_EQ(a.sat, b.sat);
  EXPECT_EQ(a.message, b.message);
  EXPECT_EQ(a.toe, b.toe);
  EXPECT_EQ(a.toc, b.toc);
  EXPECT_EQ(a.week, b.week);
  EXPECT_EQ(a.toeSeconds, b.toeSeconds);
  EXPECT_EQ(a.iode, b.iode);
  EXPECT_EQ(a.iodc, b.iodc);
  EXPECT_EQ(a.health, b.health);
  EXPECT_EQ(a.ura, b.ura);
  EXPECT_EQ(a.codesOnL2, b.codesOnL2);
  EXPECT_EQ(a.fitInterval, b.fitInterval);
  const double av[] = {a.sqrtA, a.e, a.i0, a.omega0, a.omega, a.m0, a.deltaN, a.omegaDot, a.iDot, a.cuc, a.cus,
                       a.crc, a.crs, a.cic, a.cis, a.af0, a.af1, a.af2, a.tgd[0], a.tgd[1]};
  const double bv[] = {b.sqrtA, b.e, b.i0, b.omega0, b.omega, b.m0, b.deltaN, b.omegaDot, b.iDot, b.cuc, b.cus,
                       b.crc, b.crs, b.cic, b.cis, b.af0, b.af1, b.af2, b.tgd[0], b.tgd[1]};
  for (std::size_t k = 0; k < std::size(av); ++k) EXPECT_EQ(av[k], bv[k]) << "field " << k << " " << a.sat.str();
}

TEST(RoundTrip, EphemerisMessagesOfAllSystems) {
  const Source srcs[] = {{"rtklib_testglo.rtcm3", noon(2009, 12, 18)},
                         {"rtklib_GMSD7_20121014.rtcm3", noon(2012, 10, 13)},
                         {"cssrlib_idd2023229c.rtc", noon(2023, 8, 17)},
                         {"pyrtcm_pygpsdata-NTRIP-USCL00CHL0.log", noon(2024, 3, 13)},
                         {"go-gnss_frames/1042_frame.bin", noon(2020, 1, 1)},
                         {"go-gnss_frames/1044_frame.bin", noon(2020, 1, 1)},
                         {"go-gnss_frames/1045_frame.bin", noon(2020, 1, 1)}};
  std::map<int, int> perType;
  std::int64_t identicalFrames = 0, frames = 0;
  for (const Source& s : srcs) {
    SCOPED_TRACE(s.file);
    const auto bytes = readBytes(dataDir() / "rtcm" / s.file);
    const Items in = decode(bytes, s.ref);
    // Original payloads in stream order, to compare the re-encoded frames byte for byte.
    std::vector<std::vector<std::uint8_t>> orig;
    Framer fr;
    fr.feed(bytes);
    fr.finish();
    Frame f;
    while (fr.next(f)) {
      const int t = f.type();
      if (t == 1019 || t == 1042 || t == 1044 || t == 1045 || t == 1046) orig.emplace_back(f.payload.begin(), f.payload.end());
    }
    ASSERT_EQ(orig.size(), in.kepler.size());
    Encoder enc;
    for (std::size_t k = 0; k < in.kepler.size(); ++k) {
      const auto frame = enc.ephemeris(in.kepler[k]);
      const Items back = decode(frame, in.kepler[k].toe);
      ASSERT_EQ(back.kepler.size(), 1u);
      expectSameKepler(in.kepler[k], back.kepler[0]);
      ++perType[(frame[3] << 4) | (frame[4] >> 4)];
      ++frames;
      const bool same = std::vector<std::uint8_t>(frame.begin() + 3, frame.end() - 3) == orig[k];
      identicalFrames += same;
      if (!same) {
        std::cerr << "differs: " << in.kepler[k].sat.str() << " type " << ((frame[3] << 4) | (frame[4] >> 4)) << ":";
        for (std::size_t b = 0; b < orig[k].size(); ++b) {
          if (frame[3 + b] != orig[k][b]) std::cerr << " byte " << b << " " << int(orig[k][b]) << "->" << int(frame[3 + b]);
        }
        std::cerr << "\n";
      }
    }
    for (const GlonassEphemeris& g : in.glonass) {
      const auto frame = enc.ephemeris(g);
      const Items back = decode(frame, g.toe);
      ASSERT_EQ(back.glonass.size(), 1u);
      const GlonassEphemeris& h = back.glonass[0];
      EXPECT_EQ(h.sat, g.sat);
      EXPECT_EQ(h.frequencyChannel, g.frequencyChannel);
      EXPECT_EQ(h.toe, g.toe);
      EXPECT_EQ(h.tof, g.tof);
      EXPECT_EQ(h.iode, g.iode);
      EXPECT_EQ(h.health, g.health);
      EXPECT_EQ(h.age, g.age);
      EXPECT_EQ(h.accuracy, g.accuracy);
      EXPECT_EQ(h.position, g.position);
      EXPECT_EQ(h.velocity, g.velocity);
      EXPECT_EQ(h.acceleration, g.acceleration);
      EXPECT_EQ(h.tauN, g.tauN);
      EXPECT_EQ(h.gammaN, g.gammaN);
      EXPECT_EQ(h.deltaTauN, g.deltaTauN);
      ++perType[1020];
    }
  }
  std::cerr << "ephemeris round trips:";
  for (auto [t, n] : perType) std::cerr << " " << t << "x" << n;
  std::cerr << "; re-encoded frames identical to the originals: " << identicalFrames << "/" << frames << "\n";
  for (int t : {1019, 1020, 1042, 1044, 1045, 1046}) EXPECT_GT(perType[t], 0) << t;
  EXPECT_EQ(identicalFrames, frames);
}

TEST(Ephemeris, TestgloRecordsMatchRtklibNavigationFile) {
  const NavData ref = readRinexNav((dataDir() / "reference/rtklib-2.4.3/rtcm_testglo_convbin.nav").string());
  const Items in = decode(readBytes(dataDir() / "rtcm/rtklib_testglo.rtcm3"), noon(2009, 12, 18));
  int matched = 0;
  for (const KeplerEphemeris& r : ref.kepler) {
    const auto it = std::find_if(in.kepler.begin(), in.kepler.end(), [&](const KeplerEphemeris& k) {
      return k.sat == r.sat && k.toe == r.toe && k.iode == r.iode;
    });
    ASSERT_NE(it, in.kepler.end()) << r.sat.str();
    const KeplerEphemeris& k = *it;
    ++matched;
    // RINEX keeps 12 significant digits.
    auto near = [](double a, double b) { return std::abs(a - b) <= 1e-11 * std::max(std::abs(a), std::abs(b)) + 1e-300; };
    const double a[] = {k.sqrtA, k.e, k.i0, k.omega0, k.omega, k.m0, k.deltaN, k.omegaDot, k.iDot, k.cuc, k.cus, k.crc, k.crs, k.cic, k.cis, k.af0, k.af1, k.af2, k.tgd[0]};
    const double b[] = {r.sqrtA, r.e, r.i0, r.omega0, r.omega, r.m0, r.deltaN, r.omegaDot, r.iDot, r.cuc, r.cus, r.crc, r.crs, r.cic, r.cis, r.af0, r.af1, r.af2, r.tgd[0]};
    for (std::size_t i = 0; i < std::size(a); ++i) EXPECT_TRUE(near(a[i], b[i])) << r.sat.str() << " field " << i << ": " << a[i] << " vs " << b[i];
    EXPECT_EQ(k.toc, r.toc);
    EXPECT_EQ(k.iodc, r.iodc);
    EXPECT_EQ(k.health, r.health);
    EXPECT_EQ(k.ura, r.ura);
  }
  for (const GlonassEphemeris& r : ref.glonass) {
    const auto it = std::find_if(in.glonass.begin(), in.glonass.end(), [&](const GlonassEphemeris& g) {
      return g.sat == r.sat && g.toe == r.toe;
    });
    ASSERT_NE(it, in.glonass.end()) << r.sat.str();
    ++matched;
    EXPECT_LT((it->position - r.position).norm(), 1e-3);
    EXPECT_LT((it->velocity - r.velocity).norm(), 2e-8);  // 12 digits of km/s
    EXPECT_LT((it->acceleration - r.acceleration).norm(), 1e-12);
    EXPECT_NEAR(it->tauN, r.tauN, 1e-15);
    EXPECT_NEAR(it->gammaN, r.gammaN, 1e-20);
    EXPECT_EQ(it->frequencyChannel, r.frequencyChannel);
    EXPECT_EQ(it->health, r.health);
  }
  std::cerr << "records matching RTKLIB's navigation file: " << matched << " (GPS " << ref.kepler.size() << ", GLONASS "
            << ref.glonass.size() << ")\n";
  EXPECT_GE(matched, 10);

  // The RTCM records and the RINEX ones give the same satellite positions from the same store API.
  EphemerisStore fromRtcm, fromRinex;
  for (const auto& k : in.kepler) fromRtcm.add(k);
  for (const auto& g : in.glonass) fromRtcm.add(g);
  fromRinex.add(ref);
  int states = 0;
  // At the end of the file: every record has been received (the decoder stamps a record's
  // transmission time with the time it arrived).
  const GpsTime t = GpsTime::fromCalendar({2009, 12, 18, 23, 10, 5.0});
  EphemerisSelection any;
  any.allowUnhealthy = true;  // G25 is flagged unhealthy (health 63)
  for (SatId sat : fromRinex.satellites()) {
    const auto a = fromRtcm.satelliteState(sat, t, any);
    const auto b = fromRinex.satelliteState(sat, t, any);
    ASSERT_TRUE(a.has_value()) << sat.str();
    ASSERT_TRUE(b.has_value()) << sat.str();
    EXPECT_LT((a->position - b->position).norm(), 1e-3) << sat.str();
    EXPECT_NEAR(a->clockBias, b->clockBias, 1e-12) << sat.str();
    ++states;
  }
  EXPECT_GE(states, 10);
}

}  // namespace
}  // namespace gvins::rtcm
