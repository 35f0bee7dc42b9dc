// Satellite states: analytic velocity and clock drift against central differences of our own
// positions and clocks, the relativistic term against orbit geometry, GLONASS integration
// convergence, group delays against a simulated hardware-delay truth.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <utility>
#include <string>
#include <vector>

#include "gvins/base/constants.hpp"
#include "gvins/ephemeris/rinex_nav.hpp"
#include "gvins/ephemeris/satellite_state.hpp"

using namespace gvins;

namespace {

const std::string kData = GVINS_TEST_DATA;

std::vector<std::string> navFiles() {
  return {kData + "/gnss/nagoya_static_2024/base.nav.gz",
          kData + "/gnss/kamakura_static_2021/SEPT078M.21P.gz",
          kData + "/gnss/kamakura_static_2021/30340780.21q.gz",
          kData + "/gnss/geonet_0759_3040_2005/07590920.05n.gz",
          kData + "/gnss/brd400dlr_2022_rinex4/BRD400DLR_S_20222780000_extract.rnx.gz",
          kData + "/reference/rtklib-2.4.3/satpos/testglo_rinex211.gnav.gz"};
}

NavData allNav() {
  NavData all;
  for (const auto& f : navFiles()) mergeNavData(all, readRinexNav(f));
  return all;
}

}  // namespace

TEST(SatelliteState, KeplerVelocityAndDriftMatchCentralDifferences) {
  const NavData nav = allNav();
  const double h = 0.5;
  double maxDv = 0.0, maxDd = 0.0;
  int n = 0;
  int geo = 0;
  for (const auto& e : nav.kepler) {
    for (double dt : {-7000.0, -3600.0, -600.0, 0.0, 1234.5, 3600.0, 7000.0}) {
      const GpsTime t = e.toe + dt;
      const SatelliteState s = keplerSatelliteState(e, t);
      const SatelliteState a = keplerSatelliteState(e, t + h);
      const SatelliteState b = keplerSatelliteState(e, t - h);
      const Eigen::Vector3d vNum = (a.position - b.position) / (2 * h);
      const double dNum = (a.clockBias - b.clockBias) / (2 * h);
      maxDv = std::max(maxDv, (s.velocity - vNum).norm());
      maxDd = std::max(maxDd, std::fabs(s.clockDrift - dNum));
      ++n;
    }
    if (isBeiDouGeo(e.sat)) ++geo;
  }
  std::printf("Keplerian: %d states (%d BeiDou GEO records), max |v - central difference| %.2e m/s, "
              "max |drift - difference| %.2e s/s\n", n, geo, maxDv, maxDd);
  EXPECT_GT(n, 2000);
  EXPECT_GT(geo, 5);
  EXPECT_LT(maxDv, 1e-3);   // the requirement: 1 mm/s
  EXPECT_LT(maxDv, 2e-5);   // what the analytic derivative actually achieves
  EXPECT_LT(maxDd, 1e-15);
}

TEST(SatelliteState, GlonassVelocityMatchesCentralDifference) {
  const NavData nav = allNav();
  ASSERT_GE(nav.glonass.size(), 20u);
  const double h = 0.5;
  double maxDv = 0.0;
  for (const auto& g : nav.glonass) {
    for (double dt : {-1800.0, -900.0, -301.0, 0.0, 0.7, 455.0, 900.0, 1800.0}) {
      const GpsTime t = g.toe + dt;
      const SatelliteState s = glonassSatelliteState(g, t);
      const SatelliteState a = glonassSatelliteState(g, t + h);
      const SatelliteState b = glonassSatelliteState(g, t - h);
      maxDv = std::max(maxDv, (s.velocity - (a.position - b.position) / (2 * h)).norm());
      EXPECT_DOUBLE_EQ(s.clockDrift, g.gammaN);
      EXPECT_NEAR(s.clockBias, -g.tauN + g.gammaN * dt, 1e-18);
    }
  }
  std::printf("GLONASS: max |v - central difference| %.2e m/s\n", maxDv);
  EXPECT_LT(maxDv, 1e-3);
}

