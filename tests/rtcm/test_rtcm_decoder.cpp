// Decoder: RTKLIB's conversion of rtklib_testglo.rtcm3 observation by observation, the GMSD log
// (MSM7 of four systems, GPS week rollover, BeiDou stamped in GPS time; every system against
// RTKLIB's conversion), Galileo and SBAS MSM7 of two single-epoch logs against RTKLIB, every
// single-frame file,
// malformed and hostile input.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <random>
#include <set>
#include <sstream>

#include "gvins/base/parse_error.hpp"
#include "gvins/base/rinex_obs_reader.hpp"
#include "gvins/rtcm/crc24q.hpp"
#include "gvins/rtcm/decoder.hpp"
#include "gvins/rtcm/encoder.hpp"
#include "gvins/rtcm/framer.hpp"
#include "gvins/rtcm/message_types.hpp"
#include "independent_frame_scan.hpp"

namespace gvins::rtcm {
namespace {

using testing::dataDir;
using testing::readBytes;

struct Decoded {
  std::vector<ObsEpoch> epochs;
  std::vector<KeplerEphemeris> kepler;
  std::vector<GlonassEphemeris> glonass;
  std::vector<StationPosition> stations;
  std::vector<AntennaDescriptor> antennas;
  std::vector<ReceiverDescriptor> receivers;
  std::vector<GlonassCodePhaseBiases> biases;
  std::vector<SsrMessage> ssr;
};

Decoded decodeAll(Decoder& dec, const std::vector<std::uint8_t>& d, std::size_t chunk = 4096) {
  Decoded out;
  auto drain = [&] {
    while (auto it = dec.poll()) {
      std::visit(
          [&](auto&& v) {
            using T = std::decay_t<decltype(v)>;
            if constexpr (std::is_same_v<T, ObsEpoch>) out.epochs.push_back(v);
            else if constexpr (std::is_same_v<T, KeplerEphemeris>) out.kepler.push_back(v);
            else if constexpr (std::is_same_v<T, GlonassEphemeris>) out.glonass.push_back(v);
            else if constexpr (std::is_same_v<T, StationPosition>) out.stations.push_back(v);
            else if constexpr (std::is_same_v<T, AntennaDescriptor>) out.antennas.push_back(v);
            else if constexpr (std::is_same_v<T, ReceiverDescriptor>) out.receivers.push_back(v);
            else if constexpr (std::is_same_v<T, GlonassCodePhaseBiases>) out.biases.push_back(v);
            else out.ssr.push_back(v);
          },
          *it);
    }
  };
  for (std::size_t i = 0; i < d.size(); i += chunk) {
    dec.feed({d.data() + i, std::min(chunk, d.size() - i)});
    drain();
  }
  dec.finish();
  drain();
  return out;
}

GpsTime date(int y, int m, int d) {
  CalendarTime c;
  c.year = y;
  c.month = m;
  c.day = d;
  c.hour = 12;
  return GpsTime::fromCalendar(c);
}

// ---- a minimal RINEX 3 observation parser for RTKLIB's reference file ----------------------

struct RinexValue {
  double value = 0.0;
  int lli = 0;
  bool present = false;
};
struct RinexEpoch {
  GpsTime time;
  std::map<std::string, std::vector<RinexValue>> sats;  // "G03" -> values in header type order
};
struct RinexObs {
  std::map<char, std::vector<std::string>> types;  // 'G' -> {"C1C", "L1C", ...}
  std::vector<RinexEpoch> epochs;
};

RinexObs readRtklibObs(const std::filesystem::path& p) {
  std::ifstream in(p);
  RinexObs r;
  std::string line;
  while (std::getline(in, line)) {
    if (line.find("SYS / # / OBS TYPES") != std::string::npos) {
      const char sys = line[0];
      const int n = std::stoi(line.substr(3, 3));
      for (int k = 0; k < n; ++k) r.types[sys].push_back(line.substr(7 + 4 * k, 3));
    }
    if (line.find("END OF HEADER") != std::string::npos) break;
  }
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    if (line[0] == '>') {
      CalendarTime c;
      std::istringstream ss(line.substr(1));
      ss >> c.year >> c.month >> c.day >> c.hour >> c.minute >> c.second;
      r.epochs.push_back({GpsTime::fromCalendar(c), {}});
      continue;
    }
    const std::string sat = line.substr(0, 3);
    std::vector<RinexValue> vals;
    for (std::size_t k = 0; k < r.types[line[0]].size(); ++k) {
      RinexValue v;
      const std::size_t pos = 3 + 16 * k;
      if (pos + 14 <= line.size()) {
        const std::string f = line.substr(pos, 14);
        if (f.find_first_not_of(' ') != std::string::npos) {
          v.value = std::stod(f);
          v.present = true;
        }
        if (pos + 14 < line.size() && line[pos + 14] != ' ') v.lli = line[pos + 14] - '0';
      }
      vals.push_back(v);
    }
    r.epochs.back().sats[sat] = vals;
  }
  return r;
}

TEST(Decoder, TestgloMatchesRtklibObservationByObservation) {
  const auto ref = readRtklibObs(dataDir() / "reference/rtklib-2.4.3/rtcm_testglo_convbin.obs");
  ASSERT_EQ(ref.epochs.size(), 186u);
  DecoderOptions opt;
  opt.referenceTime = date(2009, 12, 18);
  Decoder dec(opt);
  const Decoded got = decodeAll(dec, readBytes(dataDir() / "rtcm/rtklib_testglo.rtcm3"));
  ASSERT_EQ(got.epochs.size(), ref.epochs.size());

  // Tolerances: the messages' resolution is 0.02 m for code and 0.0005 m for phase-range; both
  // decoders compute the same numbers, so the RINEX rounding (0.001 m / cycle) dominates.
  std::int64_t values = 0, lliSame = 0, lliCompared = 0;
  double maxCode = 0, maxPhase = 0, maxSnr = 0;
  for (std::size_t e = 0; e < ref.epochs.size(); ++e) {
    const RinexEpoch& re = ref.epochs[e];
    const ObsEpoch& oe = got.epochs[e];
    ASSERT_EQ(oe.time, re.time) << e;
    ASSERT_EQ(oe.sats.size(), re.sats.size()) << "epoch " << e;
    for (const auto& [name, vals] : re.sats) {
      const auto sat = SatId::parse(name);
      ASSERT_TRUE(sat);
      const SatObs* so = oe.find(*sat);
      ASSERT_NE(so, nullptr) << name << " epoch " << e;
      const auto& types = ref.types.at(name[0]);
      std::size_t signalsSeen = 0;
      for (std::size_t k = 0; k < types.size(); ++k) {
        const ObsCode code(types[k][1], types[k][2]);
        const SignalObs* s = so->find(code);
        const RinexValue& v = vals[k];
        if (!v.present) {
          if (s) {
            if (types[k][0] == 'S') {
              EXPECT_FALSE(s->hasSnr()) << name << " " << types[k];
            }
            if (types[k][0] == 'L') {
              EXPECT_FALSE(s->hasPhase()) << name << " " << types[k];
            }
          }
          continue;
        }
        ASSERT_NE(s, nullptr) << name << " " << types[k] << " epoch " << e;
        ++values;
        switch (types[k][0]) {
          case 'C':
            ASSERT_TRUE(s->hasCode());
            maxCode = std::max(maxCode, std::abs(s->pseudorange - v.value));
            break;
          case 'L':
            ASSERT_TRUE(s->hasPhase());
            maxPhase = std::max(maxPhase, std::abs(s->carrierPhase - v.value));
            // RTKLIB's converter flags the first observation of every signal; compare later ones.
            if (e > 0) {
              ++lliCompared;
              lliSame += (s->lli & 1) == (v.lli & 1);
            }
            break;
          case 'S':
            ASSERT_TRUE(s->hasSnr());
            maxSnr = std::max(maxSnr, std::abs(s->snr - v.value));
            break;
        }
        if (types[k][0] == 'C') ++signalsSeen;
      }
      EXPECT_EQ(signalsSeen, so->signals.size()) << name << " epoch " << e << ": same signals";
    }
  }
  std::cerr << "testglo vs RTKLIB: " << values << " values, max |dC| " << maxCode << " m, max |dL| " << maxPhase
            << " cycles, max |dS| " << maxSnr << " dB-Hz, LLI equal " << lliSame << "/" << lliCompared << "\n";
  EXPECT_GT(values, 15000);
  EXPECT_LE(maxCode, 0.0006);
  EXPECT_LE(maxPhase, 0.0006);
  EXPECT_LE(maxSnr, 1e-9);
  EXPECT_EQ(lliSame, lliCompared);
  EXPECT_EQ(dec.stats().malformed, 0);
  EXPECT_EQ(dec.stats().epochs, 186);

  // Station and GLONASS channels as in RTKLIB's header.
  ASSERT_TRUE(dec.station().approxPosition);
  EXPECT_NEAR(dec.station().approxPosition->x(), -3869297.5138, 1e-4);
  EXPECT_NEAR(dec.station().approxPosition->y(), 3436571.3345, 1e-4);
  EXPECT_NEAR(dec.station().approxPosition->z(), 3717369.3757, 1e-4);
  // "GLONASS SLOT / FRQ #": R08 6, R13 -2, R14 -7, R15 0, R17 4, R23 3.
  const std::pair<int, int> chans[] = {{8, 6}, {13, -2}, {14, -7}, {15, 0}, {17, 4}, {23, 3}};
  for (auto [slot, k] : chans) EXPECT_EQ(dec.glonassChannels().get(slot), k) << slot;
  EXPECT_EQ(got.kepler.size(), 19u);
  EXPECT_EQ(got.glonass.size(), 19u);
}

TEST(Decoder, GmsdMsm7AcrossWeekRolloverWithBeidouInGpsTime) {
  DecoderOptions opt;
  opt.referenceTime = date(2012, 10, 13);
  Decoder dec(opt);
  const Decoded got = decodeAll(dec, readBytes(dataDir() / "rtcm/rtklib_GMSD7_20121014.rtcm3"), 1000);
  const DecoderStats& st = dec.stats();
  // 257 epochs of 1077+1087+1117+1127, each one epoch of four systems.
  ASSERT_EQ(got.epochs.size(), 257u);
  EXPECT_EQ(st.beidouGpstEpochs, 257);
  EXPECT_EQ(st.malformed, 0);
  const GpsTime first = got.epochs.front().time;
  EXPECT_EQ(first.toString(0), "2012-10-13 23:59:44");
  EXPECT_EQ(first.week(), 1709);
  EXPECT_EQ(got.epochs.back().time.week(), 1710);  // crossed the week rollover (Sunday 00:00 GPST)
  for (std::size_t i = 0; i < got.epochs.size(); ++i) {
    const ObsEpoch& e = got.epochs[i];
    EXPECT_DOUBLE_EQ(e.time - first, static_cast<double>(i)) << i;  // 1 Hz, continuous
    int perSystem[kNumSystems] = {};
    for (const SatObs& s : e.sats) ++perSystem[systemIndex(s.sat.system)];
    EXPECT_GE(perSystem[systemIndex(System::Gps)], 10) << i;
    EXPECT_GE(perSystem[systemIndex(System::Glonass)], 5) << i;
    EXPECT_EQ(perSystem[systemIndex(System::Qzss)], 1) << i;
    EXPECT_GE(perSystem[systemIndex(System::BeiDou)], 8) << i;
  }
  // Pseudoranges of all systems agree with each other: with the BeiDou epochs read as BDT instead
  // the receiver clock would look 14 s different; here every pseudorange is a plausible range.
  for (const ObsEpoch& e : got.epochs) {
    for (const SatObs& s : e.sats) {
      for (const SignalObs& g : s.signals) {
        if (!g.hasCode()) continue;
        EXPECT_GT(g.pseudorange, 1.9e7) << s.sat.str();
        EXPECT_LT(g.pseudorange, 4.2e7) << s.sat.str();
      }
    }
  }
  // GLONASS channels from the MSM7 extended satellite information; receiver from 1033.
  EXPECT_TRUE(dec.glonassChannels().get(13).has_value());
  ASSERT_FALSE(got.receivers.empty());
  EXPECT_EQ(got.receivers.front().type, "TRIMBLE NETR9");
  EXPECT_EQ(got.kepler.size(), 15u);
  EXPECT_EQ(got.glonass.size(), 16u);
  // Truncated at the end of the file, nothing else lost.
  EXPECT_EQ(st.framing.truncatedFrames, 1);
  EXPECT_EQ(st.framing.crcFailures, 0);
}

TEST(Decoder, GmsdBeidouMatchesRtklib14SecondsApart) {
  // RTKLIB converts only the BeiDou part of this log and stamps it 14 s late (it reads the GPS
  // time of week in the BeiDou messages as BDT). Its values must equal ours at time - 14 s.
  RinexObsReader ref((dataDir() / "reference/rtklib-2.4.3/rtcm_gmsd_convbin.obs.gz").string());
  DecoderOptions opt;
  opt.referenceTime = date(2012, 10, 13);
  Decoder dec(opt);
  const Decoded got = decodeAll(dec, readBytes(dataDir() / "rtcm/rtklib_GMSD7_20121014.rtcm3"));
  std::map<std::int64_t, const ObsEpoch*> byTime;
  for (const ObsEpoch& e : got.epochs) byTime[e.time.wholeSeconds()] = &e;
  ObsEpoch r;
  int epochs = 0;
  std::int64_t values = 0, lliCompared = 0, lliGapOnlyOurs = 0;
  double maxC = 0, maxL = 0, maxD = 0, maxS = 0;
  std::set<std::uint32_t> prevSignals;
  auto trackKey = [](SatId sat, ObsCode c) { return static_cast<std::uint32_t>(satIndex(sat) * 65536 + c.band * 256 + c.attr); };
  while (ref.next(r)) {
    std::set<std::uint32_t> signals;
    const auto it = byTime.find((r.time - 14.0).wholeSeconds());
    ASSERT_NE(it, byTime.end()) << r.time.toString();
    const ObsEpoch& e = *it->second;
    int bds = 0;
    for (const SatObs& s : e.sats) bds += s.sat.system == System::BeiDou;
    ASSERT_EQ(bds, static_cast<int>(r.sats.size())) << r.time.toString();
    for (const SatObs& rs : r.sats) {
      const SatObs* os = e.find(rs.sat);
      ASSERT_NE(os, nullptr) << rs.sat.str();
      ASSERT_EQ(os->signals.size(), rs.signals.size()) << rs.sat.str();
      for (const SignalObs& rg : rs.signals) {
        const SignalObs* og = os->find(rg.code);
        ASSERT_NE(og, nullptr) << rs.sat.str() << " " << rg.code.str();
        EXPECT_EQ(og->present, rg.present) << rs.sat.str() << " " << rg.code.str();
        if (rg.hasCode()) maxC = std::max(maxC, std::abs(og->pseudorange - rg.pseudorange));
        if (rg.hasPhase()) maxL = std::max(maxL, std::abs(og->carrierPhase - rg.carrierPhase));
        if (rg.hasDoppler()) maxD = std::max(maxD, std::abs(og->doppler - rg.doppler));
        if (rg.hasSnr()) maxS = std::max(maxS, std::abs(og->snr - rg.snr));
        if (epochs > 0 && rg.hasPhase()) {
          ++lliCompared;
          if ((og->lli & 1) != (rg.lli & 1)) {
            // RTKLIB flags a slip only when the indicator decreases; after a gap longer than the
            // lock time the indicator can repeat. Every disagreement must be such a gap, flagged
            // by us.
            const bool gap = !prevSignals.count(trackKey(rs.sat, rg.code));
            EXPECT_TRUE(gap && (og->lli & 1)) << rs.sat.str() << " " << rg.code.str() << " " << r.time.toString();
            ++lliGapOnlyOurs;
          }
        }
        signals.insert(trackKey(rs.sat, rg.code));
        values += std::popcount(rg.present);
      }
    }
    prevSignals = std::move(signals);
    ++epochs;
  }
  std::cerr << "GMSD BeiDou vs RTKLIB (14 s apart): " << epochs << " epochs, " << values << " values, max |dC| " << maxC
            << " m, |dL| " << maxL << " cycles, |dD| " << maxD << " Hz, |dS| " << maxS << " dB-Hz; LLI equal "
            << lliCompared - lliGapOnlyOurs << "/" << lliCompared << " (others: re-acquisition after a gap)\n";
  EXPECT_EQ(epochs, 257);
  EXPECT_LE(lliGapOnlyOurs, 10);
  EXPECT_LE(maxC, 0.0006);  // RINEX rounding (0.001)
  EXPECT_LE(maxL, 0.0006);
  EXPECT_LE(maxD, 0.001);  // RINEX rounding and RTKLIB's own wavelength arithmetic
  // RTKLIB writes C/N0 rounded to 0.25 dB-Hz (its internal unit); MSM7 has 1/16 dB-Hz.
  EXPECT_LE(maxS, 0.125 + 1e-9);
}

TEST(Decoder, GmsdGpsGlonassQzssMsm7MatchRtklib) {
  // RTKLIB keeps only BeiDou from the original log (above). Its conversion of the log without the
  // BeiDou messages (reference/rtklib-2.4.3/make_gmsd_nobds.py: 1127 frames dropped, the
  // multiple-message bit of each 1117 cleared) gives the GPS, GLONASS and QZSS MSM7 values across
  // the week rollover. Ours, decoded from the unmodified log, must equal them at the same times:
  // same satellites and signals, values within the RINEX rounding.
  RinexObsReader ref((dataDir() / "reference/rtklib-2.4.3/rtcm_gmsd_nobds_convbin.obs.gz").string());
  DecoderOptions opt;
  opt.referenceTime = date(2012, 10, 13);
  Decoder dec(opt);
  const Decoded got = decodeAll(dec, readBytes(dataDir() / "rtcm/rtklib_GMSD7_20121014.rtcm3"));
  std::map<std::int64_t, const ObsEpoch*> byTime;
  for (const ObsEpoch& e : got.epochs) byTime[e.time.wholeSeconds()] = &e;
  ObsEpoch r;
  int epochs = 0;
  std::int64_t values = 0, lliCompared = 0, lliGapOnlyOurs = 0;
  std::map<System, std::int64_t> perSystem;
  double maxC = 0, maxL = 0, maxD = 0, maxS = 0;
  std::set<std::uint32_t> prevSignals;
  auto trackKey = [](SatId sat, ObsCode c) { return static_cast<std::uint32_t>(satIndex(sat) * 65536 + c.band * 256 + c.attr); };
  while (ref.next(r)) {
    std::set<std::uint32_t> signals;
    const auto it = byTime.find(r.time.wholeSeconds());
    ASSERT_NE(it, byTime.end()) << r.time.toString();
    const ObsEpoch& e = *it->second;
    int others = 0;
    for (const SatObs& s : e.sats) others += s.sat.system != System::BeiDou;
    ASSERT_EQ(others, static_cast<int>(r.sats.size())) << r.time.toString();
    for (const SatObs& rs : r.sats) {
      const SatObs* os = e.find(rs.sat);
      ASSERT_NE(os, nullptr) << rs.sat.str() << " " << r.time.toString();
      ASSERT_EQ(os->signals.size(), rs.signals.size()) << rs.sat.str() << " " << r.time.toString();
      for (const SignalObs& rg : rs.signals) {
        const SignalObs* og = os->find(rg.code);
        ASSERT_NE(og, nullptr) << rs.sat.str() << " " << rg.code.str();
        // RTKLIB 2.4.3 writes Doppler only on the first band; we keep it on every signal.
        EXPECT_EQ(og->present | SignalObs::kDoppler, rg.present | SignalObs::kDoppler) << rs.sat.str() << " " << rg.code.str();
        if (rg.hasDoppler()) {
          EXPECT_TRUE(og->hasDoppler()) << rs.sat.str() << " " << rg.code.str();
          maxD = std::max(maxD, std::abs(og->doppler - rg.doppler));
        }
        if (rg.hasCode()) maxC = std::max(maxC, std::abs(og->pseudorange - rg.pseudorange));
        if (rg.hasPhase()) maxL = std::max(maxL, std::abs(og->carrierPhase - rg.carrierPhase));
        if (rg.hasSnr()) maxS = std::max(maxS, std::abs(og->snr - rg.snr));
        if (epochs > 0 && rg.hasPhase()) {
          ++lliCompared;
          if ((og->lli & 1) != (rg.lli & 1)) {
            // As for BeiDou: only re-acquisitions after a gap, flagged by us and not by RTKLIB.
            const bool gap = !prevSignals.count(trackKey(rs.sat, rg.code));
            EXPECT_TRUE(gap && (og->lli & 1)) << rs.sat.str() << " " << rg.code.str() << " " << r.time.toString();
            ++lliGapOnlyOurs;
          }
        }
        signals.insert(trackKey(rs.sat, rg.code));
        values += std::popcount(rg.present);
        perSystem[rs.sat.system] += std::popcount(rg.present);
      }
    }
    prevSignals = std::move(signals);
    ++epochs;
  }
  std::cerr << "GMSD GPS/GLONASS/QZSS vs RTKLIB: " << epochs << " epochs, " << values << " values (GPS "
            << perSystem[System::Gps] << ", GLONASS " << perSystem[System::Glonass] << ", QZSS " << perSystem[System::Qzss]
            << "), max |dC| " << maxC << " m, |dL| " << maxL << " cycles, |dD| " << maxD << " Hz, |dS| " << maxS
            << " dB-Hz; LLI equal " << lliCompared - lliGapOnlyOurs << "/" << lliCompared << "\n";
  EXPECT_EQ(epochs, 257);
  for (System s : {System::Gps, System::Glonass, System::Qzss}) EXPECT_GT(perSystem[s], 1000) << systemName(s);
  EXPECT_LE(lliGapOnlyOurs, 20);
  EXPECT_LE(maxC, 0.0006);  // RINEX rounding (0.001)
  EXPECT_LE(maxL, 0.0006);
  EXPECT_LE(maxD, 0.001);   // RINEX rounding and RTKLIB's own wavelength arithmetic
  EXPECT_LE(maxS, 0.125 + 1e-9);  // RTKLIB's 0.25 dB-Hz unit
}

// One-epoch logs with Galileo and SBAS MSM7 (the GMSD log has neither): RTKLIB's conversions
// (reference/rtklib-2.4.3/rtcm_uscl_msm7_convbin.obs.gz, rtcm_pyrtcm_rtcm3_convbin.obs.gz;
// commands in tests/data/README.md) against ours at the same epoch time. RTKLIB writes the epochs
// it closed (multiple-message bit clear); the logs also hold messages of other times, which it
// drops and we report as epochs of their own, so only RTKLIB's epochs are compared, system by
// system. The USCL log carries legacy, MSM6 and MSM7 observations of one epoch with values that
// disagree (RTKLIB keeps the last, we the first); both decoders get its MSM7 frames only, the
// frame selection of make_msm7_only.py.
std::vector<std::uint8_t> msm7AndNonObservationFrames(const std::vector<std::uint8_t>& log) {
  Framer f;
  f.feed(log);
  f.finish();
  std::vector<std::uint8_t> out;
  Frame fr;
  while (f.next(fr)) {
    const int t = fr.type();
    const bool legacy = (t >= 1001 && t <= 1004) || (t >= 1009 && t <= 1012);
    const bool lowMsm = t >= 1071 && t <= 1137 && t % 10 >= 1 && t % 10 <= 6;
    if (legacy || lowMsm) continue;
    const auto framed = Encoder::frame(fr.payload);
    out.insert(out.end(), framed.begin(), framed.end());
  }
  return out;
}

TEST(Decoder, GalileoAndSbasMsm7MatchRtklibOnSingleEpochLogs) {
  struct Case {
    const char* log;
    const char* ref;
    GpsTime referenceTime;
    std::set<System> systems;
    bool msm7Only;
  };
  const Case cases[] = {
      {"pyrtcm_pygpsdata-NTRIP-USCL00CHL0.log", "rtcm_uscl_msm7_convbin.obs.gz", date(2024, 3, 13),
       {System::Gps, System::Glonass, System::Galileo, System::BeiDou, System::Sbas}, true},
      {"pyrtcm_pygpsdata-RTCM3.log", "rtcm_pyrtcm_rtcm3_convbin.obs.gz", date(2020, 12, 29),
       {System::Gps, System::Glonass, System::Galileo, System::BeiDou}, false},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.log);
    DecoderOptions opt;
    opt.referenceTime = c.referenceTime;
    Decoder dec(opt);
    const auto log = readBytes(dataDir() / "rtcm" / c.log);
    const Decoded got = decodeAll(dec, c.msm7Only ? msm7AndNonObservationFrames(log) : log);
    RinexObsReader ref((dataDir() / "reference/rtklib-2.4.3" / c.ref).string());
    ObsEpoch r;
    int epochs = 0;
    std::map<System, std::int64_t> perSystem;
    double maxC = 0, maxL = 0, maxD = 0, maxS = 0;
    while (ref.next(r)) {
      const auto it = std::find_if(got.epochs.begin(), got.epochs.end(), [&](const ObsEpoch& e) { return std::abs(e.time - r.time) < 1e-6; });
      ASSERT_NE(it, got.epochs.end()) << r.time.toString();
      std::map<System, int> oursPerSystem, theirsPerSystem;
      for (const SatObs& s : it->sats) ++oursPerSystem[s.sat.system];
      for (const SatObs& s : r.sats) ++theirsPerSystem[s.sat.system];
      for (System s : c.systems) {
        EXPECT_GT(theirsPerSystem[s], 0) << systemName(s);
        EXPECT_EQ(oursPerSystem[s], theirsPerSystem[s]) << systemName(s);
      }
      for (const SatObs& rs : r.sats) {
        const SatObs* os = it->find(rs.sat);
        ASSERT_NE(os, nullptr) << rs.sat.str();
        ASSERT_EQ(os->signals.size(), rs.signals.size()) << rs.sat.str();
        for (const SignalObs& rg : rs.signals) {
          const SignalObs* og = os->find(rg.code);
          ASSERT_NE(og, nullptr) << rs.sat.str() << " " << rg.code.str();
          EXPECT_EQ(og->present, rg.present) << rs.sat.str() << " " << rg.code.str();
          if (rg.hasCode()) maxC = std::max(maxC, std::abs(og->pseudorange - rg.pseudorange));
          if (rg.hasPhase()) maxL = std::max(maxL, std::abs(og->carrierPhase - rg.carrierPhase));
          if (rg.hasDoppler()) maxD = std::max(maxD, std::abs(og->doppler - rg.doppler));
          if (rg.hasSnr()) maxS = std::max(maxS, std::abs(og->snr - rg.snr));
          perSystem[rs.sat.system] += std::popcount(rg.present);
        }
      }
      ++epochs;
    }
    std::cerr << c.log << " vs RTKLIB: " << epochs << " epoch(s), values G " << perSystem[System::Gps] << " R "
              << perSystem[System::Glonass] << " E " << perSystem[System::Galileo] << " C " << perSystem[System::BeiDou]
              << " S " << perSystem[System::Sbas] << "; max |dC| " << maxC << " m, |dL| " << maxL << " cycles, |dD| "
              << maxD << " Hz, |dS| " << maxS << " dB-Hz\n";
    EXPECT_EQ(epochs, 1);
    EXPECT_LE(maxC, 0.0006);  // RINEX rounding (0.001)
    EXPECT_LE(maxL, 0.0006);
    EXPECT_LE(maxD, 0.001);
    EXPECT_LE(maxS, 0.125 + 1e-9);  // RTKLIB's 0.25 dB-Hz unit
  }
}

