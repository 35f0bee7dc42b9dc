// The base clock of the dpsr rows (gnss_base_clock.hpp) against a simulated base: code residuals
// OMC = c·dt_b(t) + a per-signal offset (ionosphere and the like, larger at low elevation) + noise,
// with satellites joining and leaving. The estimate must follow c·dt_b with a constant offset
// through every change of the set; the plain mean of the residuals jumps at each change.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "gvins/fusion/gnss_base_clock.hpp"

namespace gvins::fusion {
namespace {

TEST(GnssBaseClock, FollowsTheClockThroughSatelliteChanges) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> noise(0.0, 0.02);  // smoothed base code, m
  // Per-signal offsets of two systems (m): ten signals each, the last two of system 0 join at
  // epoch 100 and those of system 1 leave at epoch 200 (a satellite crossing the mask).
  std::vector<double> offset;
  std::uniform_real_distribution<double> u(2.0, 20.0);
  for (int i = 0; i < 20; ++i) offset.push_back(u(rng));
  offset[8] = offset[9] = 25.0;    // the joining satellite, low: 25 m against at most 20
  offset[18] = offset[19] = 24.0;  // the leaving one
  GnssBaseClock clock;
  std::vector<double> first(2, std::nan("")), worstStep(2, 0.0), worstMeanStep(2, 0.0), lastMean(2, std::nan(""));
  std::vector<double> lastOffset(2, std::nan(""));
  for (int k = 0; k < 300; ++k) {
    const double t = 0.2 * k;
    const double trueClock = 4.0e4 + 30.0 * t + 0.5 * std::sin(0.3 * t);  // m: drift and wander
    std::vector<GnssBaseClock::Residual> r;
    std::vector<double> sum(2, 0.0), n(2, 0.0);
    for (int i = 0; i < 20; ++i) {
      const int s = i / 10;
      if (s == 0 && i >= 8 && k < 100) continue;
      if (s == 1 && i >= 18 && k >= 200) continue;
      const double omc = trueClock + offset[static_cast<std::size_t>(i)] + 0.001 * t + noise(rng);
      r.push_back({s, 1000 + i, omc});
      sum[static_cast<std::size_t>(s)] += omc;
      n[static_cast<std::size_t>(s)] += 1.0;
    }
    const std::vector<double> cb = clock.update(r, 2);
    ASSERT_EQ(cb.size(), 2u);
    for (std::size_t s = 0; s < 2; ++s) {
      const double off = cb[s] - trueClock, mean = sum[s] / n[s] - trueClock;
      if (k > 0) {
        worstStep[s] = std::max(worstStep[s], std::abs(off - lastOffset[s]));
        worstMeanStep[s] = std::max(worstMeanStep[s], std::abs(mean - lastMean[s]));
      }
      if (k == 0) first[s] = off;
      lastOffset[s] = off;
      lastMean[s] = mean;
    }
  }
  for (std::size_t s = 0; s < 2; ++s) {
    // Epoch-to-epoch change of (estimate − clock): the noise of the common signals' mean change,
    // σ = 0.02 √2 / √8 = 0.01 m, and the 0.2 mm drift of the offsets; 0.05 m is 5σ.
    EXPECT_LT(worstStep[s], 0.05) << s;
    // Over the whole run it stays near its first value (random walk of 300 such steps: σ 0.17 m).
    EXPECT_LT(std::abs(lastOffset[s] - first[s]), 0.6) << s;
    // The plain mean jumps at the change of the set by (25 − mean)·2/10 > 1 m.
    EXPECT_GT(worstMeanStep[s], 1.0) << s;
  }
}

TEST(GnssBaseClock, StartsFromTheMeanAndAfterReset) {
  GnssBaseClock clock;
  std::vector<double> cb = clock.update({{0, 1, 10.0}, {0, 2, 14.0}}, 2);
  EXPECT_DOUBLE_EQ(cb[0], 12.0);
  EXPECT_TRUE(std::isnan(cb[1]));  // no residuals of system 1
  cb = clock.update({{0, 2, 15.0}, {0, 3, 40.0}}, 2);  // signal 2 common: +1 m
  EXPECT_DOUBLE_EQ(cb[0], 13.0);
  clock.reset();
  cb = clock.update({{0, 2, 15.0}, {0, 3, 40.0}}, 2);
  EXPECT_DOUBLE_EQ(cb[0], 27.5);
}

}  // namespace
}  // namespace gvins::fusion
