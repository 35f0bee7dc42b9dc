// Doppler sanity per receiver and signal on real data: the Nagoya receivers (every signal with
// Doppler) are judged consistent as recorded; copies with the Doppler sign flipped (all signals,
// one signal), scaled or replaced by noise are detected, named in one warning each, corrected or
// dropped, and SPP velocities and RTK results then equal those of the original data. A receiver
// clock drift common to Doppler, phase and code, clock jumps and cycle slips do not move the
// verdict; files without Doppler (Kamakura, GEONET) raise nothing.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "gvins/base/constants.hpp"
#include "gvins/base/geodetic.hpp"
#include "gvins/base/rinex_obs_reader.hpp"
#include "gvins/ephemeris/rinex_nav.hpp"
#include "gvins/gnss/base_reader.hpp"
#include "gvins/gnss/doppler_consistency.hpp"
#include "gvins/gnss/rtk.hpp"
#include "gvins/gnss/spp.hpp"
#include "nagoya_pair.hpp"

using namespace gvins;

namespace {

const std::string kData = GVINS_TEST_DATA;

using Nagoya = test::RecordedPair;
const Nagoya& nagoya() { return test::nagoyaPair(); }

using Doctor = std::function<void(SatId, SignalObs&, const ObsEpoch&)>;

std::vector<ObsEpoch> doctored(const std::vector<ObsEpoch>& in, const Doctor& f) {
  std::vector<ObsEpoch> out = in;
  for (ObsEpoch& e : out) {
    for (SatObs& so : e.sats) {
      for (SignalObs& s : so.signals) f(so.sat, s, e);
    }
  }
  return out;
}

void flipAll(SatId, SignalObs& s, const ObsEpoch&) {
  if (s.hasDoppler()) s.doppler = -s.doppler;
}

Doctor flipOnly(System sys, ObsCode code) {
  return [sys, code](SatId sat, SignalObs& s, const ObsEpoch&) {
    if (sat.system == sys && s.code == code && s.hasDoppler()) s.doppler = -s.doppler;
  };
}

DopplerConsistency judge(const std::vector<ObsEpoch>& epochs, const GlonassChannels& ch, const std::string& label) {
  DopplerConsistency d(label);
  for (ObsEpoch e : epochs) d.apply(e, ch);
  return d;
}

int countVerdict(const DopplerConsistency& d, DopplerVerdict v) {
  const auto s = d.signals();
  return static_cast<int>(std::count_if(s.begin(), s.end(), [v](const DopplerSignalReport& r) { return r.verdict == v; }));
}

/// SPP velocities of every epoch after the Doppler check (nullopt where there is none).
std::vector<std::optional<Eigen::Vector3d>> sppVelocities(const std::vector<ObsEpoch>& epochs, bool check,
                                                          DopplerConsistency* doppler = nullptr) {
  const Nagoya& d = nagoya();
  SppSolver spp(d.nav);
  spp.setGlonassChannels(d.roverHeader.glonassChannels);
  DopplerConsistency local("rover");
  DopplerConsistency& dc = doppler ? *doppler : local;
  std::vector<std::optional<Eigen::Vector3d>> v;
  for (ObsEpoch e : epochs) {
    if (check) dc.apply(e, d.roverHeader.glonassChannels);
    const SppSolution s = spp.solve(e);
    v.push_back(s.velocity.valid ? std::optional<Eigen::Vector3d>(s.velocity.velocity) : std::nullopt);
  }
  return v;
}

struct RtkRun {
  int fixed = 0;
  CycleSlipCounts rover, base;
  std::vector<std::string> roverWarnings, baseWarnings;
};

RtkRun runRtk(const std::vector<ObsEpoch>& rover, const std::vector<ObsEpoch>& base, int epochs) {
  const Nagoya& d = nagoya();
  RtkSolver s(d.nav);
  s.setRoverGlonassChannels(d.roverHeader.glonassChannels);
  s.setBaseGlonassChannels(d.baseHeader.glonassChannels);
  s.setBasePosition(d.basePosition);
  std::size_t b = 0;
  RtkRun r;
  for (int i = 0; i < epochs; ++i) {
    const ObsEpoch& e = rover[static_cast<std::size_t>(i)];
    while (b < base.size() && (b == 0 || base[b - 1].time - e.time <= BaseStation::kSyncTolerance)) s.addBaseEpoch(base[b++]);
    if (s.process(e).quality == SolutionQuality::Fix) ++r.fixed;
  }
  r.rover = s.roverSlipCounts();
  r.base = s.base().slipCounts();
  r.roverWarnings = s.roverDoppler().warnings();
  r.baseWarnings = s.base().doppler().warnings();
  return r;
}

}  // namespace

