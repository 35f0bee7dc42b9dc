// Phase wind-up (gvins/gnss/phase_windup.hpp, Wu et al. 1993) against its geometric meaning: a
// receiver antenna turned about its boresight by θ under a satellite at the zenith winds the
// phase up by exactly θ/2π cycles, and so does every other satellite (yaw is common mode); a tilt
// winds satellites up differently; whole turns accumulate across the ±half-cycle boundary.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include <Eigen/Geometry>

#include "gvins/base/geodetic.hpp"
#include "gvins/ephemeris/satellite_antenna.hpp"
#include "gvins/gnss/phase_windup.hpp"

namespace gvins {
namespace {

const double kTwoPi = 2.0 * std::acos(-1.0);

struct Geometry {
  Eigen::Vector3d receiver, satellite;
  Eigen::Matrix3d enu;      // columns east, north, up at the receiver
  Eigen::Matrix3d satAxes;  // yaw steering, Sun somewhere off the orbit plane
};

Geometry geometry(double elevationDeg, double azimuthDeg) {
  Geometry g;
  const Geodetic p = geodeticFromDegrees(35.1347, 136.9776, 105.0);
  g.receiver = geodeticToEcef(p);
  const double lat = p.lat, lon = p.lon;
  const Eigen::Vector3d e(-std::sin(lon), std::cos(lon), 0.0);
  const Eigen::Vector3d n(-std::sin(lat) * std::cos(lon), -std::sin(lat) * std::sin(lon), std::cos(lat));
  const Eigen::Vector3d u(std::cos(lat) * std::cos(lon), std::cos(lat) * std::sin(lon), std::sin(lat));
  g.enu.col(0) = e;
  g.enu.col(1) = n;
  g.enu.col(2) = u;
  const double el = elevationDeg * kTwoPi / 360.0, az = azimuthDeg * kTwoPi / 360.0;
  const Eigen::Vector3d los = std::cos(el) * std::sin(az) * e + std::cos(el) * std::cos(az) * n + std::sin(el) * u;
  g.satellite = g.receiver + 2.2e7 * los;
  g.satAxes = yawSteeringAxes(g.satellite, Eigen::Vector3d(1.2e11, -0.7e11, 0.3e11));
  return g;
}

/// Receiver antenna axes: x forward (heading h from north, clockwise), y left, z up.
Eigen::Matrix3d vehicleAxes(const Geometry& g, double headingRad) {
  return g.enu * Eigen::AngleAxisd(-headingRad, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
         Eigen::AngleAxisd(kTwoPi / 4.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();  // x north at h = 0
}

TEST(PhaseWindup, TurningUnderTheZenithSatelliteIsTheTurnAngle) {
  const Geometry g = geometry(90.0, 0.0);
  const double w0 = phaseWindupCycles(g.satellite, g.receiver, g.satAxes, vehicleAxes(g, 0.0));
  EXPECT_LE(std::abs(w0), 0.5);
  double prev = w0;
  for (int i = 1; i <= 24; ++i) {  // two full turns in 30° steps
    const double h = i * kTwoPi / 12.0;
    const double w = phaseWindupCycles(g.satellite, g.receiver, g.satAxes, vehicleAxes(g, h), prev);
    EXPECT_NEAR(std::abs(w - w0), i / 12.0, 1e-9) << "step " << i;
    prev = w;
  }
  // Clockwise turns (seen from above) give one sign; the way back undoes them.
  EXPECT_NEAR(std::abs(prev - w0), 2.0, 1e-9);
  for (int i = 23; i >= 0; --i)
    prev = phaseWindupCycles(g.satellite, g.receiver, g.satAxes, vehicleAxes(g, i * kTwoPi / 12.0), prev);
  EXPECT_NEAR(prev, w0, 1e-9);
}

// A turn about the boresight rotates the effective dipole D_r rigidly about every line of sight
// (D_r' = cos θ D_r − sin θ k × D_r): the same wind-up for every satellite, whatever its elevation,
// which the receiver clock absorbs. Tilts are what differ between satellites.
TEST(PhaseWindup, YawIsCommonToAllSatellitesTiltIsNot) {
  const Geometry zen = geometry(90.0, 0.0);
  const Geometry low = geometry(15.0, 60.0);
  const double z0 = phaseWindupCycles(zen.satellite, zen.receiver, zen.satAxes, vehicleAxes(zen, 0.0));
  const double l0 = phaseWindupCycles(low.satellite, low.receiver, low.satAxes, vehicleAxes(low, 0.0));
  double zp = z0, lp = l0;
  for (int i = 1; i <= 72; ++i) {  // one turn in 5° steps
    const double h = i * kTwoPi / 72.0;
    zp = phaseWindupCycles(zen.satellite, zen.receiver, zen.satAxes, vehicleAxes(zen, h), zp);
    lp = phaseWindupCycles(low.satellite, low.receiver, low.satAxes, vehicleAxes(low, h), lp);
    EXPECT_NEAR(lp - l0, zp - z0, 1e-9) << "step " << i;
  }
  EXPECT_NEAR(std::abs(lp - l0), 1.0, 1e-9);
  // A 20° roll (about the vehicle's x axis, north here): the zenith satellite sees 0, the low
  // one in the east (azimuth 60°) a part of a cycle.
  const Eigen::Matrix3d roll = Eigen::AngleAxisd(20.0 * kTwoPi / 360.0, Eigen::Vector3d::UnitX()).toRotationMatrix();
  const double zr = phaseWindupCycles(zen.satellite, zen.receiver, zen.satAxes, vehicleAxes(zen, 0.0) * roll, z0);
  const double lr = phaseWindupCycles(low.satellite, low.receiver, low.satAxes, vehicleAxes(low, 0.0) * roll, l0);
  std::fprintf(stderr, "20 deg roll: zenith satellite %.4f cycles, 15 deg elevation %.4f cycles\n", zr - z0, lr - l0);
  EXPECT_NEAR(zr, z0, 1e-9);
  EXPECT_GT(std::abs(lr - l0), 0.005);
  EXPECT_LT(std::abs(lr - l0), 0.06);  // 20° = 0.056 cycles of rotation at most
}

TEST(PhaseWindup, LevelAntennaAxesAreNorthWestUp) {
  const Geometry g = geometry(45.0, 0.0);
  const Geodetic p = geodeticFromDegrees(35.1347, 136.9776, 105.0);
  const Eigen::Matrix3d a = levelAntennaAxes(p.lat, p.lon);
  EXPECT_NEAR((a.col(0) - g.enu.col(1)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((a.col(1) + g.enu.col(0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((a.col(2) - g.enu.col(2)).norm(), 0.0, 1e-12);
  EXPECT_NEAR(a.determinant(), 1.0, 1e-12);
}

TEST(PhaseWindup, ContinuesPreviousValueAcrossWholeCycles) {
  const Geometry g = geometry(40.0, 200.0);
  const Eigen::Matrix3d axes = vehicleAxes(g, 1.0);
  const double w = phaseWindupCycles(g.satellite, g.receiver, g.satAxes, axes);
  EXPECT_NEAR(phaseWindupCycles(g.satellite, g.receiver, g.satAxes, axes, w + 7.0), w + 7.0, 1e-12);
  EXPECT_NEAR(phaseWindupCycles(g.satellite, g.receiver, g.satAxes, axes, w - 3.4), w - 3.0, 1e-12);
}

}  // namespace
}  // namespace gvins
