// Whole-millisecond receiver clock jumps (clock_jump_repair.hpp) on real data: the Nagoya rover
// (Septentrio mosaic-X5, 1 Hz, every signal with code and phase) as recorded has none; copies
// with +1 ms added to every pseudorange from one epoch on, −2 ms to every carrier phase from
// another, or both at once (the u-blox case), are detected at exactly those epochs, named in one
// warning each, and repaired to the recorded values (truth: the unmodified file). SPP on the
// repaired copy equals SPP on the original.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "gvins/base/constants.hpp"
#include "gvins/base/signal.hpp"
#include "gvins/gnss/clock_jump_repair.hpp"
#include "gvins/gnss/spp.hpp"
#include "nagoya_pair.hpp"

using namespace gvins;

namespace {

constexpr double kMs = constants::kSpeedOfLight * 1e-3;

// A copy of `in` with `codeMs` added to every pseudorange from epoch `codeFrom` on and `phaseMs`
// to every phase (in cycles of its band) from `phaseFrom` on.
std::vector<ObsEpoch> jumped(const std::vector<ObsEpoch>& in, const GlonassChannels& ch, std::size_t codeFrom,
                             int codeMs, std::size_t phaseFrom, int phaseMs) {
  std::vector<ObsEpoch> out = in;
  for (std::size_t i = 0; i < out.size(); ++i) {
    for (SatObs& so : out[i].sats) {
      std::optional<int> channel;
      if (so.sat.system == System::Glonass) channel = ch.get(so.sat.prn);
      const auto lambda = [&](char band) { return carrierWavelength(so.sat.system, band, channel); };
      for (SignalObs& s : so.signals) {
        if (i >= codeFrom && s.hasCode()) s.pseudorange += codeMs * kMs;
        if (i >= phaseFrom && s.hasPhase() && s.carrierPhase != 0.0 && lambda(s.code.band))
          s.carrierPhase += phaseMs * kMs / *lambda(s.code.band);
      }
    }
  }
  return out;
}

struct Repaired {
  std::vector<ObsEpoch> epochs;
  ClockJumpRepair repair{"rover"};
};

void repairAll(Repaired& r, const GlonassChannels& ch) {
  for (ObsEpoch& e : r.epochs) r.repair.apply(e, ch);
}

GlonassChannels channels() {
  GlonassChannels ch = test::nagoyaPair().roverHeader.glonassChannels;
  ch.mergeMissing(test::nagoyaPair().nav.glonassChannels());
  return ch;
}

// Largest difference of code (m) and phase (m) between two copies.
std::pair<double, double> largestDifference(const std::vector<ObsEpoch>& a, const std::vector<ObsEpoch>& b) {
  double dc = 0.0, dp = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    for (std::size_t j = 0; j < a[i].sats.size(); ++j) {
      const SatObs& sa = a[i].sats[j];
      const SatObs& sb = b[i].sats[j];
      for (std::size_t k = 0; k < sa.signals.size(); ++k) {
        const auto lambda = carrierWavelength(sa.sat.system, sa.signals[k].code.band, 0).value_or(0.2);
        dc = std::max(dc, std::abs(sa.signals[k].pseudorange - sb.signals[k].pseudorange));
        dp = std::max(dp, lambda * std::abs(sa.signals[k].carrierPhase - sb.signals[k].carrierPhase));
      }
    }
  }
  return {dc, dp};
}

}  // namespace

TEST(ClockJumpRepair, RecordedDataHasNone) {
  Repaired r;
  r.epochs = test::nagoyaPair().rover;
  repairAll(r, channels());
  EXPECT_EQ(r.repair.jumps(), 0);
  EXPECT_TRUE(r.repair.warnings().empty());
  const auto [dc, dp] = largestDifference(r.epochs, test::nagoyaPair().rover);
  EXPECT_EQ(dc, 0.0);  // untouched
  EXPECT_EQ(dp, 0.0);
}

TEST(ClockJumpRepair, CodeAndPhaseJumpsRepaired) {
  const auto& orig = test::nagoyaPair().rover;
  ASSERT_GT(orig.size(), 200u);
  const GlonassChannels ch = channels();
  Repaired r;
  r.epochs = jumped(orig, ch, 100, +1, 150, -2);
  repairAll(r, ch);
  EXPECT_EQ(r.repair.jumps(), 2);
  EXPECT_EQ(r.repair.codeOffsetMs(), 1);
  EXPECT_EQ(r.repair.phaseOffsetMs(), -2);
  ASSERT_EQ(r.repair.warnings().size(), 2u);
  EXPECT_NE(r.repair.warnings()[0].find("+1 ms in the pseudoranges"), std::string::npos) << r.repair.warnings()[0];
  EXPECT_NE(r.repair.warnings()[0].find(std::to_string(static_cast<int>(std::lround(orig[100].time.tow())))),
            std::string::npos)
      << r.repair.warnings()[0];
  EXPECT_NE(r.repair.warnings()[1].find("-2 ms in the carrier phases"), std::string::npos) << r.repair.warnings()[1];
  const auto [dc, dp] = largestDifference(r.epochs, orig);
  EXPECT_LT(dc, 1e-6);  // metres: the recorded values again (rounding only)
  EXPECT_LT(dp, 1e-6);
}

TEST(ClockJumpRepair, BothTogetherAndSppUnchanged) {
  const auto& d = test::nagoyaPair();
  const GlonassChannels ch = channels();
  Repaired r;
  r.epochs = jumped(d.rover, ch, 60, -1, 60, -1);  // code and phase together, as a u-blox jumps
  repairAll(r, ch);
  EXPECT_EQ(r.repair.jumps(), 1);
  EXPECT_EQ(r.repair.warnings().size(), 2u);
  SppSolver a(d.nav), b(d.nav);
  a.setGlonassChannels(ch);
  b.setGlonassChannels(ch);
  double worst = 0.0;
  for (std::size_t i = 0; i < d.rover.size(); i += 7) {
    const SppSolution sa = a.solve(d.rover[i]), sb = b.solve(r.epochs[i]);
    ASSERT_EQ(sa.valid(), sb.valid());
    if (sa.valid()) worst = std::max(worst, (sa.position - sb.position).norm());
  }
  EXPECT_LT(worst, 1e-4);
}