TEST(DopplerConsistency, RecordedFilesAreConsistent) {
  const Nagoya& d = nagoya();
  for (const auto* set : {&d.rover, &d.base}) {
    const DopplerConsistency c = judge(*set, d.roverHeader.glonassChannels, "rover");
    // Every signal of the Septentrio receivers (GPS L1C/L2W/L2L/L5Q, Galileo, GLONASS, BeiDou,
    // QZSS: 15) is decided and consistent: no warning, nothing corrected or dropped.
    const auto signals = c.signals();
    EXPECT_EQ(signals.size(), 15u);
    for (const DopplerSignalReport& r : signals) {
      EXPECT_EQ(r.verdict, DopplerVerdict::Consistent) << r.name();
      EXPECT_TRUE(r.fromPhase) << r.name();
      EXPECT_LT(r.medianConsistent, 0.05) << r.name();  // m/s: Doppler and phase rate agree
      EXPECT_GT(r.medianFlipped, 50.0) << r.name();     // twice the satellites' range rates
    }
    EXPECT_TRUE(c.warnings().empty());
    EXPECT_TRUE(c.summary().empty());
    EXPECT_EQ(c.counts().corrected, 0);
    EXPECT_EQ(c.counts().dropped, 0);
    EXPECT_GT(c.counts().passed, 30000);
  }
  // No Doppler at all: nothing to judge, nothing withheld, no warning.
  for (const std::string f : {"/gnss/kamakura_static_2021/SEPT078M.21O.gz", "/gnss/geonet_0759_3040_2005/07590920.05o.gz",
                              "/gnss/geonet_0759_3040_2005/30400920.05o.gz"}) {
    const DopplerConsistency c = judge(readRinexObs(kData + f), {}, "rover");
    EXPECT_TRUE(c.signals().empty()) << f;
    EXPECT_TRUE(c.warnings().empty()) << f;
    EXPECT_EQ(c.counts().withheld + c.counts().dropped + c.counts().passed, 0) << f;
  }
}

TEST(DopplerConsistency, RtcmMsm7StreamIsConsistent) {
  // IGS station GMSD as RTCM 3 MSM7 (GPS, GLONASS, QZSS, BeiDou): the decoder's Doppler (from the
  // MSM phase-range rate) agrees with its phase rate on every signal.
  EphemerisStore nav;
  auto reader = BaseReader::open(kData + "/rtcm/rtklib_GMSD7_20121014.rtcm3",
                                 GpsTime::fromCalendar({2012, 10, 13, 12, 0, 0.0}), &nav);
  std::vector<ObsEpoch> epochs;
  for (ObsEpoch e; reader->next(e);) epochs.push_back(e);
  ASSERT_GT(epochs.size(), 200u);
  const DopplerConsistency c = judge(epochs, reader->glonassChannels(), "base");
  const auto signals = c.signals();
  ASSERT_EQ(signals.size(), 4u);  // G L1C, R L1C, J L1C (one satellite), C L2I
  for (const DopplerSignalReport& r : signals) {
    EXPECT_EQ(r.verdict, DopplerVerdict::Consistent) << r.name();
    EXPECT_LT(r.medianConsistent, 0.05) << r.name();
    EXPECT_GT(r.medianFlipped, 50.0) << r.name();
  }
  EXPECT_TRUE(c.warnings().empty());
  EXPECT_EQ(c.counts().dropped + c.counts().corrected, 0);
  // The same stream with the receiver quirk of a flipped MSM Doppler: every signal corrected.
  const DopplerConsistency f = judge(doctored(epochs, flipAll), reader->glonassChannels(), "base");
  EXPECT_EQ(countVerdict(f, DopplerVerdict::SignFlipped), 4);
  EXPECT_EQ(f.warnings().size(), 4u);
}