TEST(Decoder, StreamThatNeverClearsTheMultipleMessageBit) {
  // Set DF393 on every MSM frame of the GMSD log (re-sealing the CRC): epochs must still come out,
  // each closed by the next epoch's first message (the last one at the end of the stream), and be
  // the same as those of the original log.
  const auto bytes = readBytes(dataDir() / "rtcm/rtklib_GMSD7_20121014.rtcm3");
  std::vector<std::uint8_t> patched;
  Framer fr;
  fr.feed(bytes);
  Frame f;
  int set = 0;
  while (fr.next(f)) {
    std::vector<std::uint8_t> p(f.payload.begin(), f.payload.end());
    if (msmKind(f.type())) {
      set += (p[6] & 0x02) == 0;
      p[6] |= 0x02;  // DF393 is bit 54
    }
    const auto framed = Encoder::frame(p);
    patched.insert(patched.end(), framed.begin(), framed.end());
  }
  ASSERT_EQ(set, 257);  // the last message of each epoch had it cleared
  DecoderOptions opt;
  opt.referenceTime = date(2012, 10, 13);
  Decoder a(opt), b(opt);
  const Decoded orig = decodeAll(a, bytes);
  // Feed all but the end: the epoch in progress stays open until the stream ends.
  b.feed(patched);
  std::vector<ObsEpoch> got;
  while (auto item = b.poll()) {
    if (auto* e = std::get_if<ObsEpoch>(&*item)) got.push_back(*e);
  }
  EXPECT_EQ(got.size(), 256u);
  b.finish();
  while (auto item = b.poll()) {
    if (auto* e = std::get_if<ObsEpoch>(&*item)) got.push_back(*e);
  }
  ASSERT_EQ(got.size(), orig.epochs.size());
  for (std::size_t i = 0; i < got.size(); ++i) {
    EXPECT_EQ(got[i].time, orig.epochs[i].time);
    ASSERT_EQ(got[i].sats.size(), orig.epochs[i].sats.size());
    for (std::size_t k = 0; k < got[i].sats.size(); ++k) {
      EXPECT_EQ(got[i].sats[k].sat, orig.epochs[i].sats[k].sat);
      EXPECT_EQ(got[i].sats[k].signals.size(), orig.epochs[i].sats[k].signals.size());
    }
  }
  EXPECT_EQ(b.stats().beidouGpstEpochs, 257);
}

