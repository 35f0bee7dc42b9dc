// Orbit differences in the radial/along/cross frame and the SISRE weights per orbit type.
#include <gtest/gtest.h>

#include <cmath>

#include "gvins/base/constants.hpp"
#include "gvins/ephemeris/orbit_comparison.hpp"

using namespace gvins;

TEST(OrbitComparison, FrameAndSisreWeights) {
  // A satellite on the x axis moving along +y: radial = x, along = y, cross = z.
  SatelliteState ref;
  ref.position = Eigen::Vector3d(26.6e6, 0, 0);
  ref.velocity = Eigen::Vector3d(0, 3.87e3, 0);
  SatelliteState s = ref;
  s.position += Eigen::Vector3d(0.1, -2.0, 0.7);
  s.clockBias += 0.3 / constants::kSpeedOfLight;
  const OrbitDifference d = orbitDifference(s, ref);
  EXPECT_NEAR(d.radial, 0.1, 1e-8);
  EXPECT_NEAR(d.along, -2.0, 1e-8);
  EXPECT_NEAR(d.cross, 0.7, 1e-8);
  EXPECT_NEAR(d.clock, 0.3, 1e-8);
  // Montenbruck et al. 2018, Table 2: GPS 0.98 and 1/49; BeiDou GEO 0.99 and 1/126.
  const SatId g = *SatId::parse("G01"), cGeo = *SatId::parse("C01"), cMeo = *SatId::parse("C20");
  EXPECT_NEAR(sisre(g, d), std::sqrt(std::pow(0.98 * 0.1 - 0.3, 2) + (4.0 + 0.49) / 49.0), 1e-8);
  EXPECT_NEAR(sisre(cGeo, d), std::sqrt(std::pow(0.99 * 0.1 - 0.3, 2) + (4.0 + 0.49) / 126.0), 1e-8);
  EXPECT_NEAR(sisre(cMeo, d, 0.3), std::sqrt(std::pow(0.98 * 0.1, 2) + (4.0 + 0.49) / 54.0), 1e-8);
  // A radial error and an equal clock error cancel for the user but the along/cross part stays.
  OrbitDifference rc;
  rc.radial = 1.0;
  rc.clock = 0.98;
  EXPECT_NEAR(sisre(g, rc), 0.0, 1e-8);
}