TEST(DopplerConsistency, FlippedSignIsCorrectedAndSppVelocitiesAreTheOriginal) {
  const Nagoya& d = nagoya();
  const std::vector<ObsEpoch> flipped = doctored(d.rover, flipAll);
  // Unchecked, the flipped Doppler gives km/s velocities for a static receiver.
  const auto raw = sppVelocities(flipped, false);
  ASSERT_TRUE(raw[10]);
  EXPECT_GT(raw[10]->norm(), 500.0);

  DopplerConsistency dc("rover");
  const auto fixedV = sppVelocities(flipped, true, &dc);
  const auto original = sppVelocities(d.rover, true);
  ASSERT_EQ(fixedV.size(), original.size());
  int compared = 0;
  for (std::size_t i = 0; i < original.size(); ++i) {
    ASSERT_EQ(fixedV[i].has_value(), original[i].has_value()) << i;
    if (!original[i]) continue;
    EXPECT_LT((*fixedV[i] - *original[i]).norm(), 1e-6) << i;
    EXPECT_LT(original[i]->norm(), 0.1) << i;  // static receiver
    ++compared;
  }
  // The first three epochs wait for the verdict (Doppler withheld), every later one has a velocity.
  EXPECT_EQ(compared, 298);
  EXPECT_EQ(countVerdict(dc, DopplerVerdict::SignFlipped), 15);
  ASSERT_EQ(dc.warnings().size(), 15u);
  const auto& w = dc.warnings();
  EXPECT_NE(std::find(w.begin(), w.end(), "rover: Doppler sign flipped on G L1C (corrected)"), w.end());
  EXPECT_NE(std::find(w.begin(), w.end(), "rover: Doppler sign flipped on R L1C (corrected)"), w.end());
  EXPECT_GT(dc.counts().corrected, 30000);
  EXPECT_EQ(dc.counts().passed, 0);
  EXPECT_EQ(dc.counts().dropped, 0);
}

TEST(DopplerConsistency, OneFlippedSignalIsNamedAlone) {
  const Nagoya& d = nagoya();
  const std::vector<ObsEpoch> flipped = doctored(d.rover, flipOnly(System::Galileo, ObsCode('5', 'Q')));
  DopplerConsistency dc("rover");
  const auto v = sppVelocities(flipped, true, &dc);
  const auto original = sppVelocities(d.rover, true);
  for (std::size_t i = 0; i < original.size(); ++i) {
    ASSERT_EQ(v[i].has_value(), original[i].has_value()) << i;
    if (original[i]) {
      EXPECT_LT((*v[i] - *original[i]).norm(), 1e-6) << i;
    }
  }
  ASSERT_EQ(dc.warnings().size(), 1u);
  EXPECT_EQ(dc.warnings()[0], "rover: Doppler sign flipped on E L5Q (corrected)");
  EXPECT_EQ(dc.verdict(System::Galileo, ObsCode('5', 'Q')), DopplerVerdict::SignFlipped);
  EXPECT_EQ(dc.verdict(System::Galileo, ObsCode('1', 'C')), DopplerVerdict::Consistent);
  EXPECT_EQ(countVerdict(dc, DopplerVerdict::Consistent), 14);
  ASSERT_EQ(dc.summary().size(), 1u);
  EXPECT_EQ(dc.summary()[0].rfind("rover: Doppler sign flipped on E L5Q (corrected; ", 0), 0u) << dc.summary()[0];
}