TEST(SatelliteState, GlonassIntegrationConverges) {
  // Halving steps: the default 30 s step is within 0.1 mm of a 1 s step over +-30 min; RTKLIB's
  // 60 s step is 1.3 mm off at 30 min from tb (part of the residual against RTKLIB's output).
  const NavData nav = allNav();
  double max30 = 0.0, max60 = 0.0, maxV = 0.0;
  for (const auto& g : nav.glonass) {
    for (double dt : {-1800.0, -900.0, 600.0, 1800.0}) {
      const GpsTime t = g.toe + dt;
      const SatelliteState fine = glonassSatelliteState(g, t, 1.0);
      max30 = std::max(max30, (glonassSatelliteState(g, t).position - fine.position).norm());
      max60 = std::max(max60, (glonassSatelliteState(g, t, 60.0).position - fine.position).norm());
      maxV = std::max(maxV, (glonassSatelliteState(g, t).velocity - fine.velocity).norm());
    }
  }
  std::printf("GLONASS RK4 vs 1 s steps over +-30 min: 30 s %.2e m, 60 s %.2e m, velocity %.2e m/s\n", max30,
              max60, maxV);
  EXPECT_LT(max30, 1e-4);
  EXPECT_LT(max60, 2e-3);
  EXPECT_LT(maxV, 1e-6);
}

TEST(SatelliteState, RelativisticTermMatchesOrbitGeometry) {
  // F e sqrt(A) sin(E) = -2 r.v / c^2 for a Keplerian orbit (IS-GPS-200N 20.3.3.3.3.1). The
  // broadcast harmonic corrections (Crs up to ~700 m for BeiDou IGSO/GEO) perturb r.v and make
  // the two differ by up to ~0.1 ns; the term itself reaches 20-50 ns, so a wrong constant, sign
  // or eccentric-anomaly rate would show at the 1 % level.
  const NavData nav = allNav();
  double maxDiff = 0.0;
  for (const auto& e : nav.kepler) {
    for (double dt : {-3600.0, 0.0, 2000.0}) {
      const GpsTime t = e.toe + dt;
      const SatelliteState s = keplerSatelliteState(e, t);
      const double tc = t - e.toc;
      const double rel = s.clockBias - (e.af0 + e.af1 * tc + e.af2 * tc * tc);
      const double geom = -2.0 * s.position.dot(s.velocity) / (constants::kSpeedOfLight * constants::kSpeedOfLight);
      maxDiff = std::max(maxDiff, std::fabs(rel - geom));
    }
  }
  std::printf("relativistic term vs -2 r.v/c^2: max difference %.3f ns\n", maxDiff * 1e9);
  EXPECT_LT(maxDiff, 0.2e-9);
}

TEST(SatelliteState, BeiDouGeoUsesTheRotatedFrame) {
  // C01 (GEO) from the RINEX 4 extract: about 42164 km from the centre, near the equator, slow in
  // ECEF (its 4.7 deg inclination allows up to ~250 m/s north-south), and its longitude drifts by
  // less than 0.2 deg in an hour. The same elements through the MEO/IGSO formula land > 1000 km
  // away (and the RTKLIB comparison checks the GEO states to the millimetre).
  const NavData nav = readRinexNav(kData + "/gnss/brd400dlr_2022_rinex4/BRD400DLR_S_20222780000_extract.rnx.gz");
  int n = 0;
  for (const auto& e : nav.kepler) {
    if (!(e.sat == SatId(System::BeiDou, 1))) continue;
    ++n;
    const SatelliteState s = keplerSatelliteState(e, e.toe);
    const SatelliteState later = keplerSatelliteState(e, e.toe + 3600.0);
    EXPECT_NEAR(s.position.norm(), 42164e3, 100e3);
    EXPECT_LT(std::fabs(s.position.z()), 0.1 * s.position.norm());
    EXPECT_LT(s.velocity.norm(), 300.0);
    const double lon0 = std::atan2(s.position.y(), s.position.x()) * constants::kRadToDeg;
    const double lon1 = std::atan2(later.position.y(), later.position.x()) * constants::kRadToDeg;
    EXPECT_LT(std::fabs(lon1 - lon0), 0.2);
    KeplerEphemeris asMeo = e;
    asMeo.sat = SatId(System::BeiDou, 30);
    EXPECT_GT((keplerSatelliteState(asMeo, e.toe).position - s.position).norm(), 1e6);
  }
  EXPECT_EQ(n, 2);
}

