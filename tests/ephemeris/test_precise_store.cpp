// EphemerisStore with precise products: the precise state wins where the products cover a
// satellite (flagged SatelliteState::precise), the broadcast record serves everything else, and
// group delays keep coming from the broadcast records.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>

#include "gvins/base/constants.hpp"
#include "gvins/ephemeris/bias_sinex.hpp"
#include "gvins/ephemeris/broadcast_sp3.hpp"
#include "gvins/ephemeris/ephemeris_store.hpp"
#include "gvins/ephemeris/precise_ephemeris.hpp"
#include "gvins/ephemeris/rinex_nav.hpp"
#include "gvins/ephemeris/sp3.hpp"
#include "nagoya_recording.hpp"

using namespace gvins;

namespace {

const std::string kNagoya = std::string(GVINS_TEST_DATA) + "/gnss/nagoya_static_2024/base.nav.gz";

// SP3 data of one satellite: its broadcast orbit shifted by `offset` (m) and its broadcast clock
// (without the relativistic term, as SP3 clocks are) shifted by `clockOffset` (s), every 300 s
// over [from, to].
Sp3Data shiftedProducts(const EphemerisStore& nav, SatId sat, const GpsTime& from, const GpsTime& to,
                        const Eigen::Vector3d& offset, double clockOffset) {
  Sp3Data d = broadcastSp3(nav, from, to, 300.0, {sat});
  d.accuracyExponent = {4};
  for (Sp3Epoch& ep : d.epochs) {
    Sp3Record& r = ep.records.front();
    EXPECT_TRUE(r.position.allFinite() && std::isfinite(r.clock));  // a broadcast state at every node
    r.position += offset;
    r.clock += clockOffset;
  }
  return d;
}

}  // namespace

TEST(PreciseStore, PreciseStatesReplaceBroadcastWhereTheyCover) {
  EphemerisStore nav;
  nav.add(readRinexNav(kNagoya));
  const SatId g = SatId::parse("G05").value(), e = SatId::parse("E04").value();
  const GpsTime t0 = gvins::test::nagoyaTime(8, 20);
  ASSERT_TRUE(nav.satelliteState(g, t0));
  ASSERT_TRUE(nav.satelliteState(e, t0));
  const Eigen::Vector3d offset(1.0, -2.0, 0.5);
  auto precise = std::make_shared<PreciseEphemeris>();
  precise->add(shiftedProducts(nav, g, t0 - 1200.0, t0 + 3600.0, offset, 1e-8));
  const std::uint64_t rev = nav.revision();
  nav.setPrecise(precise);
  EXPECT_NE(nav.revision(), rev);

  // Covered: the precise state, 1 m / 2 m / 0.5 m and 10 ns off the broadcast one.
  const GpsTime t = t0 + 123.4;
  EphemerisStore broadcastOnly;
  broadcastOnly.add(readRinexNav(kNagoya));
  const auto b = broadcastOnly.satelliteState(g, t);
  const auto p = nav.satelliteState(g, t);
  ASSERT_TRUE(b && p);
  EXPECT_TRUE(p->precise);
  EXPECT_FALSE(b->precise);
  EXPECT_LT((p->position - b->position - offset).norm(), 0.01);  // 300 s nodes of a Kepler orbit
  EXPECT_NEAR(p->clockBias - b->clockBias, 1e-8, 1e-11);          // relativistic term restored
  EXPECT_LT((p->velocity - b->velocity).norm(), 1e-3);
  // Not in the products, or outside their span: the broadcast record.
  const auto pe = nav.satelliteState(e, t);
  ASSERT_TRUE(pe);
  EXPECT_FALSE(pe->precise);
  const auto late = nav.satelliteState(g, t0 + 3 * 3600.0);
  ASSERT_TRUE(late);
  EXPECT_FALSE(late->precise);
  // Group delays still from the broadcast record.
  EXPECT_EQ(nav.groupDelay(g, ObsCode{'1', 'C'}, t), broadcastOnly.groupDelay(g, ObsCode{'1', 'C'}, t));
  EXPECT_NE(nav.groupDelay(g, ObsCode{'1', 'C'}, t), 0.0);
  // Switching the products off again.
  nav.setPrecise(nullptr);
  EXPECT_FALSE(nav.satelliteState(g, t)->precise);
}

