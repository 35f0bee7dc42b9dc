// Ephemeris cache: the record it returns is the store's selection at every time asked, on real
// navigation files (every satellite, a dense time grid, times next to every rule edge, several
// policies), and it follows records added to the store.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <string>
#include <vector>

#include "gvins/ephemeris/ephemeris_cache.hpp"
#include "gvins/ephemeris/rinex_nav.hpp"

using namespace gvins;

namespace {

const std::string kData = GVINS_TEST_DATA;
const std::vector<std::string> kFiles = {
    kData + "/gnss/nagoya_static_2024/base.nav.gz",
    kData + "/gnss/kamakura_static_2021/SEPT078M.21P.gz",
    kData + "/gnss/kamakura_static_2021/30340780.21q.gz",
    kData + "/gnss/geonet_0759_3040_2005/07590920.05n.gz",
    kData + "/gnss/brd400dlr_2022_rinex4/BRD400DLR_S_20222780000_extract.rnx.gz",
};

std::vector<EphemerisSelection> policies() {
  EphemerisSelection fnav;
  fnav.preferGalileoInav = false;
  EphemerisSelection noFuture;
  noFuture.futureTolerance = -1.0;
  EphemerisSelection unhealthy;
  unhealthy.allowUnhealthy = true;
  EphemerisSelection shortFuture;
  shortFuture.futureTolerance = 600.0;
  return {EphemerisSelection{}, fnav, noFuture, unhealthy, shortFuture};
}

// Times next to every edge of the selection rules of a satellite's records (windows, transmission
// times, future tolerance, half-way points), on both sides and on the edge itself.
std::vector<GpsTime> edgeTimes(const EphemerisStore& store, SatId sat, const EphemerisSelection& p) {
  std::vector<GpsTime> edges;
  auto around = [&](const GpsTime& t) {
    for (double d : {-2.0, -1e-3, -5e-4, 0.0, 5e-4, 1e-3, 2.0}) edges.push_back(t + d);
  };
  auto addRecord = [&](const GpsTime& toe, const GpsTime& ttr, double window) {
    around(toe - window);
    around(toe + window);
    around(ttr);
    around(toe);
    if (p.futureTolerance >= 0.0) {
      around(toe - p.futureTolerance);
      around(toe + p.futureTolerance);
    }
  };
  std::vector<GpsTime> toes;
  if (sat.system == System::Glonass) {
    for (const auto& e : store.glonassRecords(sat)) {
      addRecord(e.toe, e.tof, EphemerisStore::validityHalfWindow(e));
      toes.push_back(e.toe);
    }
  } else {
    for (const auto& e : store.keplerRecords(sat)) {
      addRecord(e.toe, e.ttr, EphemerisStore::validityHalfWindow(e));
      toes.push_back(e.toe);
    }
  }
  for (std::size_t i = 0; i + 1 < toes.size(); ++i) {
    for (std::size_t j = i + 1; j < std::min(toes.size(), i + 4); ++j) around(toes[i] + 0.5 * (toes[j] - toes[i]));
  }
  std::sort(edges.begin(), edges.end());
  return edges;
}

const void* direct(const EphemerisStore& store, SatId sat, const GpsTime& t, const EphemerisSelection& p) {
  if (sat.system == System::Glonass) return store.selectGlonass(sat, t, p);
  return store.selectKepler(sat, t, p);
}

const void* cached(EphemerisCache& cache, SatId sat, const GpsTime& t) {
  if (sat.system == System::Glonass) return cache.glonass(sat, t);
  return cache.kepler(sat, t);
}

}  // namespace

