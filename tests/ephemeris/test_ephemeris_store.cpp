// Ephemeris store: validity windows, health, newest/nearest record, records from the future,
// Galileo I/NAV vs F/NAV, duplicates, and continuity of satellite states across record switches.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <string>

#include "gvins/ephemeris/ephemeris_store.hpp"

using namespace gvins;

namespace {

const std::string kData = GVINS_TEST_DATA;
const std::string kNagoya = kData + "/gnss/nagoya_static_2024/base.nav.gz";
const std::string kGeonet = kData + "/gnss/geonet_0759_3040_2005/07590920.05n.gz";
const std::string k21q = kData + "/gnss/kamakura_static_2021/30340780.21q.gz";
const std::string k21P = kData + "/gnss/kamakura_static_2021/SEPT078M.21P.gz";
const std::string kRinex4 = kData + "/gnss/brd400dlr_2022_rinex4/BRD400DLR_S_20222780000_extract.rnx.gz";

const KeplerEphemeris& first(const NavData& nav, SatId sat) {
  for (const auto& e : nav.kepler) {
    if (e.sat == sat) return e;
  }
  throw std::runtime_error("no record of " + sat.str());
}

// A store holding one record.
EphemerisStore single(const KeplerEphemeris& e) {
  EphemerisStore s;
  s.add(e);
  return s;
}

}  // namespace

TEST(EphemerisStore, ValidityWindowsPerSystem) {
  const NavData nagoya = readRinexNav(kNagoya);
  struct Case {
    KeplerEphemeris e;
    double halfWindow;
  };
  KeplerEphemeris gps = first(nagoya, SatId(System::Gps, 5));  // fit interval 4 h
  KeplerEphemeris gpsFit6 = gps;
  gpsFit6.fitInterval = 6.0;
  KeplerEphemeris gpsFlag = gps;
  gpsFlag.fitInterval = 1.0;  // "more than 4 h" flag
  const NavData q = readRinexNav(k21q);
  KeplerEphemeris qzss = first(q, SatId(System::Qzss, 1));  // fit flag 0 = 2 h
  KeplerEphemeris qzssLong = qzss;
  qzssLong.fitInterval = 4.0;
  const Case cases[] = {
      {gps, 7200.0},
      {gpsFit6, 10800.0},
      {gpsFlag, 10800.0},
      {qzss, 3600.0},
      {qzssLong, 7200.0},
      {first(nagoya, SatId(System::Galileo, 12)), 14400.0},
      {first(nagoya, SatId(System::BeiDou, 6)), 7200.0},
      {first(nagoya, SatId(System::BeiDou, 1)), 7200.0},
  };
  EphemerisSelection any;
  any.allowUnhealthy = true;
  any.futureTolerance = 1e9;  // windows only (records transmitted after t are tested below)
  for (const auto& c : cases) {
    SCOPED_TRACE(c.e.sat.str());
    EXPECT_DOUBLE_EQ(EphemerisStore::validityHalfWindow(c.e), c.halfWindow);
    const EphemerisStore s = single(c.e);
    for (double sign : {-1.0, 1.0}) {
      EXPECT_NE(s.selectKepler(c.e.sat, c.e.toe + sign * (c.halfWindow - 1.0), any), nullptr);
      EXPECT_EQ(s.selectKepler(c.e.sat, c.e.toe + sign * (c.halfWindow + 1.0), any), nullptr);
    }
  }
  // GLONASS: +-30 min around tb.
  EphemerisStore s;
  s.add(nagoya);
  const GlonassEphemeris& r = nagoya.glonass.front();
  EXPECT_NE(s.selectGlonass(r.sat, r.toe + 1799.0), nullptr);
  EXPECT_EQ(s.selectGlonass(r.sat, r.toe - 1801.0), nullptr);
}

