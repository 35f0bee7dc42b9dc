// PreciseEphemeris against an analytic truth: SP3-like node tables sampled from broadcast orbits
// (a real GPS LNAV record and a real GLONASS record of the Nagoya 2024 navigation file) with the
// periodic relativistic term removed from the clocks, as IGS products give them. Interpolation at
// off-node times must reproduce the broadcast functions, and the relativistic term must be
// restored. Coverage rules: nothing outside the span, across a data gap or next to a NaN node.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "gvins/base/constants.hpp"
#include "gvins/ephemeris/precise_ephemeris.hpp"
#include "gvins/ephemeris/rinex_nav.hpp"
#include "gvins/ephemeris/satellite_state.hpp"

using namespace gvins;

namespace {

const std::string kData = GVINS_TEST_DATA;
constexpr double kC2 = constants::kSpeedOfLight * constants::kSpeedOfLight;

const NavData& nagoya() {
  static const NavData nav = readRinexNav(kData + "/gnss/nagoya_static_2024/base.nav.gz");
  return nav;
}

const KeplerEphemeris& gpsRecord() {
  for (const auto& e : nagoya().kepler) {
    if (e.sat.system == System::Gps) return e;
  }
  throw std::runtime_error("no GPS record");
}

// Clock as an IGS product gives it: broadcast clock minus the periodic relativistic term.
double productClock(const SatelliteState& s) { return s.clockBias + 2.0 * s.position.dot(s.velocity) / kC2; }

template <class Truth>
Sp3Data sampled(SatId sat, const GpsTime& center, double spacing, int halfCount, Truth truth) {
  Sp3Data d;
  d.interval = spacing;
  d.satellites = {sat};
  d.accuracyExponent = {5};
  for (int k = -halfCount; k <= halfCount; ++k) {
    const GpsTime t = center + k * spacing;
    const SatelliteState s = truth(t);
    Sp3Record r;
    r.sat = sat;
    r.position = s.position;
    r.clock = productClock(s);
    d.epochs.push_back({t, {r}});
  }
  return d;
}

struct Errors {
  double pos = 0, vel = 0, clk = 0, drift = 0, rel = 0;
  int n = 0;
};

// Compares at off-node times between nodes [from, to] of the table (interior: centred windows).
template <class Truth>
Errors compare(const PreciseEphemeris& pe, SatId sat, const GpsTime& first, double spacing, int from, int to,
               Truth truth) {
  Errors e;
  for (int k = from; k < to; ++k) {
    for (double f : {0.13, 0.37, 0.5, 0.81}) {
      const GpsTime t = first + (k + f) * spacing;
      const auto s = pe.satelliteState(sat, t);
      EXPECT_TRUE(s.has_value()) << t.toString();
      if (!s) continue;
      const SatelliteState tr = truth(t);
      e.pos = std::max(e.pos, (s->position - tr.position).norm());
      e.vel = std::max(e.vel, (s->velocity - tr.velocity).norm());
      e.clk = std::max(e.clk, std::fabs(s->clockBias - tr.clockBias));
      e.drift = std::max(e.drift, std::fabs(s->clockDrift - tr.clockDrift));
      // The relativistic part: precise clock minus the product clock (linear between the two
      // bracketing file samples) must be -2 r.v/c^2 of the true state.
      const GpsTime t0 = first + k * spacing, t1 = first + (k + 1) * spacing;
      const double c0 = productClock(truth(t0)), c1 = productClock(truth(t1));
      const double fileClock = c0 + (c1 - c0) * f;
      e.rel = std::max(e.rel, std::fabs((s->clockBias - fileClock) - (-2.0 * tr.position.dot(tr.velocity) / kC2)));
      ++e.n;
    }
  }
  return e;
}

}  // namespace

