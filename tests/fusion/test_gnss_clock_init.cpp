// Clock RANSAC initialisation: recovers simulated clocks (three constellations + drift) from
// noisy rows with injected gross outliers; plain least squares over all rows would not.
#include <gtest/gtest.h>

#include <random>

#include "gvins/fusion/gnss_clock_init.hpp"

namespace gvins::fusion {
namespace {

TEST(GnssClockInit, RecoversClocksWithOutliers) {
  const std::vector<double> truth = {-45123.4, -45090.1, -44980.7, 31.25};  // m, m, m, m/s
  std::mt19937_64 rng(11);
  std::normal_distribution<double> code(0.0, 1.0), dopp(0.0, 0.05);
  std::uniform_real_distribution<double> nlos(20.0, 80.0);
  std::vector<ClockRow> rows;
  std::vector<bool> bad;
  for (int sys = 0; sys < 3; ++sys) {
    for (int i = 0; i < 7; ++i) {
      const bool outlier = i < 2;  // 2 of 7 per system: NLOS-like positive biases
      rows.push_back({sys, truth[static_cast<std::size_t>(sys)] + code(rng) + (outlier ? nlos(rng) : 0.0), 5.0});
      bad.push_back(outlier);
      rows.push_back({3, truth[3] + dopp(rng) + (i == 0 ? 3.0 : 0.0), 0.5});
      bad.push_back(i == 0);
    }
  }
  const ClockInitResult r = initializeClocksRansac(rows, 4);
  ASSERT_TRUE(r.ok);
  for (std::size_t u = 0; u < 3; ++u) {
    EXPECT_NEAR(r.x[u], truth[u], 1.5) << u;  // 5 inliers of σ 1 m: mean within ~3σ/√5
    EXPECT_EQ(r.inliers[u], 5);
  }
  EXPECT_NEAR(r.x[3], truth[3], 0.08);
  EXPECT_EQ(r.inliers[3], 18);
  for (std::size_t i = 0; i < rows.size(); ++i) EXPECT_EQ(r.inlier[i], !bad[i]) << i;
  // The mean of all rows is biased by the outliers by far more than the tolerance above.
  double mean0 = 0.0;
  int n0 = 0;
  for (const ClockRow& c : rows) {
    if (c.unknown == 0) {
      mean0 += c.value;
      ++n0;
    }
  }
  EXPECT_GT(std::abs(mean0 / n0 - truth[0]), 5.0);
}

TEST(GnssClockInit, MissingUnknownIsReported) {
  const std::vector<ClockRow> rows = {{0, 10.0, 5.0}, {0, 11.0, 5.0}};
  const ClockInitResult r = initializeClocksRansac(rows, 2);
  EXPECT_FALSE(r.ok);
  EXPECT_NEAR(r.x[0], 10.5, 1e-12);
  EXPECT_EQ(r.inliers[1], 0);
}

}  // namespace
}  // namespace gvins::fusion