TEST(EphemerisStore, NearestToeAndTieToNewestTransmission) {
  const NavData geonet = readRinexNav(kGeonet);
  EphemerisStore s;
  s.add(geonet);
  const SatId g01(System::Gps, 1);
  const auto& recs = s.keplerRecords(g01);
  ASSERT_GE(recs.size(), 3u);
  for (std::size_t i = 0; i + 1 < recs.size(); ++i) EXPECT_LT(recs[i].toe, recs[i + 1].toe);
  // Between two consecutive records (16:00 and 18:00) the nearer toe wins; between 04:00 and
  // 13:59 (no data in the file) nothing is valid from 06:00 to 11:59.
  ASSERT_EQ(recs[3].toe, GpsTime::fromWeekTow(1316, 6 * 86400 + 16 * 3600));
  const GpsTime a = recs[3].toe, b = recs[4].toe;
  const double gap = b - a;
  EXPECT_EQ(s.selectKepler(g01, a + 0.25 * gap), &recs[3]);
  EXPECT_EQ(s.selectKepler(g01, a + 0.75 * gap), &recs[4]);
  EXPECT_EQ(s.selectKepler(g01, recs[1].toe + 7201.0), nullptr);
  EXPECT_EQ(s.selectKepler(g01, recs[2].toe - 7201.0), nullptr);
  // Two copies of one toe with different issue of data: the later transmission wins a tie.
  KeplerEphemeris older = recs[3], newer = recs[3];
  older.iode = 10;
  newer.iode = 11;
  newer.ttr = older.ttr + 600.0;
  newer.af0 += 1e-9;
  EphemerisStore t;
  t.add(newer);
  t.add(older);
  EXPECT_EQ(t.size(), 2u);
  EXPECT_EQ(t.selectKepler(g01, a + 60.0)->iode, 11);
}

TEST(EphemerisStore, DuplicatesAreStoredOnce) {
  EphemerisStore s;
  s.add(readRinexNav(kNagoya));
  const std::size_t n = s.size();
  s.add(readRinexNav(kNagoya));
  EXPECT_EQ(s.size(), n);
  // The nagoya file holds two copies of E12 IODnav 67 I/NAV (1 s apart, different BGD): one kept,
  // the copy that was available first.
  int copies = 0;
  for (const auto& e : s.keplerRecords(SatId(System::Galileo, 12))) {
    if (e.iode == 67 && e.message == NavMessage::GalileoInav) {
      ++copies;
      EXPECT_DOUBLE_EQ(e.tgd[0], -8.614733815193E-09);
    }
  }
  EXPECT_EQ(copies, 1);
  EXPECT_EQ(s.glonassChannels().get(1).value_or(99), 1);
  EXPECT_EQ(s.leapSeconds().value_or(0), 18);
  EXPECT_TRUE(s.ionosphere().gps.has_value());
}

TEST(EphemerisStore, HealthFlags) {
  const NavData nagoya = readRinexNav(kNagoya);
  KeplerEphemeris good = first(nagoya, SatId(System::Gps, 5));
  KeplerEphemeris bad = good;
  bad.health = 0x3F;
  bad.toe += 600.0;  // nearer to the query time
  bad.iode += 1;
  EphemerisStore s;
  s.add(good);
  s.add(bad);
  const GpsTime t = good.toe + 900.0;
  EXPECT_EQ(s.selectKepler(good.sat, t)->health, 0);
  EphemerisSelection any;
  any.allowUnhealthy = true;
  EXPECT_EQ(s.selectKepler(good.sat, t, any)->health, 0x3F);
  EXPECT_FALSE(s.satelliteState(good.sat, t, any)->healthy);
  // QZSS: the L1C/B bit alone (health 1, as broadcast by QZS-2/3/4) is healthy.
  const NavData q = readRinexNav(k21q);
  KeplerEphemeris j = first(q, SatId(System::Qzss, 2));
  j.health = 1;
  EXPECT_TRUE(isHealthy(j));
  j.health = 0x21;
  EXPECT_FALSE(isHealthy(j));
  // Galileo: I/NAV looks at E1-B/E5b bits only, F/NAV at E5a bits only.
  KeplerEphemeris gal = first(nagoya, SatId(System::Galileo, 12));
  gal.message = NavMessage::GalileoInav;
  gal.health = 0x038;  // E5a DVS + HS
  EXPECT_TRUE(isHealthy(gal));
  gal.message = NavMessage::GalileoFnav;
  EXPECT_FALSE(isHealthy(gal));
  // GLONASS.
  GlonassEphemeris r = nagoya.glonass.front();
  r.health = 1;
  EphemerisStore g;
  g.add(r);
  EXPECT_EQ(g.selectGlonass(r.sat, r.toe), nullptr);
  EXPECT_NE(g.selectGlonass(r.sat, r.toe, any), nullptr);
}