TEST(PreciseEphemeris, GpsKeplerTruthAt900And300Seconds) {
  const KeplerEphemeris& eph = gpsRecord();
  auto truth = [&](const GpsTime& t) { return keplerSatelliteState(eph, t); };
  for (double spacing : {900.0, 300.0}) {
    const int half = static_cast<int>(3 * 3600 / spacing);  // +-3 h of nodes
    PreciseEphemeris pe;
    pe.add(sampled(eph.sat, eph.toe, spacing, half, truth));
    const GpsTime first = eph.toe - half * spacing;
    // Interior (the 11-node window centred on t): nodes 5 .. 2*half-5.
    const Errors e = compare(pe, eph.sat, first, spacing, 5, 2 * half - 5, truth);
    // Edges (window clamped to the data, t in the first/last node intervals).
    const Errors edge0 = compare(pe, eph.sat, first, spacing, 0, 1, truth);
    const Errors edge1 = compare(pe, eph.sat, first, spacing, 2 * half - 1, 2 * half, truth);
    std::printf("%s %4.0f s nodes: %d interior points, max |dr| %.2e m, |dv| %.2e m/s, |dclk| %.2e s, "
                "|ddrift| %.2e s/s, relativistic term %.2e s; edge intervals |dr| %.2e / %.2e m\n",
                eph.sat.str().c_str(), spacing, e.n, e.pos, e.vel, e.clk, e.drift, e.rel, edge0.pos, edge1.pos);
    // Measured (first GPS record of base.nav, G05, Nagoya 2024-06; 11-node windows, interior):
    //   900 s: |dr| 1.9e-5 m, |dv| 6.3e-8 m/s, |dclk| 5.5e-13 s, |ddrift| 1.8e-15 s/s, rel. 2e-17 s
    //   300 s: |dr| 4.0e-8 m, |dv| 1.2e-10 m/s, |dclk| 6.2e-14 s, |ddrift| 6.1e-16 s/s, rel. 4e-20 s
    //   (edge intervals, window clamped to the data: 1.6e-3 m at 900 s, 5e-8 m at 300 s; not asserted)
    EXPECT_LT(e.pos, spacing == 900.0 ? 0.01 : 0.001);
    EXPECT_LT(e.vel, 1e-4);
    EXPECT_LT(e.clk, 1e-11);
    EXPECT_LT(e.drift, 1e-13);
    EXPECT_LT(e.rel, 1e-13);
    // The relativistic term is far above the tolerances (so restoring it is really tested): for
    // this record it reaches several ns within the table.
    double maxRel = 0.0;
    for (int k = -half; k <= half; ++k) {
      const SatelliteState tr = truth(eph.toe + k * spacing);
      maxRel = std::max(maxRel, std::fabs(2.0 * tr.position.dot(tr.velocity) / kC2));
    }
    std::printf("  max |2 r.v/c^2| over the table %.2e s\n", maxRel);
    EXPECT_GT(maxRel, 1e-10);
    const auto s = pe.satelliteState(eph.sat, eph.toe + 0.37 * spacing);
    ASSERT_TRUE(s);
    EXPECT_TRUE(s->precise);
    EXPECT_EQ(s->accuracy, 0.032);  // 2^5 mm
  }
}

TEST(PreciseEphemeris, GlonassIntegratedTruthAt900Seconds) {
  ASSERT_FALSE(nagoya().glonass.empty());
  const GlonassEphemeris& eph = nagoya().glonass.front();
  auto truth = [&](const GpsTime& t) { return glonassSatelliteState(eph, t); };
  const double spacing = 900.0;
  const int half = 12;
  PreciseEphemeris pe;
  pe.add(sampled(eph.sat, eph.toe, spacing, half, truth));
  const Errors e = compare(pe, eph.sat, eph.toe - half * spacing, spacing, 5, 2 * half - 5, truth);
  std::printf("%s 900 s nodes: %d points, max |dr| %.2e m, |dv| %.2e m/s, |dclk| %.2e s, relativistic %.2e s\n",
              eph.sat.str().c_str(), e.n, e.pos, e.vel, e.clk, e.rel);
  // Measured (R01 of base.nav): |dr| 2.5e-5 m, |dv| 1.0e-7 m/s, |dclk| 2.1e-12 s, rel. 3e-17 s.
  EXPECT_LT(e.pos, 0.01);
  EXPECT_LT(e.vel, 1e-4);
  EXPECT_LT(e.clk, 1e-11);
  EXPECT_LT(e.rel, 1e-13);
}