TEST(Decoder, BeidouStampedInGpsTimeSentFirstInItsEpoch) {
  // Reorder the GMSD log so that each epoch's 1127 comes before the other MSM messages (with its
  // multiple-message bit set): every BeiDou message must still join its epoch.
  const auto bytes = readBytes(dataDir() / "rtcm/rtklib_GMSD7_20121014.rtcm3");
  std::vector<std::uint8_t> reordered, held;
  Framer fr;
  fr.feed(bytes);
  Frame f;
  while (fr.next(f)) {
    std::vector<std::uint8_t> p(f.payload.begin(), f.payload.end());
    const int t = f.type();
    if (t == 1077) held.clear();
    if (t == 1077 || t == 1087 || t == 1117) {
      const auto framed = Encoder::frame(p);
      held.insert(held.end(), framed.begin(), framed.end());
      continue;
    }
    if (t == 1127) {
      p[6] |= 0x02;  // more messages follow now
      const auto framed = Encoder::frame(p);
      reordered.insert(reordered.end(), framed.begin(), framed.end());
      // The last of the others now closes the epoch.
      Framer inner;
      inner.feed(held);
      Frame g;
      std::vector<std::vector<std::uint8_t>> others;
      while (inner.next(g)) others.emplace_back(g.payload.begin(), g.payload.end());
      others.back()[6] &= static_cast<std::uint8_t>(~0x02u);
      for (const auto& o : others) {
        const auto fo = Encoder::frame(o);
        reordered.insert(reordered.end(), fo.begin(), fo.end());
      }
      held.clear();
      continue;
    }
    const auto framed = Encoder::frame(p);
    reordered.insert(reordered.end(), framed.begin(), framed.end());
  }
  DecoderOptions opt;
  opt.referenceTime = date(2012, 10, 13);
  Decoder dec(opt);
  const Decoded got = decodeAll(dec, reordered);
  // The open BeiDou-only epoch is retimed when the other systems' messages arrive 14 s earlier;
  // from then on the stamping is known.
  ASSERT_EQ(got.epochs.size(), 257u);
  EXPECT_EQ(dec.stats().beidouGpstEpochs, 257);
  int merged = 0;
  for (const ObsEpoch& e : got.epochs) {
    bool bds = false, others = false;
    for (const SatObs& s : e.sats) (s.sat.system == System::BeiDou ? bds : others) = true;
    merged += bds && others;
  }
  EXPECT_EQ(merged, 257);
}

