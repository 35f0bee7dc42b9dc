// SSR corrections (ssr_corrections.hpp) applied to the broadcast records of the bundled Nagoya
// navigation file: definitions of RTCM 10403.3 3.5.12.3 (radial/along/cross frame, reference time
// epoch + update interval / 2, δC added to the broadcast clock), selection as a real-time receiver
// would see the stream, issue-of-data matching, code-bias sign, and an end-to-end check that
// corrections made from products (ssrFromProducts; the broadcast orbit moved by a known offset)
// give the products' states back.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include <Eigen/Geometry>

#include "gvins/base/constants.hpp"
#include "gvins/ephemeris/ephemeris_store.hpp"
#include "gvins/ephemeris/broadcast_sp3.hpp"
#include "gvins/ephemeris/precise_ephemeris.hpp"
#include "gvins/ephemeris/rinex_nav.hpp"
#include "gvins/ephemeris/sp3.hpp"
#include "gvins/ephemeris/ssr_from_products.hpp"
#include "gvins/ephemeris/ssr_corrections.hpp"
#include "nagoya_recording.hpp"

using namespace gvins;

namespace {

const std::string kNagoya = std::string(GVINS_TEST_DATA) + "/gnss/nagoya_static_2024/base.nav.gz";
constexpr double kC = constants::kSpeedOfLight;

SsrHeader header(SsrKind kind, const GpsTime& epoch, System sys = System::Gps, double udi = 5.0, int iodSsr = 3) {
  SsrHeader h;
  h.kind = kind;
  h.system = sys;
  h.epoch = epoch;
  h.updateInterval = udi;
  h.iodSsr = iodSsr;
  h.messageType = sys == System::Gps ? 1060 : 1066;
  return h;
}

SsrMessage combined(SatId sat, const GpsTime& epoch, int iode, const Eigen::Vector3d& rac,
                    const Eigen::Vector3d& racRate, const SsrClockCorrection& clock, double udi = 5.0,
                    int iodSsr = 3) {
  SsrMessage m;
  m.header = header(SsrKind::kCombined, epoch, sat.system, udi, iodSsr);
  SsrSatellite s;
  s.sat = sat;
  s.orbit = SsrOrbitCorrection{iode, 0, rac, racRate};
  s.clock = clock;
  m.satellites.push_back(s);
  return m;
}

const KeplerEphemeris& recordAt(const EphemerisStore& nav, SatId sat, const GpsTime& t) {
  const KeplerEphemeris* e = nav.selectKepler(sat, t);
  EXPECT_NE(e, nullptr);
  return *e;
}

}  // namespace

TEST(SsrCorrections, RadialAlongCrossFrameAndClockFollowTheRtcmDefinitions) {
  EphemerisStore nav;
  nav.add(readRinexNav(kNagoya));
  const SatId g = SatId::parse("G05").value();
  const GpsTime t0 = gvins::test::nagoyaTime(8, 20);
  const SatelliteState b = *nav.satelliteState(g, t0);
  const int iode = recordAt(nav, g, t0).iode;
  const GpsTime epoch = t0 - 2.5;  // reference time t0 = epoch + udi/2 = t0 exactly

  // 1 m radial: the satellite moves 1 m towards the Earth's centre (GPS orbits are nearly circular,
  // so the RTCM radial e_a × e_c is within the eccentricity (< 0.02 rad) of r/|r|).
  EphemerisStore a;
  a.add(readRinexNav(kNagoya));
  a.addSsr(combined(g, epoch, iode, {1, 0, 0}, {0, 0, 0}, {0, 0, 0}));
  const auto s = a.satelliteState(g, t0);
  ASSERT_TRUE(s);
  EXPECT_TRUE(s->ssr);
  EXPECT_FALSE(s->precise);
  const Eigen::Vector3d d = s->position - b.position;
  EXPECT_NEAR(d.norm(), 1.0, 1e-7);
  EXPECT_GT(-d.dot(b.position.normalized()), 0.9998);
  EXPECT_NEAR(d.dot(b.velocity.normalized()), 0.0, 1e-7);  // radial ⟂ along (= velocity)
  EXPECT_EQ(s->clockBias, b.clockBias);

  // 1 m along: exactly against the velocity; 1 m cross: along −(r × v).
  EphemerisStore al;
  al.add(readRinexNav(kNagoya));
  al.addSsr(combined(g, epoch, iode, {0, 1, 0}, {0, 0, 0}, {0, 0, 0}));
  EXPECT_LT((al.satelliteState(g, t0)->position - b.position + b.velocity.normalized()).norm(), 1e-7);
  EphemerisStore cr;
  cr.add(readRinexNav(kNagoya));
  cr.addSsr(combined(g, epoch, iode, {0, 0, 1}, {0, 0, 0}, {0, 0, 0}));
  EXPECT_LT((cr.satelliteState(g, t0)->position - b.position +
             b.position.cross(b.velocity).normalized()).norm(), 1e-7);

  // Rates and the clock polynomial count from epoch + udi/2: 10 s later the 0.01 m/s radial rate
  // adds 0.1 m, the clock 3 m + 0.02 m/s × 10 s + 0.001 m/s² × 100 s² = 3.3 m (added to the
  // broadcast clock offset, as t_sat,corrected = t_sv − (dt_brdc + δC/c)).
  EphemerisStore r;
  r.add(readRinexNav(kNagoya));
  r.addSsr(combined(g, epoch, iode, {0, 0, 0}, {0.01, 0, 0}, {3.0, 0.02, 0.001}));
  const GpsTime t = t0 + 10.0;
  const SatelliteState bt = *nav.satelliteState(g, t);
  const auto st = r.satelliteState(g, t);
  ASSERT_TRUE(st);
  EXPECT_NEAR((st->position - bt.position).norm(), 0.1, 1e-7);
  EXPECT_NEAR((st->clockBias - bt.clockBias) * kC, 3.3, 1e-6);
  EXPECT_NEAR((st->clockDrift - bt.clockDrift) * kC, 0.02 + 2 * 0.001 * 10.0, 1e-9);
}