TEST(PreciseEphemeris, VelocityRecordsAndClockFilesAreUsed) {
  const KeplerEphemeris& eph = gpsRecord();
  auto truth = [&](const GpsTime& t) { return keplerSatelliteState(eph, t); };
  Sp3Data d = sampled(eph.sat, eph.toe, 900.0, 12, truth);
  // V records: interpolated instead of the derivative of the position polynomial.
  for (auto& ep : d.epochs) ep.records[0].velocity = truth(ep.time).velocity;
  PreciseEphemeris pe;
  pe.add(d);
  const GpsTime t = eph.toe + 0.37 * 900.0;
  auto s = pe.satelliteState(eph.sat, t);
  ASSERT_TRUE(s);
  EXPECT_LT((s->velocity - truth(t).velocity).norm(), 1e-6);

  // A clock file with an offset of 1 us everywhere takes precedence over the SP3 clocks.
  ClockData clk;
  std::vector<ClockRecord> recs;
  for (int k = -20; k <= 20; ++k) {
    const GpsTime tk = eph.toe + 30.0 * k;
    recs.push_back({tk, productClock(truth(tk)) + 1e-6, 0.0});
  }
  clk.satellites.push_back({eph.sat, recs});
  pe.add(clk);
  s = pe.satelliteState(eph.sat, t);
  ASSERT_TRUE(s);
  EXPECT_NEAR(s->clockBias - truth(t).clockBias, 1e-6, 1e-12);
  // Outside the clock file the SP3 clocks are used again.
  s = pe.satelliteState(eph.sat, eph.toe + 3000.0);
  ASSERT_TRUE(s);
  EXPECT_NEAR(s->clockBias, truth(eph.toe + 3000.0).clockBias, 1e-11);
}