TEST(Decoder, BeidouStampCheckLeavesCorrectBdtAlone) {
  // Re-encode the GMSD epochs (our encoder stamps BeiDou in BDT): no correction must happen and
  // the epochs must come out the same.
  DecoderOptions opt;
  opt.referenceTime = date(2012, 10, 13);
  Decoder dec(opt);
  const Decoded got = decodeAll(dec, readBytes(dataDir() / "rtcm/rtklib_GMSD7_20121014.rtcm3"));
  Encoder enc;
  enc.setGlonassChannels(dec.glonassChannels());
  std::vector<std::uint8_t> stream;
  for (const ObsEpoch& e : got.epochs) {
    const auto f = enc.msm(e, 7);
    stream.insert(stream.end(), f.begin(), f.end());
  }
  Decoder dec2(opt);
  const Decoded again = decodeAll(dec2, stream);
  EXPECT_EQ(dec2.stats().beidouGpstEpochs, 0);
  ASSERT_EQ(again.epochs.size(), got.epochs.size());
  for (std::size_t i = 0; i < got.epochs.size(); ++i) {
    EXPECT_EQ(again.epochs[i].time, got.epochs[i].time);
    EXPECT_EQ(again.epochs[i].sats.size(), got.epochs[i].sats.size());
  }
}