TEST(EphemerisStore, RecordsFromTheFuture) {
  // G05's 10:00 record was transmitted at 08:00:18. A real-time receiver has it from then on; with
  // a whole-day file it may be used earlier only within futureTolerance of its toe.
  const NavData nagoya = readRinexNav(kNagoya);
  const KeplerEphemeris& e = first(nagoya, SatId(System::Gps, 5));
  const EphemerisStore s = single(e);
  EphemerisSelection realtime;
  realtime.futureTolerance = -1.0;
  EXPECT_EQ(s.selectKepler(e.sat, e.ttr - 1.0, realtime), nullptr);
  EXPECT_NE(s.selectKepler(e.sat, e.ttr + 1.0, realtime), nullptr);
  EXPECT_NE(s.selectKepler(e.sat, e.ttr - 1.0), nullptr);  // default: within 2 h of toe
  EphemerisSelection tight;
  tight.futureTolerance = 3600.0;  // 08:00:17 is 7183 s before toe
  EXPECT_EQ(s.selectKepler(e.sat, e.ttr - 1.0, tight), nullptr);
  EXPECT_NE(s.selectKepler(e.sat, e.ttr + 1.0, tight), nullptr);
  // GLONASS uses the frame time.
  EphemerisStore g;
  const GlonassEphemeris& r = nagoya.glonass.front();
  g.add(r);
  EXPECT_EQ(g.selectGlonass(r.sat, r.tof - 1.0, realtime), nullptr);
  EXPECT_NE(g.selectGlonass(r.sat, r.tof + 1.0, realtime), nullptr);
}

TEST(EphemerisStore, GalileoInavPreferredWithFnavFallback) {
  EphemerisStore s;
  s.add(readRinexNav(kNagoya));
  const SatId e12(System::Galileo, 12);
  const GpsTime t = first(readRinexNav(kNagoya), e12).toe + 300.0;
  ASSERT_NE(s.selectKepler(e12, t), nullptr);
  EXPECT_EQ(s.selectKepler(e12, t)->message, NavMessage::GalileoInav);
  EphemerisSelection fnav;
  fnav.preferGalileoInav = false;
  EXPECT_EQ(s.selectKepler(e12, t, fnav)->message, NavMessage::GalileoFnav);
  // Only F/NAV present: used even though I/NAV is preferred.
  EphemerisStore onlyF;
  for (const auto& e : s.keplerRecords(e12)) {
    if (e.message == NavMessage::GalileoFnav) onlyF.add(e);
  }
  ASSERT_NE(onlyF.selectKepler(e12, t), nullptr);
  EXPECT_EQ(onlyF.selectKepler(e12, t)->message, NavMessage::GalileoFnav);
  // The group delay follows the selected message: BGD(E1,E5b) for I/NAV, BGD(E1,E5a) for F/NAV.
  EXPECT_EQ(s.groupDelay(e12, ObsCode('1', 'C'), t), s.selectKepler(e12, t)->tgd[1]);
  EXPECT_EQ(s.groupDelay(e12, ObsCode('1', 'C'), t, fnav), s.selectKepler(e12, t, fnav)->tgd[0]);
}

