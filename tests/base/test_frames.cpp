#include <gtest/gtest.h>

#include <cmath>

#include <Eigen/LU>

#include "gvins/base/constants.hpp"
#include "gvins/base/geodetic.hpp"
#include "gvins/base/local_frame.hpp"

using namespace gvins;

TEST(Frames, GeodeticOfKnownStation) {
  // Kamakura truth (GSI F5, ITRF2014) and the nagoya base position from the data README.
  const Eigen::Vector3d kamakura(-3962108.673, 3381309.574, 3668678.638);
  const Geodetic g = ecefToGeodetic(kamakura);
  const Eigen::Vector3d back = geodeticToEcef(g);
  EXPECT_LT((back - kamakura).norm(), 1e-6);
  EXPECT_NEAR(g.lat * constants::kRadToDeg, 35.3, 0.1);
  EXPECT_NEAR(g.lon * constants::kRadToDeg, 139.5, 0.1);

  const Geodetic nagoya = geodeticFromDegrees(35.134707705, 136.977577939, 104.853);
  const Geodetic n2 = ecefToGeodetic(geodeticToEcef(nagoya));
  EXPECT_NEAR(n2.lat, nagoya.lat, 1e-13);
  EXPECT_NEAR(n2.lon, nagoya.lon, 1e-13);
  EXPECT_NEAR(n2.height, nagoya.height, 1e-6);
}

TEST(Frames, RoundTripOverTheGlobeAndAltitudes) {
  for (double lat = -89.5; lat <= 89.5; lat += 12.7) {
    for (double lon = -180.0; lon < 180.0; lon += 33.3) {
      for (double h : {-100.0, 0.0, 50.0, 20000e3}) {
        const Geodetic g = geodeticFromDegrees(lat, lon, h);
        const Geodetic b = ecefToGeodetic(geodeticToEcef(g));
        EXPECT_NEAR(b.lat, g.lat, 1e-12);
        EXPECT_NEAR(b.lon, g.lon, 1e-12);
        EXPECT_NEAR(b.height, g.height, 1e-6);
      }
    }
  }
  // Poles.
  const Geodetic np = ecefToGeodetic(Eigen::Vector3d(0, 0, 6356752.314245));
  EXPECT_NEAR(np.lat, M_PI / 2, 1e-12);
  EXPECT_NEAR(np.height, 0.0, 1e-6);
}

TEST(Frames, EnuNedAndAzimuthElevation) {
  const Geodetic g = geodeticFromDegrees(35.0, 137.0, 100.0);
  const Eigen::Vector3d p = geodeticToEcef(g);
  const Eigen::Matrix3d r = ecefToEnuRotation(g.lat, g.lon);
  EXPECT_LT((r * r.transpose() - Eigen::Matrix3d::Identity()).norm(), 1e-15);
  EXPECT_NEAR(r.determinant(), 1.0, 1e-15);
  // Up is the ellipsoid normal: moving 10 m up in height is +10 in U.
  const Geodetic gUp{g.lat, g.lon, g.height + 10.0};
  const Eigen::Vector3d enu = ecefToEnu(geodeticToEcef(gUp), p);
  EXPECT_NEAR(enu.z(), 10.0, 1e-8);
  EXPECT_NEAR(enu.head<2>().norm(), 0.0, 1e-8);
  EXPECT_LT((enuToEcef(Eigen::Vector3d(3, -4, 5), p) - p - r.transpose() * Eigen::Vector3d(3, -4, 5)).norm(), 1e-9);
  const Eigen::Matrix3d ned = ecefToNedRotation(g.lat, g.lon);
  EXPECT_LT((ned.row(0) - r.row(1)).norm(), 1e-15);
  EXPECT_LT((ned.row(2) + r.row(2)).norm(), 1e-15);

  // A satellite due east at 30 degrees elevation (20000 km away).
  const double el = 30.0 * constants::kDegToRad;
  const Eigen::Vector3d losEnu(std::cos(el), 0.0, std::sin(el));
  const Eigen::Vector3d sat = p + r.transpose() * losEnu * 2.0e7;
  const AzEl ae = azimuthElevation(p, sat);
  EXPECT_NEAR(ae.azimuth, M_PI / 2, 1e-12);
  EXPECT_NEAR(ae.elevation, el, 1e-12);
  // Unknown receiver position: elevation 90 deg so nothing is masked.
  EXPECT_DOUBLE_EQ(azimuthElevation(Eigen::Vector3d::Zero(), sat).elevation, M_PI / 2);
}