TEST(Decoder, EverySingleFrameFileDecodesCleanly) {
  DecoderOptions opt;
  opt.referenceTime = date(2021, 1, 1);
  std::int64_t decoded = 0, unsupported = 0;
  for (const auto& path : testing::rtcmFiles()) {
    SCOPED_TRACE(path.string());
    opt.streamName = path.filename().string();
    Decoder dec(opt);
    const auto d = readBytes(path);
    decodeAll(dec, d, 17);
    EXPECT_EQ(dec.stats().malformed, 0);
    for (const auto& issue : dec.stats().issues) ADD_FAILURE() << issue.what;
    decoded += dec.stats().decoded;
    unsupported += dec.stats().unsupported;
    // Every good frame is either decoded or of a type this decoder does not decode.
    std::int64_t frames = 0, notDecoded = 0;
    for (const auto& [type, n] : dec.stats().messages) {
      frames += n;
      if (!isDecodedType(type)) notDecoded += n;
    }
    EXPECT_EQ(dec.stats().decoded + dec.stats().malformed, frames - notDecoded);
  }
  std::cerr << "decoded " << decoded << " messages, " << unsupported << " of types not decoded\n";
}

TEST(Decoder, StationAndDescriptorsFromSingleFrames) {
  Decoder dec;
  decodeAll(dec, readBytes(dataDir() / "rtcm/go-gnss_frames/1006_frame.bin"));
  ASSERT_TRUE(dec.stationPosition());
  const StationPosition& p = *dec.stationPosition();
  EXPECT_EQ(p.messageType, 1006);
  ASSERT_TRUE(p.antennaHeight);
  // The marker is the ARP lowered by the antenna height.
  EXPECT_NEAR((p.arp - *dec.station().approxPosition).norm(), *p.antennaHeight, 1e-6);
  EXPECT_NEAR(p.arp.norm(), 6.37e6, 0.03e6);

  Decoder d2;
  decodeAll(d2, readBytes(dataDir() / "rtcm/go-gnss_frames/1033_frame.bin"));
  // The frame's text fields (readable in a hex dump): no antenna descriptor, antenna serial
  // "Unknown", receiver "SEPT POLARX5", firmware "5.2.0", receiver serial "3025123".
  EXPECT_EQ(d2.station().antennaType, "");
  EXPECT_EQ(d2.station().antennaNumber, "Unknown");
  EXPECT_EQ(d2.station().receiverType, "SEPT POLARX5");
  EXPECT_EQ(d2.station().receiverVersion, "5.2.0");
  EXPECT_EQ(d2.station().receiverNumber, "3025123");
}

