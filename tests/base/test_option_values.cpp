// Command-line option values (base/option_values.hpp): whole finite numbers in range, X,Y,Z
// triples, and station positions near the Earth's surface, with messages naming the option.
#include <gtest/gtest.h>

#include <string>

#include "gvins/base/geodetic.hpp"
#include "gvins/base/option_values.hpp"

using namespace gvins;

namespace {
std::string errorOf(auto&& f) {
  try {
    f();
  } catch (const OptionError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(OptionValues, NumbersMustBeWholeFiniteAndInRange) {
  EXPECT_EQ(optionNumber("--start", "12.5", 0.0, 100.0), 12.5);
  EXPECT_EQ(optionNumber("--start", "+3", 0.0, 100.0), 3.0);
  EXPECT_EQ(optionNumber("--start", "1e2", 0.0, 100.0), 100.0);
  for (const char* bad : {"", "nan", "NaN", "inf", "-inf", "1e999", "5s", " 5", "0x10", "1,5", "--"}) {
    const std::string e = errorOf([&] { optionNumber("--start", bad, 0.0, 100.0); });
    EXPECT_EQ(e.rfind("--start: ", 0), 0u) << "'" << bad << "' -> '" << e << "'";
  }
  EXPECT_EQ(errorOf([] { optionNumber("--duration", "-1", 0.0, 1e7, "s"); }), "--duration: -1 is outside [0, 10000000] s");
  EXPECT_NE(errorOf([] { optionNumber("--start", std::string(200, '9'), 0.0, 1e7); }), "");
}

TEST(OptionValues, VectorsNeedThreeNumbers) {
  EXPECT_EQ(optionVector3("--lever-arm", "0.1,-0.2,0.3", -10, 10), Eigen::Vector3d(0.1, -0.2, 0.3));
  EXPECT_EQ(optionVector3("--lever-arm", "0.1, -0.2, 0.3", -10, 10), Eigen::Vector3d(0.1, -0.2, 0.3));
  EXPECT_EQ(optionVector3("--lever-arm", "0.1 -0.2 0.3", -10, 10), Eigen::Vector3d(0.1, -0.2, 0.3));
  for (const char* bad : {"1,2", "1,2,3,4", "1,,2,3", ",1,2", "1,2,nan", "1e6,0,0", "a,b,c"}) {
    EXPECT_NE(errorOf([&] { optionVector3("--lever-arm", bad, -10, 10); }), "") << bad;
  }
}

TEST(OptionValues, StationsLieNearTheEarthsSurface) {
  // The Nagoya base of tests/data (base_position.txt) passes both ways and gives the same point.
  const Eigen::Vector3d llh = optionStationLlh("--base-llh", "35.134707705,136.977577939,104.853");
  const Eigen::Vector3d expect = geodeticToEcef(geodeticFromDegrees(35.134707705, 136.977577939, 104.853));
  EXPECT_LT((llh - expect).norm(), 1e-6);
  char xyz[96];
  std::snprintf(xyz, sizeof xyz, "%.4f,%.4f,%.4f", expect.x(), expect.y(), expect.z());
  EXPECT_LT((optionStationEcef("--base-xyz", xyz) - expect).norm(), 1e-3);
  // The geocentre, a point 11,000 km up and one 20 km above the equator are mistakes.
  for (const char* bad : {"0,0,0", "1e7,1e7,1e7", "6398137,0,0"}) {
    const std::string e = errorOf([&] { optionStationEcef("--base-xyz", bad); });
    EXPECT_NE(e.find("from the Earth's surface"), std::string::npos) << bad << ": " << e;
  }
  EXPECT_EQ(optionStationEcef("--base-xyz", "6378137,0,0").x(), 6378137.0);
  for (const char* bad : {"35,137,1e9", "95,137,0", "35,400,0", "35,137"})
    EXPECT_NE(errorOf([&] { optionStationLlh("--base-llh", bad); }), "") << bad;
}