TEST(PreciseEphemeris, CoverageSpanGapsAndMissingNodes) {
  const KeplerEphemeris& eph = gpsRecord();
  auto truth = [&](const GpsTime& t) { return keplerSatelliteState(eph, t); };
  const Sp3Data full = sampled(eph.sat, eph.toe, 900.0, 12, truth);  // 25 nodes
  const GpsTime first = full.epochs.front().time, last = full.epochs.back().time;
  {
    PreciseEphemeris pe;
    pe.add(full);
    EXPECT_TRUE(pe.hasOrbit(eph.sat));
    EXPECT_FALSE(pe.hasOrbit(SatId(System::Galileo, 1)));
    EXPECT_EQ(pe.satellites(), std::vector<SatId>{eph.sat});
    EXPECT_EQ(pe.span().first, first);
    EXPECT_EQ(pe.span().second, last);
    EXPECT_TRUE(pe.satelliteState(eph.sat, first));
    EXPECT_TRUE(pe.satelliteState(eph.sat, last));
    EXPECT_FALSE(pe.satelliteState(eph.sat, first - 1.0));
    EXPECT_FALSE(pe.satelliteState(eph.sat, last + 1.0));
    EXPECT_FALSE(pe.satelliteState(SatId(System::Galileo, 1), eph.toe));
    // With extrapolation allowed, a little beyond the end is served.
    PreciseEphemeris ex(PreciseEphemerisOptions{10, 330.0, 60.0});
    ex.add(full);
    EXPECT_TRUE(ex.satelliteState(eph.sat, last + 30.0));
    EXPECT_FALSE(ex.satelliteState(eph.sat, last + 90.0));
  }
  {
    // Data built in memory without the ## interval: the epoch spacing is used instead (SP3 clocks
    // at 900 s are still interpolated, a missing epoch is still a gap).
    Sp3Data noInterval = full;
    noInterval.interval = 0.0;
    noInterval.epochs.erase(noInterval.epochs.begin() + 12);
    PreciseEphemeris pe;
    pe.add(noInterval);
    const GpsTime t = first + 5.37 * 900.0;
    const auto s = pe.satelliteState(eph.sat, t);
    ASSERT_TRUE(s);
    EXPECT_NEAR(s->clockBias, truth(t).clockBias, 1e-11);
    EXPECT_FALSE(pe.satelliteState(eph.sat, first + 11.5 * 900.0));
  }
  {
    // Data gap: node 12 removed. Windows containing the gap are unavailable, far ones are not.
    Sp3Data gap = full;
    gap.epochs.erase(gap.epochs.begin() + 12);
    PreciseEphemeris pe;
    pe.add(gap);
    EXPECT_FALSE(pe.satelliteState(eph.sat, first + 11.5 * 900.0));
    EXPECT_FALSE(pe.satelliteState(eph.sat, first + 12.5 * 900.0));
    EXPECT_TRUE(pe.satelliteState(eph.sat, first + 0.5 * 900.0));
    EXPECT_TRUE(pe.satelliteState(eph.sat, first + 23.5 * 900.0));
  }
  {
    // NaN position at node 12: unavailable while node 12 is in the window.
    Sp3Data nan = full;
    nan.epochs[12].records[0].position.setConstant(std::numeric_limits<double>::quiet_NaN());
    PreciseEphemeris pe;
    pe.add(nan);
    EXPECT_FALSE(pe.satelliteState(eph.sat, first + 12.2 * 900.0));
    EXPECT_FALSE(pe.satelliteState(eph.sat, first + 8.5 * 900.0));
    EXPECT_TRUE(pe.satelliteState(eph.sat, first + 1.5 * 900.0));
  }
  {
    // Missing SP3 clock at node 12 (and no clock file): the two intervals around it are not covered.
    Sp3Data noClock = full;
    noClock.epochs[12].records[0].clock = std::numeric_limits<double>::quiet_NaN();
    PreciseEphemeris pe;
    pe.add(noClock);
    EXPECT_FALSE(pe.satelliteState(eph.sat, first + 11.5 * 900.0));
    EXPECT_FALSE(pe.satelliteState(eph.sat, first + 12.5 * 900.0));
    EXPECT_TRUE(pe.satelliteState(eph.sat, first + 10.5 * 900.0));
  }
  {
    // Clock file with a gap larger than maxClockGap (330 s) and no SP3 clocks.
    Sp3Data noClocks = full;
    for (auto& ep : noClocks.epochs) ep.records[0].clock = std::numeric_limits<double>::quiet_NaN();
    ClockData clk;
    clk.satellites.push_back({eph.sat, {{eph.toe, 1e-4, 0}, {eph.toe + 300.0, 1e-4, 0}, {eph.toe + 900.0, 1e-4, 0}}});
    PreciseEphemeris pe;
    pe.add(noClocks);
    pe.add(clk);
    EXPECT_TRUE(pe.satelliteState(eph.sat, eph.toe + 100.0));
    EXPECT_FALSE(pe.satelliteState(eph.sat, eph.toe + 500.0));
    EXPECT_FALSE(pe.satelliteState(eph.sat, eph.toe - 100.0));
  }
}

TEST(PreciseEphemeris, ConsecutiveFilesMergeAndLaterDuplicatesWin) {
  const KeplerEphemeris& eph = gpsRecord();
  auto truth = [&](const GpsTime& t) { return keplerSatelliteState(eph, t); };
  const Sp3Data full = sampled(eph.sat, eph.toe, 900.0, 12, truth);
  Sp3Data a = full, b = full;
  a.epochs.erase(a.epochs.begin() + 14, a.epochs.end());  // nodes 0..13
  b.epochs.erase(b.epochs.begin(), b.epochs.begin() + 13);  // nodes 13..24 (13 duplicated)
  // The earlier file's copy of the shared epoch is wrong by 1 km; the later one must win.
  a.epochs.back().records[0].position.x() += 1000.0;
  PreciseEphemeris pe;
  pe.add(a);
  pe.add(b);
  const GpsTime t = full.epochs[13].time + 0.4 * 900.0;
  const auto s = pe.satelliteState(eph.sat, t);
  ASSERT_TRUE(s);
  EXPECT_LT((s->position - truth(t).position).norm(), 0.01);
}