TEST(EphemerisStore, UnknownSatellitesAndSystems) {
  EphemerisStore s;
  EXPECT_FALSE(s.satelliteState(SatId(System::Gps, 5), GpsTime::fromWeekTow(2320, 0)).has_value());
  s.add(readRinexNav(kNagoya));
  EXPECT_FALSE(s.satelliteState(SatId(System::Sbas, 27), GpsTime::fromWeekTow(2320, 115200)).has_value());
  EXPECT_FALSE(s.satelliteState(SatId(System::Gps, 31), GpsTime::fromWeekTow(2320, 115200)).has_value());
  EXPECT_EQ(s.groupDelay(SatId(System::Gps, 31), ObsCode('1', 'C'), GpsTime::fromWeekTow(2320, 115200)), 0.0);
  EXPECT_TRUE(s.keplerRecords(SatId(System::Gps, 31)).empty());
  std::set<std::string> ids;
  const NavData nav = readRinexNav(kNagoya);
  for (const auto& e : nav.kepler) ids.insert(e.sat.str());
  for (const auto& g : nav.glonass) ids.insert(g.sat.str());
  EXPECT_EQ(s.satellites().size(), ids.size());
}

TEST(EphemerisStore, SwitchesJumpNoMoreThanTheBroadcastError) {
  // At the midpoint between consecutive records of a satellite both describe the same orbit; the
  // difference is the broadcast orbit/clock error of the two (metres, nanoseconds).
  // Besides the 3-D position and clock jumps, the signal-in-space range error of the switch:
  // sqrt((dR - c dt)^2 + (dA^2 + dC^2)/49), the usual global-average weighting for MEO orbits
  // (radial R, along-track A, cross-track C).
  struct Jump {
    int n = 0;
    double maxPos = 0.0, maxClock = 0.0, maxSisre = 0.0;
    void add(const SatelliteState& a, const SatelliteState& b) {
      ++n;
      const Eigen::Vector3d d = a.position - b.position;
      const Eigen::Vector3d r = a.position.normalized();
      const double dr = d.dot(r);
      const double dc = (a.clockBias - b.clockBias) * 299792458.0;
      const double ac2 = d.squaredNorm() - dr * dr;
      maxPos = std::max(maxPos, d.norm());
      maxClock = std::max(maxClock, std::fabs(a.clockBias - b.clockBias));
      maxSisre = std::max(maxSisre, std::sqrt((dr - dc) * (dr - dc) + ac2 / 49.0));
    }
  };
  std::map<System, Jump> jumps;
  for (const auto& f : {kNagoya, kGeonet, k21q, k21P, kRinex4}) {
    EphemerisStore s;
    s.add(readRinexNav(f));
    for (const SatId sat : s.satellites()) {
      if (sat.system == System::Glonass) {
        const auto& list = s.glonassRecords(sat);
        for (std::size_t i = 0; i + 1 < list.size(); ++i) {
          const double gap = list[i + 1].toe - list[i].toe;
          if (gap <= 0.0 || gap > 3600.0 || !isHealthy(list[i]) || !isHealthy(list[i + 1])) continue;
          const GpsTime tm = list[i].toe + gap / 2;
          jumps[sat.system].add(glonassSatelliteState(list[i], tm), glonassSatelliteState(list[i + 1], tm));
        }
        continue;
      }
      const auto& list = s.keplerRecords(sat);
      for (std::size_t i = 0; i < list.size(); ++i) {
        // Next record of the same message with a later toe.
        std::size_t k = i + 1;
        while (k < list.size() && (list[k].message != list[i].message || !(list[i].toe < list[k].toe))) ++k;
        if (k >= list.size() || !isHealthy(list[i]) || !isHealthy(list[k])) continue;
        const double gap = list[k].toe - list[i].toe;
        if (gap > 2.0 * EphemerisStore::validityHalfWindow(list[i])) continue;
        const GpsTime tm = list[i].toe + gap / 2;
        jumps[sat.system].add(keplerSatelliteState(list[i], tm), keplerSatelliteState(list[k], tm));
      }
    }
  }
  std::printf("record switches: system     n  max position (m)  max clock (ns)  max SISRE (m)\n");
  for (const auto& [sys, j] : jumps) {
    std::printf("                 %-8s %4d  %16.3f  %14.3f  %13.3f\n", std::string(systemName(sys)).c_str(), j.n,
                j.maxPos, j.maxClock * 1e9, j.maxSisre);
  }
  for (System sys : {System::Gps, System::Glonass, System::Galileo, System::BeiDou, System::Qzss}) {
    ASSERT_TRUE(jumps.count(sys)) << systemName(sys);
    EXPECT_GE(jumps[sys].n, 1) << systemName(sys);
    // GPS 2005 (geonet) has the largest: 6.7 m along/cross-track and 13 ns between interleaved
    // upload sets; the range users see moves by at most 3.9 m (URA 2-2.8 m).
    EXPECT_LT(jumps[sys].maxPos, 10.0) << systemName(sys);
    EXPECT_LT(jumps[sys].maxClock, 20e-9) << systemName(sys);
    EXPECT_LT(jumps[sys].maxSisre, 5.0) << systemName(sys);
  }
}