TEST(SatelliteState, CorruptRecordsGiveUnhealthyStatesNotNaNOrHangs) {
  KeplerEphemeris e;
  e.sat = SatId(System::Gps, 1);
  e.sqrtA = 0.0;
  EXPECT_FALSE(keplerSatelliteState(e, GpsTime::fromWeekTow(2000, 0)).healthy);
  e.sqrtA = 5153.0;
  e.e = 1.5;
  EXPECT_FALSE(keplerSatelliteState(e, GpsTime::fromWeekTow(2000, 0)).healthy);
  e.e = 0.999999;
  const SatelliteState s = keplerSatelliteState(e, GpsTime::fromWeekTow(2000, 100));
  EXPECT_TRUE(std::isfinite(s.position.norm()));
  GlonassEphemeris g;
  g.sat = SatId(System::Glonass, 1);
  g.toe = GpsTime::fromWeekTow(2000, 0);
  // A time years from tb is refused instead of integrated for minutes.
  EXPECT_FALSE(glonassSatelliteState(g, g.toe + 3.0e8).healthy);
  // A zero state vector does not divide by zero.
  EXPECT_TRUE(std::isfinite(glonassSatelliteState(g, g.toe + 100.0).position.norm()));
}

TEST(GroupDelay, GpsAndQzssFromTgd) {
  KeplerEphemeris e;
  e.sat = SatId(System::Gps, 3);
  e.tgd[0] = -1.071020960808E-08;
  const double g12 = std::pow(77.0 / 60.0, 2);    // (1575.42 / 1227.60)^2
  EXPECT_DOUBLE_EQ(broadcastGroupDelay(e, ObsCode('1', 'C')), e.tgd[0]);
  EXPECT_DOUBLE_EQ(broadcastGroupDelay(e, ObsCode('1', 'W')), e.tgd[0]);
  EXPECT_NEAR(broadcastGroupDelay(e, ObsCode('2', 'W')), g12 * e.tgd[0], 1e-22);
  // L5 is not a frequency scaling of T_GD: T_GD − ISC_L5 (IS-GPS-705J), T_GD without CNAV's ISC.
  EXPECT_DOUBLE_EQ(broadcastGroupDelay(e, ObsCode('5', 'Q')), e.tgd[0]);
  e.sat = SatId(System::Qzss, 2);
  e.message = NavMessage::QzssLnav;
  EXPECT_NEAR(broadcastGroupDelay(e, ObsCode('2', 'L')), g12 * e.tgd[0], 1e-22);
  EXPECT_EQ(broadcastGroupDelay(e, ObsCode('6', 'L')), 0.0);
  // The ionosphere-free L1/L2 combination carries no group delay (the clock's reference).
  const double tIf = (g12 * broadcastGroupDelay(e, ObsCode('1', 'C')) - broadcastGroupDelay(e, ObsCode('2', 'L'))) /
                     (g12 - 1.0);
  EXPECT_NEAR(tIf, 0.0, 1e-22);
}

TEST(GroupDelay, GpsL5FromSimulatedHardwareDelays) {
  // Truth: satellite code delays on L1 P(Y), L2 P(Y) and L5 with ISC_L5 = t_L1P(Y) − t_L5 = 0
  // (LNAV carries no ISC, so a receiver can do no better than assume it zero). The LNAV clock
  // absorbs the L1/L2 P(Y) ionosphere-free combination and T_GD = (b1 − b2)/(1 − γ12)
  // (IS-GPS-200N 20.3.3.3.3.2); a signal's delay relative to the clock is b_k minus that
  // combination. The L1/L5 pair then carries T_GD (IS-GPS-705J 20.3.3.3.1.2.3), not zero as a
  // γ15 scaling of T_GD would give.
  const double f1 = 1575.42e6, f2 = 1227.60e6, f5 = 1176.45e6;
  const double g12 = f1 * f1 / (f2 * f2), g15 = f1 * f1 / (f5 * f5);
  const double b1 = 4.0e-9, b2 = 9.5e-9, b5 = b1;
  KeplerEphemeris e;
  e.sat = SatId(System::Gps, 23);
  e.tgd[0] = (b1 - b2) / (1.0 - g12);
  const double clockRef = (g12 * b1 - b2) / (g12 - 1.0);
  EXPECT_NEAR(broadcastGroupDelay(e, ObsCode('1', 'C')), b1 - clockRef, 1e-20);
  EXPECT_NEAR(broadcastGroupDelay(e, ObsCode('2', 'L')), b2 - clockRef, 1e-20);
  EXPECT_NEAR(broadcastGroupDelay(e, ObsCode('5', 'Q')), b5 - clockRef, 1e-20);
  const double a1 = g15 / (g15 - 1.0), a2 = -1.0 / (g15 - 1.0);
  const double pairDelay =
      a1 * broadcastGroupDelay(e, ObsCode('1', 'C')) + a2 * broadcastGroupDelay(e, ObsCode('5', 'Q'));
  EXPECT_NEAR(pairDelay, a1 * b1 + a2 * b5 - clockRef, 1e-20);
  EXPECT_GT(std::abs(pairDelay), 1e-9);  // metres: the term the L1/L5 pair must remove
}