TEST(DopplerConsistency, RtkOnFlippedDataEqualsTheOriginal) {
  const Nagoya& d = nagoya();
  constexpr int kEpochs = 120;
  const RtkRun original = runRtk(d.rover, d.base, kEpochs);
  // Rover: every signal flipped; base: GPS L2W only.
  const RtkRun flipped = runRtk(doctored(d.rover, flipAll), doctored(d.base, flipOnly(System::Gps, ObsCode('2', 'W'))), kEpochs);
  EXPECT_EQ(original.fixed, kEpochs);
  EXPECT_EQ(flipped.fixed, original.fixed);
  EXPECT_EQ(flipped.rover.doppler, original.rover.doppler);
  EXPECT_EQ(flipped.base.doppler, original.base.doppler);
  EXPECT_EQ(flipped.rover.checked, original.rover.checked);
  EXPECT_LT(original.rover.doppler, 5);
  EXPECT_TRUE(original.roverWarnings.empty());
  EXPECT_TRUE(original.baseWarnings.empty());
  EXPECT_EQ(flipped.roverWarnings.size(), 15u);
  ASSERT_EQ(flipped.baseWarnings.size(), 1u);
  EXPECT_EQ(flipped.baseWarnings[0], "base: Doppler sign flipped on G L2W (corrected)");
}

TEST(DopplerConsistency, ScaledOrRandomDopplerIsDropped) {
  const Nagoya& d = nagoya();
  // GPS L1C Doppler with a wrong factor (a GLONASS-like wavelength error of 1575.42/1602): dropped,
  // the velocity comes from the other GPS signals' Doppler and stays that of a static receiver.
  const double k = 1575.42 / 1602.0;
  const auto scaled = doctored(d.rover, [k](SatId sat, SignalObs& s, const ObsEpoch&) {
    if (sat.system == System::Gps && s.code == ObsCode('1', 'C') && s.hasDoppler()) s.doppler *= k;
  });
  DopplerConsistency dc("rover");
  const auto v = sppVelocities(scaled, true, &dc);
  EXPECT_EQ(dc.verdict(System::Gps, ObsCode('1', 'C')), DopplerVerdict::Scaled);
  const auto reports = dc.signals();
  const auto it = std::find_if(reports.begin(), reports.end(),
                               [](const DopplerSignalReport& r) { return r.verdict == DopplerVerdict::Scaled; });
  ASSERT_NE(it, reports.end());
  EXPECT_NEAR(it->factor, k, 1e-4);
  ASSERT_EQ(dc.warnings().size(), 1u);
  EXPECT_EQ(dc.warnings()[0].rfind("rover: Doppler scaled by 0.9834 against the carrier-phase rate on G L1C (dropped)", 0), 0u)
      << dc.warnings()[0];
  EXPECT_GT(dc.counts().dropped, 2000);
  int valid = 0;
  for (const auto& x : v) {
    if (!x) continue;
    ++valid;
    EXPECT_LT(x->norm(), 0.1);
  }
  EXPECT_EQ(valid, 298);

  // Noise instead of Doppler on every signal: all dropped, no velocity at all.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> noise(-5000.0, 5000.0);
  const auto random = doctored(d.rover, [&](SatId, SignalObs& s, const ObsEpoch&) {
    if (s.hasDoppler()) s.doppler = noise(rng);
  });
  DopplerConsistency dr("rover");
  const auto vr = sppVelocities(random, true, &dr);
  EXPECT_EQ(countVerdict(dr, DopplerVerdict::Inconsistent), 15);
  EXPECT_EQ(dr.warnings().size(), 15u);
  EXPECT_EQ(dr.counts().passed + dr.counts().corrected, 0);
  EXPECT_TRUE(std::none_of(vr.begin(), vr.end(), [](const auto& x) { return x.has_value(); }));
}

TEST(DopplerConsistency, PseudorangeRateJudgesSignalsWithoutPhase) {
  const Nagoya& d = nagoya();
  auto noPhase = [](SatId, SignalObs& s, const ObsEpoch&) {
    s.carrierPhase = 0.0;
    s.present = static_cast<std::uint8_t>(s.present & ~SignalObs::kPhase);
  };
  const auto codeOnly = doctored(d.rover, noPhase);
  const DopplerConsistency ok = judge(codeOnly, d.roverHeader.glonassChannels, "rover");
  EXPECT_EQ(countVerdict(ok, DopplerVerdict::Consistent), 15);
  for (const auto& r : ok.signals()) EXPECT_FALSE(r.fromPhase) << r.name();
  const DopplerConsistency bad = judge(doctored(codeOnly, flipAll), d.roverHeader.glonassChannels, "rover");
  EXPECT_EQ(countVerdict(bad, DopplerVerdict::SignFlipped), 15);
}

