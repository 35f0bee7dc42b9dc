// Sun position, yaw-steering attitude and satellite antenna offsets (ANTEX) on precise products:
// the Sun against almanac facts (solstice declination, equinox, a published sidereal time), the
// attitude axes against their definition, and a centre-of-mass SP3 made from broadcast (antenna
// phase centre) orbits that the store turns back into the broadcast positions.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include <Eigen/Geometry>

#include "gvins/base/constants.hpp"
#include "gvins/ephemeris/antex.hpp"
#include "gvins/ephemeris/broadcast_sp3.hpp"
#include "gvins/ephemeris/ephemeris_store.hpp"
#include "gvins/ephemeris/precise_ephemeris.hpp"
#include "gvins/ephemeris/rinex_nav.hpp"
#include "gvins/ephemeris/satellite_antenna.hpp"
#include "gvins/ephemeris/sun_position.hpp"
#include "nagoya_recording.hpp"

using namespace gvins;

namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;
constexpr double kAu = 1.495978707e11;  // m (IAU 2012)

double declinationDeg(const Eigen::Vector3d& r) { return std::asin(r.z() / r.norm()) / kDeg; }

}  // namespace

// Greenwich mean sidereal time: Vallado, "Fundamentals of Astrodynamics and Applications",
// Example 3-5: 1992-08-20 12:14 UT1 -> 152.578787810 deg (UT1 taken as UTC here, as the
// function does).
TEST(SunPosition, SiderealTimeOfAPublishedExample) {
  EXPECT_NEAR(greenwichMeanSiderealTime(utcToGpst({1992, 8, 20, 12, 14, 0.0})) / kDeg, 152.578787810, 1e-6);
}

// June solstice 2024-06-20 20:51 UTC: declination = obliquity (23.4393 deg), the Sun ~1.0163 AU
// away, and overhead at about 132.4 deg W (apparent noon: 12 h - 20.85 h + 1.5 min equation of
// time, times 15 deg/h). March equinox 2024-03-20 03:06 UTC: declination 0 (it moves 0.017 deg/h).
TEST(SunPosition, SolsticeAndEquinox) {
  const Eigen::Vector3d s = sunPositionEcef(utcToGpst({2024, 6, 20, 20, 51, 0.0}));
  EXPECT_NEAR(declinationDeg(s), 23.4393, 0.02);
  EXPECT_NEAR(s.norm() / kAu, 1.0163, 0.0005);
  EXPECT_NEAR(std::atan2(s.y(), s.x()) / kDeg, -132.4, 0.3);
  const Eigen::Vector3d e = sunPositionEcef(utcToGpst({2024, 3, 20, 3, 6, 0.0}));
  EXPECT_NEAR(declinationDeg(e), 0.0, 0.03);
  EXPECT_NEAR(e.norm() / kAu, 0.996, 0.001);
  // Twelve hours later the Sun stands over the opposite meridian (to the equation of time's
  // change, seconds).
  const Eigen::Vector3d e12 = sunPositionEcef(utcToGpst({2024, 3, 20, 15, 6, 0.0}));
  double dl = (std::atan2(e12.y(), e12.x()) - std::atan2(e.y(), e.x())) / kDeg;
  dl = std::remainder(dl, 360.0);
  EXPECT_NEAR(std::abs(dl), 180.0, 0.2);
}

// Yaw steering: z to the Earth's centre, y perpendicular to the Sun direction, x on the Sun's
// side, a proper rotation.
TEST(SatelliteAttitude, YawSteeringAxesFollowTheirDefinition) {
  const Eigen::Vector3d sun = sunPositionEcef(utcToGpst({2024, 6, 24, 8, 0, 0.0}));
  for (const Eigen::Vector3d& pos : {Eigen::Vector3d(15e6, -10e6, 18e6), Eigen::Vector3d(-26e6, 2e6, -1e6),
                                     Eigen::Vector3d(5e6, 25e6, 7e6)}) {
    const Eigen::Matrix3d R = yawSteeringAxes(pos, sun);
    EXPECT_NEAR((R.transpose() * R - Eigen::Matrix3d::Identity()).norm(), 0.0, 1e-12);
    EXPECT_NEAR(R.determinant(), 1.0, 1e-12);
    EXPECT_NEAR(R.col(2).dot(-pos.normalized()), 1.0, 1e-12);
    const Eigen::Vector3d toSun = (sun - pos).normalized();
    EXPECT_NEAR(R.col(1).dot(toSun), 0.0, 1e-12);
    EXPECT_GT(R.col(0).dot(toSun), 0.0);
  }
}

namespace {

/// A satellite antenna entry with L1/L2 (or E1/E5a) offsets in the body frame.
AntexAntenna satelliteAntenna(SatId sat, char b1, char b2, const Eigen::Vector3d& pco1, const Eigen::Vector3d& pco2) {
  AntexAntenna a;
  a.type = "TEST BLOCK";
  a.serial = sat.str();
  a.satellite = sat;
  a.zen1 = 0.0;
  a.zen2 = 14.0;
  a.dzen = 1.0;
  for (auto [b, p] : {std::pair<char, Eigen::Vector3d>{b1, pco1}, std::pair<char, Eigen::Vector3d>{b2, pco2}}) {
    AntexFrequency f;
    f.system = sat.system;
    f.band = b;
    f.offset = p;
    f.noAzimuth.assign(15, 0.0);
    a.frequencies.push_back(f);
  }
  return a;
}

}  // namespace