TEST(SsrCorrections, SelectionIsCausalAgesOutAndNeedsOneIodSsr) {
  SsrCorrections c;
  const SatId g = SatId::parse("G05").value();
  const GpsTime t0 = gvins::test::nagoyaTime(8, 20);
  EXPECT_TRUE(c.empty());
  EXPECT_FALSE(c.select(g, t0));
  c.add(combined(g, t0, 7, {0.1, 0, 0}, {0, 0, 0}, {1, 0, 0}));
  c.add(combined(g, t0 + 30.0, 7, {0.2, 0, 0}, {0, 0, 0}, {2, 0, 0}));
  EXPECT_FALSE(c.select(g, t0 - 1.0));                   // nothing received yet
  EXPECT_DOUBLE_EQ(c.select(g, t0 + 29.0)->clock.c0, 1);  // the later one is still in the future
  EXPECT_DOUBLE_EQ(c.select(g, t0 + 30.0)->clock.c0, 2);
  EXPECT_TRUE(c.select(g, t0 + 30.0 + 90.0));
  EXPECT_FALSE(c.select(g, t0 + 30.0 + 90.5));  // older than maxAge
  EXPECT_TRUE(c.coversSystem(System::Gps, t0 + 100.0));
  EXPECT_FALSE(c.coversSystem(System::Galileo, t0 + 100.0));
  EXPECT_FALSE(c.coversSystem(System::Gps, t0 + 200.0));

  // A clock of another IOD SSR (a new solution configuration) does not go with this orbit.
  SsrCorrections d;
  SsrMessage orbit;
  orbit.header = header(SsrKind::kOrbit, t0, System::Gps, 5.0, 1);
  orbit.satellites.push_back({g, SsrOrbitCorrection{7, 0, {0.1, 0, 0}, {0, 0, 0}}, {}, {}, {}, {}});
  d.add(orbit);
  SsrMessage clock;
  clock.header = header(SsrKind::kClock, t0 + 5.0, System::Gps, 5.0, 2);
  clock.satellites.push_back({g, {}, SsrClockCorrection{1, 0, 0}, {}, {}, {}});
  d.add(clock);
  EXPECT_FALSE(d.select(g, t0 + 6.0));
  clock.header.iodSsr = 1;
  clock.header.epoch = t0 + 4.0;
  d.add(clock);
  EXPECT_TRUE(d.select(g, t0 + 6.0));
  // High-rate clock of the same IOD SSR adds to δC while it is fresh (10 s).
  SsrMessage hr;
  hr.header = header(SsrKind::kHighRateClock, t0 + 5.0, System::Gps, 1.0, 1);
  hr.satellites.push_back({g, {}, {}, {}, {}, 0.25});
  d.add(hr);
  EXPECT_DOUBLE_EQ(*d.select(g, t0 + 6.0)->highRateClock, 0.25);
  EXPECT_FALSE(d.select(g, t0 + 15.5)->highRateClock);
}