TEST(GroupDelay, GpsCnavIscsFromSimulatedHardwareDelays) {
  // Truth: satellite code delays on L1 P(Y), L2 P(Y), L1 C/A, L2C, L5 I5 and L5 Q5 (values of
  // the size the walk log's CNAV messages imply). The clock absorbs the L1/L2 P(Y) pair; T_GD =
  // (b1P − b2P)/(1 − γ12) and ISC_x = t_L1P(Y) − t_x = b1P − b_x (IS-GPS-200N 30.3.3.3.1.1.1,
  // IS-GPS-705J 20.3.3.3.1.2.1). Every signal's delay relative to the clock is b_x − clockRef.
  const double f1 = 1575.42e6, f2 = 1227.60e6, f5 = 1176.45e6;
  const double g12 = f1 * f1 / (f2 * f2), g15 = f1 * f1 / (f5 * f5);
  const double b1p = 2.0e-9, b2p = 16.1e-9, b1ca = 2.2e-9, b2c = 16.3e-9, b5i = 2.5e-9, b5q = 2.4e-9;
  const double clockRef = (g12 * b1p - b2p) / (g12 - 1.0);
  KeplerEphemeris e;
  e.sat = SatId(System::Gps, 23);
  e.tgd[0] = 1e-9;  // LNAV's T_GD: replaced by the CNAV message's own
  CnavGroupDelays c;
  c.sat = e.sat;
  c.tgd = (b1p - b2p) / (1.0 - g12);
  c.iscL1ca = b1p - b1ca;
  c.iscL2c = b1p - b2c;
  c.iscL5i5 = b1p - b5i;
  c.iscL5q5 = b1p - b5q;
  const std::pair<ObsCode, double> truth[] = {
      {ObsCode('1', 'W'), b1p}, {ObsCode('2', 'W'), b2p}, {ObsCode('1', 'C'), b1ca}, {ObsCode('2', 'L'), b2c},
      {ObsCode('2', 'S'), b2c}, {ObsCode('2', 'X'), b2c}, {ObsCode('5', 'I'), b5i},  {ObsCode('5', 'Q'), b5q},
      {ObsCode('5', 'X'), 0.5 * (b5i + b5q)}};
  for (const auto& [code, b] : truth) EXPECT_NEAR(broadcastGroupDelay(e, code, &c), b - clockRef, 1e-20) << code.str();
  // The ICDs' pair formulas, PR = (PR_2 − γ PR_L1C/A + c (ISC_2 − γ ISC_L1C/A))/(1 − γ) − c T_GD
  // (IS-GPS-200N 30.3.3.3.1.1.2, IS-GPS-705J 20.3.3.3.1.2.3), on pseudoranges made of a range,
  // a first-order ionosphere and the delays: both they and the pair of per-signal corrections
  // give the range.
  const double kC = 299792458.0, range = 2.2e7, iono = 7.3;
  auto pr = [&](double b, double f) { return range + iono * (f1 / f) * (f1 / f) + kC * (b - clockRef); };
  const struct {
    ObsCode code;
    double b, f, g, isc;
  } pairs[] = {{ObsCode('2', 'L'), b2c, f2, g12, *c.iscL2c}, {ObsCode('5', 'Q'), b5q, f5, g15, *c.iscL5q5}};
  for (const auto& p : pairs) {
    const double icd = (pr(p.b, p.f) - p.g * pr(b1ca, f1) + kC * (p.isc - p.g * *c.iscL1ca)) / (1.0 - p.g) - kC * *c.tgd;
    EXPECT_NEAR(icd, range, 1e-6) << p.code.str();
    const double a1 = p.g / (p.g - 1.0), a2 = -1.0 / (p.g - 1.0);
    const double ours = a1 * (pr(b1ca, f1) - kC * broadcastGroupDelay(e, ObsCode('1', 'C'), &c)) +
                        a2 * (pr(p.b, p.f) - kC * broadcastGroupDelay(e, p.code, &c));
    EXPECT_NEAR(ours, range, 1e-6) << p.code.str();
    // Without the message the L1/L5 pair keeps metres of error (the L1/L2C pair here only the
    // 0.2 ns by which L1 C/A and L2C differ from the P(Y) signals).
    if (p.code.band != '5') continue;
    const double lnav = a1 * (pr(b1ca, f1) - kC * broadcastGroupDelay(e, ObsCode('1', 'C'))) +
                        a2 * (pr(p.b, p.f) - kC * broadcastGroupDelay(e, p.code));
    EXPECT_GT(std::abs(lnav - range), 1.0) << p.code.str();
  }
  // "Not available" fields keep the LNAV rule (with the message's T_GD); another satellite's
  // message is not used.
  c.iscL2c.reset();
  EXPECT_NEAR(broadcastGroupDelay(e, ObsCode('2', 'L'), &c), g12 * *c.tgd, 1e-22);
  CnavGroupDelays other = c;
  other.sat = SatId(System::Gps, 24);
  EXPECT_EQ(broadcastGroupDelay(e, ObsCode('1', 'C'), &other), e.tgd[0]);
  // Galileo and BeiDou records ignore it.
  KeplerEphemeris gal;
  gal.sat = SatId(System::Galileo, 23);
  gal.message = NavMessage::GalileoInav;
  gal.tgd = {1e-9, 2e-9};
  EXPECT_EQ(broadcastGroupDelay(gal, ObsCode('1', 'C'), &c), broadcastGroupDelay(gal, ObsCode('1', 'C')));
}

