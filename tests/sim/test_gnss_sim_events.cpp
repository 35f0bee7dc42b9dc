// GNSS simulator, events and bookkeeping: scheduled outages, satellite blockages, NLOS reception
// and cycle slips do what the configuration says and are recorded in the truth; the truth
// ambiguities make double-differenced phases integer; runs are reproducible from the seed.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <set>

#include "gvins/base/constants.hpp"
#include "gvins/sim/gnss_epoch_generator.hpp"
#include "test_gnss_support.hpp"

namespace gvins::sim {
namespace {

using testing::CircleTrajectory;
using testing::nagoyaFrame;
using testing::nagoyaNav;
constexpr double kC = constants::kSpeedOfLight;

GnssSimConfig calmConfig() {
  GnssSimConfig c;
  c.rover.rate = 5.0;
  c.rover.nlos.ratePerMinute = 0.0;
  c.rover.blockage.ratePerMinute = 0.0;
  c.rover.slips.ratePerMinute = 0.0;
  return c;
}

struct SimRun {
  std::vector<GnssSimEpoch> rover, base;
  std::vector<GnssAmbiguityArc> arcs;
  std::vector<GnssSlipEvent> slips;
  std::vector<GnssEventInterval> events;
};

SimRun simulate(const GnssSimConfig& cfg, double duration, std::uint64_t seed, double speed = 6.0) {
  const CircleTrajectory traj(duration, 50.0, 30.0, speed);
  GnssEpochGenerator gen(cfg, nagoyaNav(), traj, nagoyaFrame(), Eigen::Vector3d(0.0, 0.0, 0.1), seed);
  SimRun r;
  while (auto e = gen.next()) (e->role == GnssReceiverRole::Rover ? r.rover : r.base).push_back(std::move(*e));
  gen.finish();
  r.arcs = gen.rover().arcs();
  r.slips = gen.rover().slips();
  r.events = gen.rover().events();
  if (gen.base()) {
    r.arcs.insert(r.arcs.end(), gen.base()->arcs().begin(), gen.base()->arcs().end());
    r.slips.insert(r.slips.end(), gen.base()->slips().begin(), gen.base()->slips().end());
  }
  return r;
}

TEST(GnssSimEvents, ScheduledOutagesSilenceTheReceiverAndRestartEveryArc) {
  GnssSimConfig cfg = calmConfig();
  cfg.rover.outages = {GnssOutage{8.0, 6.0, {true, true, true, true, true, true, true}},
                       GnssOutage{20.0, 4.0, {false, false, true, true, false, false, false}}};  // Galileo+BeiDou
  const SimRun r = simulate(cfg, 30.0, 4);
  const GpsTime t0 = nagoyaFrame().startTime;
  int silent = 0, partial = 0;
  for (std::size_t k = 0; k < r.rover.size(); ++k) {
    const GnssSimEpoch& e = r.rover[k];
    const double ft = e.truth.time - t0;
    if (ft >= 8.0 && ft < 14.0) {
      EXPECT_TRUE(e.obs.sats.empty()) << ft;
      ++silent;
    } else if (ft >= 20.0 && ft < 24.0) {
      ++partial;
      EXPECT_FALSE(e.obs.sats.empty());
      for (const SatObs& so : e.obs.sats)
        EXPECT_TRUE(so.sat.system != System::Galileo && so.sat.system != System::BeiDou) << so.sat.str();
    } else if (k > 0) {
      EXPECT_GT(e.obs.sats.size(), 20u) << ft;
    }
    // First epoch after an outage: every affected signal restarts with the loss-of-lock flag.
    const bool afterTotal = ft >= 14.0 && ft < 14.0 + 0.2;
    const bool afterPartial = ft >= 24.0 && ft < 24.0 + 0.2;
    for (std::size_t i = 0; i < e.obs.sats.size(); ++i) {
      const System s = e.obs.sats[i].sat.system;
      for (std::size_t j = 0; j < e.obs.sats[i].signals.size(); ++j) {
        const bool affected = afterTotal || (afterPartial && (s == System::Galileo || s == System::BeiDou));
        if (!affected) continue;
        EXPECT_TRUE(e.obs.sats[i].signals[j].lli & 1) << e.obs.sats[i].sat.str();
        EXPECT_TRUE(e.truth.sats[i].signals[j].arcStart);
      }
    }
  }
  EXPECT_EQ(silent, 30);
  EXPECT_EQ(partial, 20);
  // Truth: two outage intervals, arcs and restart records with the cause.
  int outages = 0;
  for (const GnssEventInterval& ev : r.events) {
    if (ev.kind != "outage") continue;
    ++outages;
    EXPECT_TRUE(ev.systems == "GRECJSI" || ev.systems == "EC") << ev.systems;
  }
  EXPECT_EQ(outages, 2);
  int outageArcs = 0, outageRestarts = 0;
  for (const GnssAmbiguityArc& a : r.arcs) outageArcs += a.cause == "outage" && a.role == GnssReceiverRole::Rover;
  for (const GnssSlipEvent& s : r.slips) {
    if (s.cause != "outage") continue;
    ++outageRestarts;
    EXPECT_TRUE(s.flagged);
  }
  EXPECT_GT(outageArcs, 100);
  EXPECT_EQ(outageRestarts, outageArcs);
  // The base keeps running.
  EXPECT_EQ(r.base.size(), 30u);
  for (const GnssSimEpoch& e : r.base) EXPECT_GT(e.obs.sats.size(), 20u);
}

TEST(GnssSimEvents, NlosAddsAPositiveExtraPathLowersCn0AndRestartsTracking) {
  GnssSimConfig cfg = calmConfig();
  cfg.rover.nlos = {6.0, 90.0, 3.0, 10.0, 40.0, 10.0};  // frequent, at any elevation
  cfg.rover.cn0.minimum = 0.0;                             // keep every signal to compare C/N0
  cfg.base.enabled = false;
  GnssSimConfig clean = cfg;
  clean.rover.nlos.ratePerMinute = 0.0;
  const SimRun r = simulate(cfg, 20.0, 5), c = simulate(clean, 20.0, 5);
  ASSERT_EQ(r.rover.size(), c.rover.size());
  int nlosSignals = 0, nlosStarts = 0;
  double maxNoiseChange = 0.0;
  for (std::size_t k = 0; k < r.rover.size(); ++k) {
    const GnssReceiverTruth& a = r.rover[k].truth;
    const GnssReceiverTruth& b = c.rover[k].truth;
    ASSERT_EQ(a.sats.size(), b.sats.size());
    for (std::size_t i = 0; i < a.sats.size(); ++i) {
      const GnssSatelliteTruth& sa = a.sats[i];
      if (sa.nlosBias == 0.0) continue;
      EXPECT_GE(sa.nlosBias, 10.0);
      EXPECT_LE(sa.nlosBias, 40.0);
      for (std::size_t j = 0; j < sa.signals.size(); ++j) {
        ++nlosSignals;
        // Same per-signal random draws in both runs: exactly the configured drop.
        const GnssSignalTruth& ga = sa.signals[j];
        const GnssSignalTruth& gb = b.sats[i].signals[j];
        EXPECT_NEAR(ga.cn0, gb.cn0 - 10.0, 1e-9);
        // The weaker signal is noisier: the code noise follows the thermal-noise scaling
        // sigma ~ 10^((45 - C/N0) / 20) of the noise model (DLL jitter ~ 1/sqrt(C/N0)), so the
        // 10 dB drop multiplies the same standard-normal draw by 10^(10/20).
        const double noiseScale = std::pow(10.0, 10.0 / 20.0);
        EXPECT_NEAR(ga.codeSigma, gb.codeSigma * noiseScale, 1e-9 * gb.codeSigma);
        EXPECT_NEAR(ga.codeNoise, gb.codeNoise * noiseScale, 1e-9 * std::abs(gb.codeNoise) + 1e-12);
        // Everything else is the same: the pseudorange differs by the extra path plus the
        // difference of the two noise realisations.
        const SignalObs& o = r.rover[k].obs.sats[i].signals[j];
        const SignalObs& oc = c.rover[k].obs.sats[i].signals[j];
        EXPECT_NEAR(o.pseudorange - oc.pseudorange, sa.nlosBias + (ga.codeNoise - gb.codeNoise), 1e-6);
        maxNoiseChange = std::max(maxNoiseChange, std::abs(ga.codeNoise - gb.codeNoise));
        nlosStarts += sa.signals[j].arcStart;
      }
    }
  }
  EXPECT_GT(nlosSignals, 200);
  EXPECT_GT(nlosStarts, 20);
  std::printf("NLOS: %d signal-epochs, %d tracking restarts, largest code-noise change %.2f m\n", nlosSignals,
              nlosStarts, maxNoiseChange);
  EXPECT_GT(maxNoiseChange, 0.1);  // the noise term is not negligible: it had to be accounted for
  // Every epoch with an extra path lies inside a recorded NLOS interval of that satellite.
  for (const GnssSimEpoch& e : r.rover)
    for (const GnssSatelliteTruth& s : e.truth.sats) {
      if (s.nlosBias == 0.0) continue;
      const bool inside = std::any_of(r.events.begin(), r.events.end(), [&](const GnssEventInterval& ev) {
        return ev.kind == "nlos" && ev.sat == s.sat && !(e.truth.time < ev.start) && e.truth.time < ev.end &&
               std::abs(ev.value - s.nlosBias) < 1e-9;
      });
      EXPECT_TRUE(inside) << s.sat.str();
    }
}

TEST(GnssSimEvents, BlockedSatellitesVanishForTheirInterval) {
  GnssSimConfig cfg = calmConfig();
  cfg.rover.blockage = {3.0, 90.0, 2.0};
  cfg.base.enabled = false;
  const SimRun r = simulate(cfg, 20.0, 6);
  int blockages = 0, checked = 0;
  for (const GnssEventInterval& ev : r.events) {
    if (ev.kind != "blockage") continue;
    ++blockages;
    EXPECT_GT(ev.end - ev.start, 0.0);
    for (const GnssSimEpoch& e : r.rover) {
      if (e.truth.time < ev.start || !(e.truth.time < ev.end)) continue;
      EXPECT_EQ(e.obs.find(ev.sat), nullptr) << ev.sat.str() << " " << e.obs.time.toString();
      ++checked;
    }
  }
  EXPECT_GT(blockages, 30);
  EXPECT_GT(checked, 100);
}

TEST(GnssSimEvents, CycleSlipsJumpTheAmbiguityAndAreFlaggedAsConfigured) {
  GnssSimConfig cfg = calmConfig();
  cfg.rover.slips = {3.0, 5, 0.6};
  cfg.base.enabled = false;
  const SimRun r = simulate(cfg, 30.0, 8);
  // Ambiguity of each signal per epoch from the truth, to find every jump.
  std::map<std::pair<SatId, std::string>, std::pair<std::int64_t, std::size_t>> last;
  int jumps = 0, flagged = 0;
  for (std::size_t k = 0; k < r.rover.size(); ++k) {
    const GnssSimEpoch& e = r.rover[k];
    for (std::size_t i = 0; i < e.truth.sats.size(); ++i) {
      for (std::size_t j = 0; j < e.truth.sats[i].signals.size(); ++j) {
        const GnssSignalTruth& g = e.truth.sats[i].signals[j];
        const auto key = std::make_pair(e.truth.sats[i].sat, g.code.str());
        const auto it = last.find(key);
        if (it != last.end() && it->second.second + 1 == k && !g.arcStart) {
          EXPECT_EQ(g.ambiguity, it->second.first);
        }
        if (it != last.end() && it->second.second + 1 == k && g.arcStart) {
          // A slip of a continuously tracked signal: recorded with its size and flag.
          const auto s = std::find_if(r.slips.begin(), r.slips.end(), [&](const GnssSlipEvent& x) {
            return x.tag == e.obs.time && x.sat == key.first && x.code == g.code;
          });
          ASSERT_NE(s, r.slips.end());
          EXPECT_EQ(s->jump, g.ambiguity - it->second.first);
          EXPECT_GE(std::abs(s->jump), 1);
          EXPECT_LE(std::abs(s->jump), 5);
          EXPECT_EQ(s->flagged, (e.obs.sats[i].signals[j].lli & 1) == 1);
          ++jumps;
          flagged += s->flagged;
        }
        last[key] = {g.ambiguity, k};
      }
    }
  }
  // 3 per minute per signal over ~30 s and ~100 signals: ~150 slips, 60 % flagged.
  EXPECT_GT(jumps, 80);
  EXPECT_NEAR(static_cast<double>(flagged) / jumps, 0.6, 0.15);
}

TEST(GnssSimEvents, TruthAmbiguitiesMakeDoubleDifferencedPhasesIntegers) {
  // Rover and base phases minus their true ranges, clocks and truth ambiguities, double
  // differenced: only the differential atmosphere, multipath and noise remain (a few mm), so the
  // truth ambiguities are the integers an RTK engine must find.
  GnssSimConfig cfg = calmConfig();
  const SimRun r = simulate(cfg, 20.0, 9);
  std::map<std::int64_t, const GnssSimEpoch*> base;
  for (const GnssSimEpoch& e : r.base) base[e.obs.time.wholeSeconds()] = &e;
  double worst = 0.0;
  int n = 0;
  for (const GnssSimEpoch& e : r.rover) {
    if (e.obs.time.fraction() != 0.0) continue;
    const auto b = base.find(e.obs.time.wholeSeconds());
    if (b == base.end()) continue;
    // Single differences (rover - base) of the GPS L1 phase residual in cycles, per satellite.
    std::vector<double> sd;
    for (std::size_t i = 0; i < e.truth.sats.size(); ++i) {
      const GnssSatelliteTruth& st = e.truth.sats[i];
      if (st.sat.system != System::Gps || st.azel.elevation < 15.0 * constants::kDegToRad) continue;
      const SatObs* bo = b->second->obs.find(st.sat);
      if (!bo) continue;
      const std::size_t bi = static_cast<std::size_t>(bo - b->second->obs.sats.data());
      const GnssSatelliteTruth& bt = b->second->truth.sats[bi];
      auto residual = [](const ObsEpoch& o, const GnssReceiverTruth& t, std::size_t k) {
        const GnssSatelliteTruth& s = t.sats[k];
        const GnssSignalTruth& g = s.signals.front();
        const double lambda = g.wavelength;
        return o.sats[k].signals.front().carrierPhase - static_cast<double>(g.ambiguity) -
               (s.range + kC * t.systemClockBias[systemIndex(s.sat.system)] - kC * s.satClock) / lambda;
      };
      sd.push_back(residual(e.obs, e.truth, i) - residual(b->second->obs, b->second->truth, bi));
      (void)bt;
    }
    for (std::size_t k = 1; k < sd.size(); ++k) {
      worst = std::max(worst, std::abs(sd[k] - sd[0]));
      ++n;
    }
  }
  EXPECT_GT(n, 100);
  EXPECT_LT(worst, 0.25);  // cycles: differential troposphere/ionosphere/multipath at 3 km
}

TEST(GnssSimEvents, SeedsMakeRunsReproducible) {
  const GnssSimConfig cfg;
  const SimRun a = simulate(cfg, 5.0, 42), b = simulate(cfg, 5.0, 42), c = simulate(cfg, 5.0, 43);
  ASSERT_EQ(a.rover.size(), b.rover.size());
  bool anyDifferent = false;
  for (std::size_t k = 0; k < a.rover.size(); ++k) {
    ASSERT_EQ(a.rover[k].obs.sats.size(), b.rover[k].obs.sats.size());
    for (std::size_t i = 0; i < a.rover[k].obs.sats.size(); ++i)
      for (std::size_t j = 0; j < a.rover[k].obs.sats[i].signals.size(); ++j) {
        EXPECT_EQ(a.rover[k].obs.sats[i].signals[j].pseudorange, b.rover[k].obs.sats[i].signals[j].pseudorange);
        EXPECT_EQ(a.rover[k].obs.sats[i].signals[j].carrierPhase, b.rover[k].obs.sats[i].signals[j].carrierPhase);
      }
    if (k < c.rover.size() && !c.rover[k].obs.sats.empty() && !a.rover[k].obs.sats.empty())
      anyDifferent = anyDifferent || c.rover[k].obs.sats[0].signals[0].pseudorange != a.rover[k].obs.sats[0].signals[0].pseudorange;
  }
  EXPECT_TRUE(anyDifferent);
}

TEST(GnssSimEvents, SignalsElevationMaskAndReportedClock) {
  GnssSimConfig cfg = calmConfig();
  cfg.rover.elevationMaskDeg = 20.0;
  cfg.base.enabled = false;
  const SimRun r = simulate(cfg, 4.0, 10);
  std::set<SatId> seen;
  for (const GnssSimEpoch& e : r.rover) {
    ASSERT_TRUE(e.obs.receiverClockOffset);
    EXPECT_NEAR(*e.obs.receiverClockOffset, e.truth.clockBias, 6.0 * cfg.rover.clock.reportSigma);
    for (std::size_t i = 0; i < e.obs.sats.size(); ++i) {
      const SatObs& so = e.obs.sats[i];
      seen.insert(so.sat);
      EXPECT_GE(e.truth.sats[i].azel.elevation, 20.0 * constants::kDegToRad);
      std::set<std::string> codes;
      for (const SignalObs& g : so.signals) codes.insert(g.code.str());
      if (so.sat.system == System::BeiDou) {
        EXPECT_EQ(codes.count("7I"), so.sat.prn <= 18 ? 1u : 0u) << so.sat.str();  // B2I: BDS-2 only
        EXPECT_EQ(codes.count("2I"), 1u);
        EXPECT_EQ(codes.count("6I"), 1u);
      }
      if (so.sat.system == System::Glonass) {
        // FDMA: the wavelength follows the channel of the navigation data.
        const double f = kC / e.truth.sats[i].signals.front().wavelength;
        EXPECT_NEAR(std::fmod(f - 1602e6, 562.5e3), 0.0, 1e-3);
        EXPECT_EQ(codes, (std::set<std::string>{"1C", "2C"}));
      }
      if (so.sat.system == System::Gps) {
        EXPECT_EQ(codes, (std::set<std::string>{"1C", "2W", "5Q"}));
      }
    }
  }
  EXPECT_GT(seen.size(), 25u);
}

}  // namespace
}  // namespace gvins::sim