TEST(SsrCorrections, IssueOfDataPicksTheRecordAndUncoveredSatellitesAreDropped) {
  EphemerisStore nav;
  nav.add(readRinexNav(kNagoya));
  const GpsTime t0 = gvins::test::nagoyaTime(8, 20);
  // A satellite with two records of different issues of data, both valid at t0: the one the
  // correction names is used even when the other is the one the broadcast selection picks.
  SatId g;
  const KeplerEphemeris* other = nullptr;
  const KeplerEphemeris* chosen = nullptr;
  for (SatId sat : nav.satellites()) {
    if (sat.system != System::Gps && sat.system != System::Galileo) continue;
    const KeplerEphemeris* sel = nav.selectKepler(sat, t0);
    if (!sel) continue;
    for (const auto& e : nav.keplerRecords(sat))
      if (e.iode != sel->iode && e.message == sel->message &&
          std::abs(t0 - e.toe) <= EphemerisStore::validityHalfWindow(e)) {
        g = sat;
        other = &e;
        chosen = sel;
      }
    if (other) break;
  }
  ASSERT_NE(other, nullptr);
  const KeplerEphemeris& now = *chosen;
  const auto& recs = nav.keplerRecords(g);
  EphemerisStore s;
  s.add(readRinexNav(kNagoya));
  s.addSsr(combined(g, t0, other->iode, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}));
  const auto st = s.satelliteState(g, t0 + 1.0);
  ASSERT_TRUE(st);
  const SatelliteState fromOther = keplerSatelliteState(*other, t0 + 1.0);
  EXPECT_LT((st->position - fromOther.position).norm(), 1e-9);
  EXPECT_EQ(st->clockBias, fromOther.clockBias);
  // An IODE that no record has: no state, and none from the broadcast either (GPS is covered).
  EphemerisStore u;
  u.add(readRinexNav(kNagoya));
  u.addSsr(combined(g, t0, 255 - (now.iode % 7), {0, 0, 0}, {0, 0, 0}, {0, 0, 0}));
  bool anyRecordWithThatIode = false;
  for (const auto& e : recs) anyRecordWithThatIode |= e.iode == 255 - (now.iode % 7);
  ASSERT_FALSE(anyRecordWithThatIode);
  EXPECT_FALSE(u.satelliteState(g, t0 + 1.0));
  // Another GPS satellite without a correction: dropped while the stream covers GPS, Galileo
  // satellites keep their broadcast states; after maxAge GPS falls back to broadcast too.
  const System otherSystem = g.system == System::Gps ? System::Galileo : System::Gps;
  SatId g2, e;
  for (SatId sat : nav.satellites()) {
    if (!nav.satelliteState(sat, t0) || sat == g) continue;
    if (sat.system == g.system) g2 = sat;
    if (sat.system == otherSystem) e = sat;
  }
  ASSERT_TRUE(g2.valid() && e.valid());
  EXPECT_FALSE(s.satelliteState(g2, t0 + 1.0));
  EXPECT_TRUE(s.satelliteState(e, t0 + 1.0));
  EXPECT_FALSE(s.satelliteState(e, t0 + 1.0)->ssr);
  EXPECT_TRUE(s.satelliteState(g2, t0 + 100.0));
}

TEST(SsrCorrections, CodeBiasesAreAddedToTheMeasurementSoTheDelayIsTheirNegative) {
  EphemerisStore nav;
  nav.add(readRinexNav(kNagoya));
  const GpsTime t0 = gvins::test::nagoyaTime(8, 20);
  const SatId g = SatId::parse("G05").value();
  const int iode = recordAt(nav, g, t0).iode;
  const ObsCode c1c('1', 'C'), c2w('2', 'W'), c5q('5', 'Q');
  const double tgd = nav.groupDelay(g, c1c, t0);
  nav.addSsr(combined(g, t0, iode, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}));
  SsrMessage cb;
  cb.header = header(SsrKind::kCodeBias, t0, System::Gps);
  SsrSatellite s;
  s.sat = g;
  s.codeBiases = {{c1c, 0.5}, {c2w, -1.25}};
  cb.satellites.push_back(s);
  nav.addSsr(cb);
  const auto st = nav.satelliteState(g, t0 + 1.0);
  ASSERT_TRUE(st && st->ssr);
  EXPECT_NEAR(nav.codeDelay(*st, g, c1c, t0 + 1.0) * kC, -0.5, 1e-12);
  EXPECT_NEAR(nav.codeDelay(*st, g, c2w, t0 + 1.0) * kC, 1.25, 1e-12);
  // No SSR bias for the signal: the broadcast group delay, as for an uncorrected state.
  EXPECT_DOUBLE_EQ(nav.codeDelay(*st, g, c5q, t0 + 1.0), nav.groupDelay(g, c5q, t0 + 1.0));
  SatelliteState plain = *st;
  plain.ssr = false;
  EXPECT_DOUBLE_EQ(nav.codeDelay(plain, g, c1c, t0 + 1.0), tgd);
}