// CNAV message type 30: the latest message at or before the time asked for; repetitions extend
// how long its corrections are known; an old one is not used; groupDelay applies it.
TEST(EphemerisStore, CnavGroupDelaysLatestAtOrBefore) {
  const NavData nav = readRinexNav(kNagoya);
  const SatId g = nav.kepler.front().sat;
  ASSERT_EQ(g.system, System::Gps);
  EphemerisStore s;
  s.add(nav);
  const GpsTime t0 = nav.kepler.front().toe;
  auto message = [&](double dt, double iscL1ca) {
    CnavGroupDelays c;
    c.sat = g;
    c.time = t0 + dt;
    c.tgd = nav.kepler.front().tgd[0];
    c.iscL1ca = iscL1ca;
    return c;
  };
  const std::uint64_t rev = s.revision();
  s.add(message(0.0, 1e-9));
  s.add(message(48.0, 1e-9));    // a repetition
  s.add(message(600.0, -2e-9));  // new corrections
  s.add(message(-30.0, 1e-9));   // the first values, seen earlier than known
  EXPECT_EQ(s.revision(), rev);  // no record choice changed
  EXPECT_EQ(s.cnavGroupDelays(g, t0 - 31.0), nullptr);
  ASSERT_NE(s.cnavGroupDelays(g, t0 - 30.0), nullptr);
  EXPECT_EQ(s.cnavGroupDelays(g, t0 - 30.0)->time, t0 - 30.0);
  EXPECT_EQ(s.cnavGroupDelays(g, t0 + 599.0)->iscL1ca, 1e-9);
  EXPECT_EQ(s.cnavGroupDelays(g, t0 + 600.0)->iscL1ca, -2e-9);
  EXPECT_EQ(s.cnavGroupDelays(SatId(System::Gps, g.prn % 32 + 1), t0 + 600.0), nullptr);
  EXPECT_NE(s.cnavGroupDelays(g, t0 + 600.0 + kCnavGroupDelayMaxAge), nullptr);
  EXPECT_EQ(s.cnavGroupDelays(g, t0 + 601.0 + kCnavGroupDelayMaxAge), nullptr);
  // groupDelay: L1 C/A T_GD − ISC_L1C/A (the message's T_GD) where a message is known, T_GD
  // before.
  const double tgd = nav.kepler.front().tgd[0];
  ASSERT_NE(s.selectKepler(g, t0 - 60.0), nullptr);
  EXPECT_EQ(s.groupDelay(g, ObsCode('1', 'C'), t0 - 60.0), s.selectKepler(g, t0 - 60.0)->tgd[0]);
  EXPECT_EQ(s.groupDelay(g, ObsCode('1', 'C'), t0 + 60.0), tgd - 1e-9);
  EXPECT_EQ(s.groupDelay(g, ObsCode('1', 'C'), t0 + 900.0), tgd + 2e-9);
  // Only GPS and QZSS take CNAV group delays.
  CnavGroupDelays galileo = message(0.0, 1e-9);
  galileo.sat = SatId(System::Galileo, 1);
  s.add(galileo);
  EXPECT_EQ(s.cnavGroupDelays(galileo.sat, t0 + 1.0), nullptr);
}