TEST(DopplerConsistency, ClockDriftJumpsAndSlipsDoNotMoveTheVerdict) {
  const Nagoya& d = nagoya();
  const GpsTime t0 = d.rover.front().time;
  // A free-running receiver oscillator 2 ppm off (600 m/s of clock drift) seen alike by Doppler,
  // phase and code; a 1 ms clock jump in phase and code (not Doppler) at epoch 1; undetected
  // cycle slips of 1000 cycles (no LLI) at epoch 2 on every satellite with a PRN divisible by 5
  // (a third of GPS): 44 % of the GPS samples of the first three intervals are outliers.
  auto doctor = [&](SatId sat, SignalObs& s, const ObsEpoch& e) {
    const double drift = 2e-6;  // s/s
    const auto f = carrierFrequency(sat.system, s.code.band, sat.system == System::Glonass
                                                                 ? d.roverHeader.glonassChannels.get(sat.prn)
                                                                 : std::optional<int>());
    if (!f) return;
    const double dt = e.time - t0;
    const double jump = dt > 0.5 ? 1e-3 : 0.0;  // s, from epoch 1 on
    if (s.hasDoppler()) s.doppler -= *f * drift;
    const double slip = sat.prn % 5 == 0 && dt > 1.5 ? 1000.0 : 0.0;  // cycles, from epoch 2 on
    if (s.hasPhase()) s.carrierPhase += *f * (drift * dt + jump) + slip;
    if (s.hasCode()) s.pseudorange += constants::kSpeedOfLight * (drift * dt + jump);
  };
  const auto drifting = doctored(d.rover, doctor);
  const DopplerConsistency ok = judge(drifting, d.roverHeader.glonassChannels, "rover");
  EXPECT_EQ(countVerdict(ok, DopplerVerdict::Consistent), 15);
  EXPECT_TRUE(ok.warnings().empty());
  const DopplerConsistency bad = judge(doctored(drifting, flipAll), d.roverHeader.glonassChannels, "rover");
  EXPECT_EQ(countVerdict(bad, DopplerVerdict::SignFlipped), 15);
}

TEST(DopplerConsistency, SmallRangeRatesWaitThenTakeTheConvention) {
  // One satellite at a constant range rate (exact RINEX-convention data: L(t) = L0 − D·t): at
  // 500 Hz (95 m/s) the two hypotheses are far apart and the verdict comes once enough intervals
  // are in (patientIntervals waives the satellite count); at 1 Hz (0.19 m/s, a geostationary
  // satellite) both fit, the Doppler is withheld until maxPendingIntervals, then the convention.
  for (const double dopplerHz : {500.0, 1.0}) {
    DopplerConsistency dc("rover");
    const GpsTime t0 = GpsTime::fromWeekTow(2000, 0.0);
    int decidedAt = -1;
    for (int i = 0; i <= 70; ++i) {
      ObsEpoch e;
      e.time = t0 + static_cast<double>(i);
      SignalObs s;
      s.code = ObsCode('1', 'C');
      s.setCode(2.2e7 - 0.19029367 * dopplerHz * i);
      s.setPhase(1.1e8 - dopplerHz * i);
      s.setDoppler(dopplerHz);
      e.add(SatId{System::Gps, 1}).signals.push_back(s);
      dc.apply(e);
      if (decidedAt < 0 && dc.verdict(System::Gps, s.code) != DopplerVerdict::Pending) decidedAt = i;
      const SignalObs& out = e.sats[0].signals[0];
      EXPECT_EQ(out.hasDoppler(), decidedAt >= 0) << i;
      if (out.hasDoppler()) {
        EXPECT_EQ(out.doppler, dopplerHz);
      }
    }
    EXPECT_EQ(dc.verdict(System::Gps, ObsCode('1', 'C')), DopplerVerdict::Consistent) << dopplerHz;
    EXPECT_EQ(decidedAt, dopplerHz > 100.0 ? 12 : dc.options().maxPendingIntervals) << dopplerHz;
    EXPECT_TRUE(dc.warnings().empty());
  }
}