TEST(Decoder, GlonassBiases1230) {
  Decoder dec;
  const Decoded got = decodeAll(dec, readBytes(dataDir() / "rtcm/pyrtcm_pygpsdata-1230.bin"));
  ASSERT_EQ(got.biases.size(), 5u);
  for (const auto& b : got.biases) {
    const int n = b.l1ca.has_value() + b.l1p.has_value() + b.l2ca.has_value() + b.l2p.has_value();
    EXPECT_GT(n, 0);
    for (const auto* v : {&b.l1ca, &b.l1p, &b.l2ca, &b.l2p}) {
      if (*v) {
        EXPECT_LT(std::abs(**v), 100.0);  // inter-frequency biases are metres, not kilometres
      }
    }
  }
}

/// Builds a frame with a good CRC around an arbitrary payload.
std::vector<std::uint8_t> frameOf(std::vector<std::uint8_t> payload) { return Encoder::frame(payload); }

TEST(Decoder, MalformedMessagesAreReportedWithOffsetAndField) {
  // A 1077 whose payload is cut in the middle of the signal data but carries a valid CRC.
  auto full = readBytes(dataDir() / "rtcm/go-gnss_frames/1077_frame.bin");
  std::vector<std::uint8_t> payload(full.begin() + 3, full.end() - 3);
  payload.resize(payload.size() / 2);
  std::vector<std::uint8_t> stream = readBytes(dataDir() / "rtcm/go-gnss_frames/1005_frame.bin");
  const std::int64_t offset = static_cast<std::int64_t>(stream.size());
  const auto bad = frameOf(payload);
  stream.insert(stream.end(), bad.begin(), bad.end());
  const auto tail = readBytes(dataDir() / "rtcm/go-gnss_frames/1019_frame.bin");
  stream.insert(stream.end(), tail.begin(), tail.end());

  DecoderOptions opt;
  opt.streamName = "cut.rtcm3";
  Decoder dec(opt);
  const Decoded got = decodeAll(dec, stream);
  EXPECT_EQ(dec.stats().malformed, 1);
  ASSERT_EQ(dec.stats().issues.size(), 1u);
  const DecodeIssue& is = dec.stats().issues[0];
  EXPECT_EQ(is.offset, offset);
  EXPECT_EQ(is.type, 1077);
  EXPECT_EQ(is.field, "satellite and signal data");
  EXPECT_NE(is.what.find("byte " + std::to_string(offset)), std::string::npos) << is.what;
  EXPECT_NE(is.what.find("message too short"), std::string::npos) << is.what;
  // The messages around it are decoded.
  EXPECT_EQ(got.stations.size(), 1u);
  EXPECT_EQ(got.kepler.size(), 1u);

  // Strict mode throws ParseError naming the stream and the offset.
  opt.strict = true;
  Decoder strict(opt);
  try {
    strict.feed(stream);
    FAIL() << "no exception";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.file(), "cut.rtcm3");
    EXPECT_EQ(e.line(), offset);
    EXPECT_EQ(e.field(), "satellite and signal data");
  }
}