// broadcastSp3 → PreciseEphemeris gives the broadcast states back for GPS, whose record stays the
// same over the hour (300 s nodes: interpolation well below a millimetre; the relativistic term
// restored). Where the selected record changes within the interpolation window the samples jump
// by the record-to-record difference (measured at 08:28:31: GLONASS 6-24 cm, 30-min records;
// Galileo 3-18 mm, 10-min records).
TEST(PreciseStore, BroadcastSampledAsSp3ReadsBack) {
  EphemerisStore nav;
  nav.add(readRinexNav(kNagoya));
  const GpsTime t0 = gvins::test::nagoyaTime(8, 0);
  const Sp3Data d = broadcastSp3(nav, t0, t0 + 3600.0, 300.0);
  EXPECT_EQ(d.satellites.size(), nav.satellites().size());
  EXPECT_EQ(d.epochs.size(), 13u);
  PreciseEphemeris p;
  p.add(d);
  int compared = 0;
  for (SatId s : nav.satellites()) {
    if (s.system != System::Gps) continue;
    const GpsTime t = t0 + 1711.3;
    const auto b = nav.satelliteState(s, t);
    const auto q = p.satelliteState(s, t);
    if (!b || !q) continue;
    EXPECT_LT((q->position - b->position).norm(), 1e-3) << s.str();
    EXPECT_NEAR(q->clockBias, b->clockBias, 1e-12) << s.str();
    ++compared;
  }
  EXPECT_GT(compared, 8);
  EXPECT_THROW(broadcastSp3(nav, t0, t0 - 1.0, 300.0), std::invalid_argument);
}

// codeDelay: the OSB of the code biases for a precise state that has one, the broadcast group
// delay for a broadcast state or a signal without an OSB.
TEST(PreciseStore, CodeDelayTakesTheOsbOnlyWithPreciseStates) {
  EphemerisStore nav;
  nav.add(readRinexNav(kNagoya));
  const SatId g = SatId::parse("G05").value();
  const GpsTime t = gvins::test::nagoyaTime(8, 50);
  auto precise = std::make_shared<PreciseEphemeris>();
  precise->add(broadcastSp3(nav, t - 3000.0, t + 3000.0, 300.0, {g}));
  auto biases = std::make_shared<BiasSinexData>();
  BiasEntry b;
  b.satellite = g;
  b.obs1 = ObsCode('1', 'C');
  b.start = t - 600.0;
  b.end = t + 600.0;
  b.unit = "ns";
  b.value = 4.5e-9;
  biases->entries.push_back(b);
  const double tgd = nav.groupDelay(g, ObsCode('1', 'C'), t);
  const SatelliteState broadcast = *nav.satelliteState(g, t);
  nav.setCodeBiases(biases);
  EXPECT_DOUBLE_EQ(nav.codeDelay(broadcast, g, ObsCode('1', 'C'), t), tgd);
  nav.setPrecise(precise);
  const SatelliteState st = *nav.satelliteState(g, t);
  ASSERT_TRUE(st.precise);
  EXPECT_DOUBLE_EQ(nav.codeDelay(st, g, ObsCode('1', 'C'), t), 4.5e-9);
  EXPECT_DOUBLE_EQ(nav.codeDelay(st, g, ObsCode('2', 'W'), t), nav.groupDelay(g, ObsCode('2', 'W'), t));
  EXPECT_DOUBLE_EQ(nav.codeDelay(st, g, ObsCode('1', 'C'), t + 900.0), nav.groupDelay(g, ObsCode('1', 'C'), t + 900.0));
}
