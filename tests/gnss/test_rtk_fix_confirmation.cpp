// Confirmation of marginal fixes (docs/rtk.md, "Integrity of the fix", rule 5) on the real GEONET
// 0759-3040 pair (3.34 km, GPS L1/L2, 120 epochs at 30 s; tests/data/README.md), every epoch on
// its own (instantaneous AR) with few satellites: a fix whose ratio is below twice its critical
// ratio needs another validated fix of the same DD integers on the same arcs. Truth: the last
// epoch of RTKLIB 2.4.3's static fixed solution of the pair (stored with its command); a wrong
// fix is a fixed epoch more than 0.10 m from it, as in bench/gnss/integrity.py.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "gvins/base/constants.hpp"
#include "gvins/gnss/pos_reader.hpp"
#include "gvins/gnss/rtk.hpp"
#include "nagoya_pair.hpp"

using namespace gvins;

namespace {

const std::string kData = GVINS_TEST_DATA;

const test::RecordedPair& geonet() {
  static const test::RecordedPair d = [] {
    test::RecordedPair s;
    const std::string dir = kData + "/gnss/geonet_0759_3040_2005/";
    s.rover = readRinexObs(dir + "07590920.05o.gz", &s.roverHeader);
    s.base = readRinexObs(dir + "30400920.05o.gz", &s.baseHeader);
    s.nav.add(readRinexNav(dir + "30400920.05n.gz"));
    s.basePosition = Eigen::Vector3d(-3978242.4348, 3382841.1715, 3649902.7667);  // as bench/gnss/integrity.py
    s.truth = readPosFile(kData + "/reference/rtklib-2.4.3/geonet_0759_rtk_static.pos").solutions.back().position;
    return s;
  }();
  return d;
}

/// Every rover epoch, the base epochs up to its time and the first one after it (as gvins-rtk).
std::vector<RtkSolution> run(const RtkConfig& cfg, RtkCounters* counters = nullptr) {
  const test::RecordedPair& d = geonet();
  RtkSolver s(d.nav, cfg);
  s.setBasePosition(d.basePosition);
  std::vector<RtkSolution> out;
  std::size_t next = 0;
  for (const ObsEpoch& e : d.rover) {
    while (next < d.base.size() && (next == 0 || d.base[next - 1].time - e.time <= BaseStation::kSyncTolerance)) {
      s.addBaseEpoch(d.base[next]);
      ++next;
    }
    out.push_back(s.process(e));
  }
  if (counters) *counters = s.counters();
  return out;
}

RtkConfig instantaneous(double maskDeg, int frequencies) {
  RtkConfig c;
  c.systems = parseSystemLetters("G");
  c.frequencies = frequencies;
  c.elevationMask = c.arElevationMask = maskDeg * constants::kDegToRad;
  c.ambiguityMode = AmbiguityMode::Instantaneous;
  return c;
}

int fixed(const std::vector<RtkSolution>& sol) {
  return static_cast<int>(std::count_if(sol.begin(), sol.end(), [](const RtkSolution& s) { return s.quality == SolutionQuality::Fix; }));
}

int wrong(const std::vector<RtkSolution>& sol) {
  return static_cast<int>(std::count_if(sol.begin(), sol.end(), [](const RtkSolution& s) {
    return s.quality == SolutionQuality::Fix && (s.position - geonet().truth).norm() > 0.10;
  }));
}

}  // namespace

// 35 deg mask: four GPS satellites most of the hour, bootstrapped success rate ~0.25, critical
// ratios 12-22. Marginal fixes separated by epochs without a fix are confirmed by the earlier fix
// of the same integers on the same arcs; with the previous epoch's fix as the only confirmation
// 14 epochs were fixed (RTKLIB 2.4.3, ratio 3: 68, none wrong).
TEST(RtkFixConfirmation, EarlierFixOnTheSameArcsConfirmsAMarginalFix) {
  const RtkConfig c = instantaneous(35.0, 2);
  RtkCounters counters;
  const std::vector<RtkSolution> sol = run(c, &counters);
  ASSERT_EQ(sol.size(), 120u);
  EXPECT_EQ(wrong(sol), 0);
  EXPECT_GE(fixed(sol), 24);
  int confirmedByAnEarlierFix = 0;
  for (std::size_t i = 1; i < sol.size(); ++i) {
    const RtkSolution& s = sol[i];
    if (s.quality != SolutionQuality::Fix) continue;
    EXPECT_LE(std::sqrt(s.positionCovariance.trace()), c.maxFixedSigma + 1e-12) << i;
    const bool marginal = s.ratio < c.confirmRatioFactor * s.criticalRatio;
    const bool previousValidated = sol[i - 1].quality == SolutionQuality::Fix || sol[i - 1].ar == ArStatus::Unconfirmed;
    if (marginal && !previousValidated) ++confirmedByAnEarlierFix;
  }
  EXPECT_GE(confirmedByAnEarlierFix, 5);
  EXPECT_GT(counters.unconfirmedFixes, 0);  // the first marginal fix of each arc set still waits
}

// The same rule on the other weak GEONET variants: more fixes, none wrong (before: 25 deg 102 of
// 120 fixed, L1 only none; RTKLIB 2.4.3: 114 and 31, none wrong).
TEST(RtkFixConfirmation, WeakGeonetVariantsFixMoreAndNeverWrong) {
  const std::vector<RtkSolution> mask25 = run(instantaneous(25.0, 2));
  EXPECT_EQ(wrong(mask25), 0);
  EXPECT_GE(fixed(mask25), 104);
  const std::vector<RtkSolution> l1 = run(instantaneous(15.0, 1));
  EXPECT_EQ(wrong(l1), 0);
  EXPECT_GE(fixed(l1), 1);
}