TEST(Decoder, ImpossibleFieldValuesAreRejected) {
  struct Case {
    std::vector<std::uint8_t> payload;
    std::string field;
  };
  // MSM header with 9 satellites x 8 signals (72 cells > 64).
  std::vector<std::uint8_t> msm(40, 0);
  msm[0] = 1077 >> 4;
  msm[1] = static_cast<std::uint8_t>((1077 & 0xF) << 4);
  // satellite mask starts at bit 73 (12+12+30+1+3+7+2+2+1+3); set 9 bits, signal mask 8 bits.
  auto setBit = [&](std::vector<std::uint8_t>& p, int bit) { p[static_cast<std::size_t>(bit / 8)] |= static_cast<std::uint8_t>(0x80 >> (bit % 8)); };
  for (int k = 0; k < 9; ++k) setBit(msm, 73 + k);
  for (int k = 0; k < 8; ++k) setBit(msm, 73 + 64 + k);
  // GPS ephemeris with satellite ID 0.
  std::vector<std::uint8_t> eph(61, 0);
  eph[0] = 1019 >> 4;
  eph[1] = static_cast<std::uint8_t>((1019 & 0xF) << 4);
  // 1004 with time of week beyond a week (all ones).
  std::vector<std::uint8_t> legacy(8, 0xFF);
  legacy[0] = 1004 >> 4;
  legacy[1] = static_cast<std::uint8_t>(((1004 & 0xF) << 4) | 0xF);
  const Case cases[] = {{msm, "DF396 cell mask"}, {eph, "DF009 satellite ID"}, {legacy, "DF004 GPS epoch time"}};
  for (const Case& c : cases) {
    Decoder dec;
    dec.feed(frameOf(c.payload));
    dec.finish();
    ASSERT_EQ(dec.stats().issues.size(), 1u) << c.field;
    EXPECT_EQ(dec.stats().issues[0].field, c.field);
    EXPECT_FALSE(dec.poll().has_value());
  }
}