// Ionosphere-free offset: a1 PCO(f1) + a2 PCO(f2) with GPS L1/L2 a1 = 2.5457, a2 = -1.5457.
TEST(SatelliteAntenna, IonosphereFreeOffsetOfTheReferencePair) {
  const SatId g = SatId::parse("G05").value();
  const AntexAntenna a = satelliteAntenna(g, '1', '2', {0.10, 0.0, 1.20}, {0.12, 0.0, 1.00});
  const auto o = ionosphereFreeOffset(a, System::Gps);
  ASSERT_TRUE(o);
  const double a1 = 1575.42 * 1575.42 / (1575.42 * 1575.42 - 1227.60 * 1227.60);
  EXPECT_NEAR(a1, 2.5457, 1e-4);
  EXPECT_NEAR(o->x(), a1 * 0.10 + (1 - a1) * 0.12, 1e-12);
  EXPECT_NEAR(o->z(), a1 * 1.20 + (1 - a1) * 1.00, 1e-12);
  EXPECT_FALSE(ionosphereFreeOffset(a, System::Galileo));
  // Only L1: its offset.
  AntexAntenna one = a;
  one.frequencies.pop_back();
  EXPECT_NEAR((*ionosphereFreeOffset(one, System::Gps) - Eigen::Vector3d(0.10, 0.0, 1.20)).norm(), 0.0, 1e-15);
}

// Centre-of-mass products: the broadcast orbits (antenna phase centre) of a GPS and a Galileo
// satellite minus the yaw-steered offset, every 300 s. With the ANTEX entries the store gives the
// phase-centre positions back (against the same nodes without the offset, interpolated alike);
// without, it is off by the offset (~1.5 m); a satellite of the products without an ANTEX entry
// falls back to its broadcast record.
TEST(SatelliteAntenna, CentreOfMassProductsComeBackToThePhaseCentre) {
  EphemerisStore nav, plain;
  nav.add(readRinexNav(std::string(GVINS_TEST_DATA) + "/gnss/nagoya_static_2024/base.nav.gz"));
  plain = nav;
  const SatId g = SatId::parse("G05").value(), e = SatId::parse("E04").value(), other = SatId::parse("G13").value();
  const GpsTime t0 = gvins::test::nagoyaTime(8, 20);
  auto antex = std::make_shared<AntexData>();
  antex->antennas.push_back(satelliteAntenna(g, '1', '2', {0.279, 0.0, 1.5}, {0.279, 0.0, 1.5}));
  antex->antennas.push_back(satelliteAntenna(e, '1', '5', {0.15, 0.01, 0.8}, {0.15, 0.01, 0.7}));
  Sp3Data d = broadcastSp3(nav, t0 - 1800.0, t0 + 3600.0, 300.0, {g, e, other});
  // The reference: the phase-centre nodes themselves, interpolated the same way (the broadcast
  // records differ from their interpolation by up to 2 cm where Galileo switches records).
  auto apc = std::make_shared<PreciseEphemeris>();
  apc->add(d);
  plain.setPrecise(apc);
  auto broadcastStateNoPrecise = [&](SatId s, const GpsTime& t) { return plain.satelliteState(s, t); };
  for (Sp3Epoch& ep : d.epochs) {
    for (Sp3Record& r : ep.records) {
      if (!r.position.allFinite()) continue;  // outside the broadcast coverage
      if (r.sat == other) continue;
      // Solve com = apc - R(com) pco by fixed point (R changes by 1e-7 rad per metre).
      Eigen::Vector3d com = r.position;
      for (int i = 0; i < 3; ++i) com = r.position - *satelliteAntennaOffset(*antex, r.sat, ep.time, com);
      r.position = com;
    }
  }
  auto precise = std::make_shared<PreciseEphemeris>();
  precise->add(d);
  nav.setPrecise(precise);
  double without = 0.0;
  for (double dt : {0.0, 450.0, 1234.5}) {
    for (SatId s : {g, e}) {
      const auto st = nav.satelliteState(s, t0 + dt);
      ASSERT_TRUE(st && st->precise);
      without = std::max(without, (st->position - broadcastStateNoPrecise(s, t0 + dt)->position).norm());
    }
  }
  EXPECT_GT(without, 0.8);
  const std::uint64_t rev = nav.revision();
  nav.setSatelliteAntennas(antex);
  EXPECT_NE(nav.revision(), rev);
  double with = 0.0;
  for (double dt : {0.0, 450.0, 1234.5}) {
    for (SatId s : {g, e}) {
      const auto st = nav.satelliteState(s, t0 + dt);
      ASSERT_TRUE(st && st->precise);
      with = std::max(with, (st->position - broadcastStateNoPrecise(s, t0 + dt)->position).norm());
    }
    const auto o = nav.satelliteState(other, t0 + dt);
    ASSERT_TRUE(o);
    EXPECT_FALSE(o->precise);  // in the products, not in the ANTEX file: broadcast
  }
  std::printf("centre-of-mass products vs broadcast: %.3f m without ANTEX, %.4f m with\n", without, with);
  EXPECT_LT(with, 0.001);
}