TEST(GroupDelay, GalileoFromSimulatedHardwareDelays) {
  // Truth: satellite code delays on E1, E5a, E5b. The I/NAV clock absorbs the E1/E5b
  // ionosphere-free combination, the F/NAV clock the E1/E5a one; the delay a single-frequency
  // user must remove on band k is b_k minus the clock's combination. The broadcast BGDs are
  // (b5 - b1)/(g15 - 1) and (b7 - b1)/(g17 - 1) (OS SIS ICD 5.1.5).
  const double f1 = 1575.42e6, f5 = 1176.45e6, f7 = 1207.14e6;
  const double g15 = f1 * f1 / (f5 * f5), g17 = f1 * f1 / (f7 * f7);
  const double b1 = 3.1e-9, b5 = -2.4e-9, b7 = 5.7e-9;
  KeplerEphemeris e;
  e.sat = SatId(System::Galileo, 11);
  e.tgd = {(b5 - b1) / (g15 - 1.0), (b7 - b1) / (g17 - 1.0)};
  const double ifInav = (g17 * b1 - b7) / (g17 - 1.0);
  const double ifFnav = (g15 * b1 - b5) / (g15 - 1.0);
  e.message = NavMessage::GalileoInav;
  EXPECT_NEAR(broadcastGroupDelay(e, ObsCode('1', 'C')), b1 - ifInav, 1e-20);
  EXPECT_NEAR(broadcastGroupDelay(e, ObsCode('7', 'Q')), b7 - ifInav, 1e-20);
  EXPECT_NEAR(broadcastGroupDelay(e, ObsCode('5', 'Q')), b5 - ifInav, 1e-20);
  e.message = NavMessage::GalileoFnav;
  EXPECT_NEAR(broadcastGroupDelay(e, ObsCode('1', 'X')), b1 - ifFnav, 1e-20);
  EXPECT_NEAR(broadcastGroupDelay(e, ObsCode('5', 'X')), b5 - ifFnav, 1e-20);
  EXPECT_NEAR(broadcastGroupDelay(e, ObsCode('7', 'X')), b7 - ifFnav, 1e-20);
  EXPECT_EQ(broadcastGroupDelay(e, ObsCode('6', 'C')), 0.0);
}

TEST(GroupDelay, BeiDouAndGlonass) {
  KeplerEphemeris e;
  e.sat = SatId(System::BeiDou, 1);
  e.message = NavMessage::BeiDouD2;
  e.tgd = {-4.9e-09, -1.0e-08};
  EXPECT_EQ(broadcastGroupDelay(e, ObsCode('2', 'I')), -4.9e-09);
  EXPECT_EQ(broadcastGroupDelay(e, ObsCode('1', 'I')), -4.9e-09);  // RINEX 3.02 B1I code
  EXPECT_EQ(broadcastGroupDelay(e, ObsCode('7', 'I')), -1.0e-08);
  EXPECT_EQ(broadcastGroupDelay(e, ObsCode('6', 'I')), 0.0);       // B3I is the clock reference
  EXPECT_EQ(broadcastGroupDelay(e, ObsCode('1', 'P')), 0.0);       // B1C: CNAV1 only
  EXPECT_EQ(broadcastGroupDelay(e, ObsCode('7', 'D')), 0.0);       // B2b
  GlonassEphemeris g;
  g.deltaTauN = 8.381903171539e-09;
  EXPECT_EQ(broadcastGroupDelay(g, ObsCode('1', 'C')), 0.0);
  EXPECT_EQ(broadcastGroupDelay(g, ObsCode('2', 'P')), g.deltaTauN);
}