TEST(Decoder, HostileStreamsNeverCrashOrHang) {
  // Random bytes, random payloads behind valid CRCs, and valid frames with random bit flips
  // re-sealed with a fresh CRC: the decoder must survive all of them and keep its memory bounded.
  std::mt19937 rng(7);
  std::vector<std::vector<std::uint8_t>> goods;
  for (const auto& path : testing::rtcmFiles()) {
    if (path.parent_path().filename() == "go-gnss_frames") goods.push_back(readBytes(path));
  }
  std::int64_t frames = 0, malformed = 0;
  for (int round = 0; round < 300; ++round) {
    std::vector<std::uint8_t> stream;
    for (int k = 0; k < 20; ++k) {
      const int kind = static_cast<int>(rng() % 3);
      if (kind == 0) {
        for (int j = 0, n = static_cast<int>(rng() % 64); j < n; ++j) stream.push_back(static_cast<std::uint8_t>(rng()));
      } else {
        const auto& g = goods[rng() % goods.size()];
        std::vector<std::uint8_t> p(g.begin() + 3, g.end() - 3);
        if (kind == 1) {
          for (int j = 0, n = 1 + static_cast<int>(rng() % 8); j < n; ++j) {
            p[2 + rng() % (p.size() - 2)] ^= static_cast<std::uint8_t>(1u << (rng() % 8));
          }
        } else {
          p.resize(2 + rng() % (p.size() - 1));
        }
        const auto f = frameOf(p);
        stream.insert(stream.end(), f.begin(), f.end());
      }
    }
    DecoderOptions opt;
    opt.referenceTime = date(2020, 6, 1);
    Decoder dec(opt);
    std::size_t pos = 0;
    while (pos < stream.size()) {
      const std::size_t n = std::min<std::size_t>(1 + rng() % 300, stream.size() - pos);
      dec.feed({stream.data() + pos, n});
      pos += n;
      while (dec.poll()) {
      }
    }
    dec.finish();
    while (dec.poll()) {
    }
    frames += dec.stats().framing.frames;
    malformed += dec.stats().malformed;
    EXPECT_LE(dec.stats().issues.size(), opt.maxIssues);
  }
  std::cerr << "hostile streams: " << frames << " frames, " << malformed << " malformed\n";
  EXPECT_GT(malformed, 100);
}

}  // namespace
}  // namespace gvins::rtcm