TEST(SsrCorrections, CorrectionsMadeFromProductsGiveTheProductStatesBack) {
  // A correction service's view (ssrFromProducts): "products" = the broadcast orbits moved by a
  // fixed ECEF offset and clocks shifted by 0.8 m, as SP3/clock data with 300 s nodes; it sends
  // combined corrections every 5 s (udi 5 s). A receiver applying each one until the next (up to
  // 7.5 s after the reference time, by its rates) gets the products' states back.
  EphemerisStore nav;
  nav.add(readRinexNav(kNagoya));
  const GpsTime t0 = gvins::test::nagoyaTime(8, 20);
  const Eigen::Vector3d offset(1.5, -0.7, 2.0);
  std::vector<SatId> sats;
  for (const char* id : {"G05", "G13", "E04", "J03", "C23", "R07"}) {
    const SatId sat = SatId::parse(id).value();
    if (nav.satelliteState(sat, t0)) sats.push_back(sat);
  }
  ASSERT_GE(sats.size(), 4u);
  Sp3Data sp3 = broadcastSp3(nav, t0 - 1800.0, t0 + 1800.0, 300.0, sats);
  for (Sp3Epoch& ep : sp3.epochs)
    for (Sp3Record& r : ep.records) {
      r.position += offset;
      r.clock += 0.8 / kC;
    }
  auto precise = std::make_shared<PreciseEphemeris>();
  precise->add(sp3);
  EphemerisStore products;
  products.add(readRinexNav(kNagoya));
  products.setPrecise(precise);
  SsrServiceConfig service;
  const std::vector<SsrMessage> messages = ssrFromProducts(nav, products, t0 - 10.0, t0 + 70.0, service);
  ASSERT_GE(messages.size(), 16u);  // every 5 s, one message per system with satellites
  EXPECT_EQ(messages.front().header.kind, SsrKind::kCombined);
  EXPECT_DOUBLE_EQ(messages.front().header.updateInterval, 5.0);
  EphemerisStore rx;
  rx.add(readRinexNav(kNagoya));
  for (const SsrMessage& m : messages) rx.addSsr(m);
  double worst = 0.0, worstClock = 0.0;
  for (double dt = 0.0; dt < 60.0; dt += 0.7) {
    const GpsTime t = t0 + dt;
    for (SatId sat : sats) {
      const auto p = products.preciseState(sat, t);
      const auto s = rx.satelliteState(sat, t);
      ASSERT_TRUE(p && s) << sat.str() << " at +" << dt;
      EXPECT_TRUE(s->ssr);
      worst = std::max(worst, (s->position - p->position).norm());
      worstClock = std::max(worstClock, std::abs(s->clockBias - p->clockBias) * kC);
    }
  }
  // Measured: 1e-5 m position, 1e-8 m clock (second-order terms of the rates' linear
  // extrapolation over <= 7.5 s).
  EXPECT_LT(worst, 1e-4);
  EXPECT_LT(worstClock, 1e-4);
  std::printf("SSR from products: worst position %.2e m, clock %.2e m\n", worst, worstClock);
}

TEST(SsrCorrections, UraIndexFollowsDf389) {
  EXPECT_FALSE(ssrUraMetres(0));
  EXPECT_FALSE(ssrUraMetres(63));
  EXPECT_NEAR(*ssrUraMetres(1), 0.25e-3, 1e-12);              // class 0, value 1: 1.25 − 1 mm
  EXPECT_NEAR(*ssrUraMetres((2 << 3) | 4), 17e-3, 1e-12);    // 9 × 2 − 1 mm
  EXPECT_NEAR(*ssrUraMetres(62), (2187.0 * 2.5 - 1) * 1e-3, 1e-12);
}