// Lagrange interpolation of degree n - 1 reproduces any polynomial of that degree exactly, with
// its derivatives: an SP3 table sampled from a degree-10 polynomial orbit (11-node windows, the
// default order) and a linear clock gives at off-node times the polynomial's position and
// velocity, and the clock drift including the relativistic rate -2 (v.v + r.a)/c^2 built from the
// second derivative; with SP3 velocity records (the polynomial's derivative) the velocity comes
// from them and the acceleration from their derivative.
TEST(PreciseEphemeris, PolynomialOrbitIsReproducedWithItsDerivatives) {
  const SatId sat{System::Gps, 7};
  const GpsTime t0 = GpsTime::fromWeekTow(2320, 172800.0);
  constexpr double h = 300.0;
  constexpr int half = 15, degree = 10;
  // r(t) = sum_k c_k u^k, u = (t - t0) / (half h): every term below 2.6e7 m over the table.
  std::array<Eigen::Vector3d, degree + 1> c;
  for (int k = 0; k <= degree; ++k)
    c[static_cast<std::size_t>(k)] = Eigen::Vector3d(2.6e7 * std::cos(0.7 * k), -1.9e7 * std::sin(1.3 * k + 0.2), 1.1e7 * std::cos(2.1 * k + 0.5)) / (k + 1.0);
  const double s = half * h;
  auto at = [&](const GpsTime& t, int derivative) {
    const double u = (t - t0) / s;
    Eigen::Vector3d r = Eigen::Vector3d::Zero();
    for (int k = derivative; k <= degree; ++k) {
      double f = 1.0;
      for (int m = 0; m < derivative; ++m) f *= k - m;
      r += c[static_cast<std::size_t>(k)] * f * std::pow(u, k - derivative) / std::pow(s, derivative);
    }
    return r;
  };
  constexpr double clock0 = 1.5e-4, drift = 2.0e-11;
  for (const bool velocityRecords : {false, true}) {
    Sp3Data d;
    d.interval = h;
    d.satellites = {sat};
    d.accuracyExponent = {3};
    for (int k = -half; k <= half; ++k) {
      const GpsTime t = t0 + k * h;
      Sp3Record r;
      r.sat = sat;
      r.position = at(t, 0);
      if (velocityRecords) r.velocity = at(t, 1);
      r.clock = clock0 + drift * (t - t0);
      d.epochs.push_back({t, {r}});
    }
    PreciseEphemeris pe;
    pe.add(d);
    double dr = 0.0, dv = 0.0, dd = 0.0;
    for (int k = -half + 5; k < half - 5; ++k) {
      for (double f : {0.0, 0.21, 0.5, 0.77}) {
        const GpsTime t = t0 + (k + f) * h;
        const auto st = pe.satelliteState(sat, t);
        ASSERT_TRUE(st.has_value());
        const Eigen::Vector3d r = at(t, 0), v = at(t, 1), a = at(t, 2);
        dr = std::max(dr, (st->position - r).norm());
        dv = std::max(dv, (st->velocity - v).norm());
        dd = std::max(dd, std::fabs(st->clockDrift - (drift - 2.0 * (v.squaredNorm() + r.dot(a)) / kC2)));
      }
    }
    std::printf("degree-%d polynomial orbit, %s: max |dr| %.2e m, |dv| %.2e m/s, |ddrift| %.2e s/s\n", degree,
                velocityRecords ? "with V records" : "positions only", dr, dv, dd);
    // Rounding only (positions of 1e7 m). Measured: |dr| 2.3e-8 m, |dv| 8.2e-11 m/s (1.9e-12 with V
    // records), |ddrift| 4e-22 s/s, against a relativistic rate of ~1e-7 s/s here.
    EXPECT_LT(dr, 1e-6);
    EXPECT_LT(dv, 1e-9);
    EXPECT_LT(dd, 1e-19);
  }
}