TEST(EphemerisCache, SameRecordsAsTheStoreOnRealFiles) {
  long checked = 0, selected = 0;
  for (const auto& file : kFiles) {
    EphemerisStore store;
    store.add(readRinexNav(file));
    for (const auto& p : policies()) {
      EphemerisCache cache(store, p);
      for (SatId sat : store.satellites()) {
        // Times in order, as a processor asks, across the file and a little beyond.
        GpsTime t0, t1;
        if (sat.system == System::Glonass) {
          t0 = store.glonassRecords(sat).front().toe;
          t1 = store.glonassRecords(sat).back().toe;
        } else {
          t0 = store.keplerRecords(sat).front().toe;
          t1 = store.keplerRecords(sat).back().toe;
        }
        for (GpsTime t = t0 - 5000.0; t < t1 + 5000.0; t += 7.3) {
          const void* d = direct(store, sat, t, p);
          ASSERT_EQ(cached(cache, sat, t), d) << file << " " << sat.str() << " " << t.toString(4);
          ++checked;
          selected += d != nullptr;
        }
        // Next to every rule edge, in order and back again.
        const std::vector<GpsTime> edges = edgeTimes(store, sat, p);
        for (const GpsTime& t : edges) {
          ASSERT_EQ(cached(cache, sat, t), direct(store, sat, t, p)) << file << " " << sat.str() << " " << t.toString(4);
          ++checked;
        }
        for (auto it = edges.rbegin(); it != edges.rend(); ++it) {
          ASSERT_EQ(cached(cache, sat, *it), direct(store, sat, *it, p)) << file << " " << sat.str();
          ++checked;
        }
      }
    }
  }
  EXPECT_GT(checked, 1000000);
  EXPECT_GT(selected, checked / 4);  // most of the grid has a record: the comparison is not all nullptr
}

TEST(EphemerisCache, SpanOfAChoiceHoldsTheSameSelection) {
  EphemerisStore store;
  store.add(readRinexNav(kFiles[1]));
  std::mt19937 rng(7);
  int spans = 0;
  for (SatId sat : store.satellites()) {
    if (sat.system == System::Glonass) continue;
    const auto& recs = store.keplerRecords(sat);
    std::uniform_real_distribution<double> u(-3600.0, recs.back().toe - recs.front().toe + 3600.0);
    for (int k = 0; k < 20; ++k) {
      const GpsTime t = recs.front().toe + u(rng);
      const auto c = store.chooseKepler(sat, t);
      EXPECT_EQ(c.record, store.selectKepler(sat, t));
      ASSERT_FALSE(t < c.from || c.until < t);
      // The ends and points inside select the same record.
      EXPECT_EQ(store.selectKepler(sat, c.from), c.record);
      EXPECT_EQ(store.selectKepler(sat, c.until), c.record);
      for (int i = 1; i < 10; ++i) EXPECT_EQ(store.selectKepler(sat, c.from + (c.until - c.from) * i / 10.0), c.record);
      spans += c.until - c.from > 60.0;
    }
  }
  EXPECT_GT(spans, 100);  // spans are minutes long, so a cache hits
}

TEST(EphemerisCache, FollowsRecordsAddedToTheStore) {
  const NavData nav = readRinexNav(kFiles[1]);
  EphemerisStore store;
  // The first GPS satellite with two records of different toe.
  std::vector<KeplerEphemeris> recs;
  for (const auto& a : nav.kepler) {
    for (const auto& b : nav.kepler) {
      if (recs.empty() && a.sat.system == System::Gps && b.sat == a.sat && a.toe < b.toe) recs = {a, b};
    }
  }
  ASSERT_EQ(recs.size(), 2u);
  const SatId sat = recs[0].sat;
  store.add(recs[0]);
  EphemerisCache cache(store);
  const GpsTime t = recs[1].toe;  // nearer to the second record once it is known
  EXPECT_EQ(cache.kepler(sat, t), store.selectKepler(sat, t));
  const std::uint64_t before = store.revision();
  store.add(recs[1]);
  EXPECT_NE(store.revision(), before);
  const KeplerEphemeris* now = store.selectKepler(sat, t);
  ASSERT_NE(now, nullptr);
  EXPECT_EQ(now->toe, recs[1].toe);
  EXPECT_EQ(cache.kepler(sat, t), now);
  store.add(recs[1]);  // a duplicate changes nothing
  EXPECT_EQ(cache.kepler(sat, t), now);
}
