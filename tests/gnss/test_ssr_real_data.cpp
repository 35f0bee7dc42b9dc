// SSR corrections of a real correction stream: tests/data/rtcm/cssrlib_idd2023229c.rtc
// (cssrlib-data, MIT; 2023-08-17, about an hour of GPS and Galileo broadcast ephemerides 1019/1046
// with RTCM SSR 1059/1060 and 1242/1243 of one provider). There is no precise product of that day
// in the repository, so the checks are those that need none:
//  - every orbit correction names a broadcast record that the same stream delivered (issue of
//    data matching, EphemerisStore::ssrState finds it);
//  - the corrections have the size of broadcast orbit/clock errors (decimetres to a few metres);
//  - across a change of issue of data the corrected orbit and clock stay continuous while the
//    broadcast ones jump: the old record with its last correction and the new record with the
//    first correction for it agree to centimetres at the same instant. A wrong sign of the orbit
//    or clock correction, a wrong radial/along/cross frame, a wrong reference time or a mismatched
//    record shows up there as a jump of the size of the correction itself.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <map>
#include <string>
#include <variant>
#include <vector>

#include "gvins/base/constants.hpp"
#include "gvins/ephemeris/ephemeris_store.hpp"
#include "gvins/ephemeris/ssr_corrections.hpp"
#include "gvins/rtcm/decoder.hpp"

using namespace gvins;

namespace {

struct Stream {
  EphemerisStore nav;
  std::vector<SsrMessage> ssr;
};

const Stream& stream() {
  static const Stream s = [] {
    Stream out;
    const std::string path = std::string(GVINS_TEST_DATA) + "/rtcm/cssrlib_idd2023229c.rtc";
    std::ifstream f(path, std::ios::binary);
    EXPECT_TRUE(f) << path;
    const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    rtcm::DecoderOptions o;
    o.referenceTime = GpsTime::fromWeekTow(2275, 352752.0);  // 2023-08-17 01:59 GPST
    rtcm::Decoder d(o);
    d.feed(bytes);
    d.finish();
    while (auto m = d.poll()) {
      if (auto* k = std::get_if<KeplerEphemeris>(&*m)) out.nav.add(*k);
      else if (auto* msg = std::get_if<SsrMessage>(&*m)) out.ssr.push_back(*msg);
    }
    EXPECT_EQ(d.stats().malformed, 0);
    return out;
  }();
  return s;
}

const KeplerEphemeris* recordWithIod(const EphemerisStore& nav, SatId sat, int iod, const GpsTime& t) {
  const KeplerEphemeris* best = nullptr;
  for (const auto& e : nav.keplerRecords(sat))
    if (ssrIssueOfData(e) == iod && (!best || std::abs(t - e.toe) < std::abs(t - best->toe))) best = &e;
  return best;
}

struct Timed {
  SsrHeader header;
  SsrOrbitCorrection orbit;
  SsrClockCorrection clock;
};

}  // namespace

TEST(SsrRealData, CorrectionsNameRecordsOfTheStreamAndHaveBroadcastErrorSizes) {
  const Stream& s = stream();
  ASSERT_GT(s.ssr.size(), 700u);
  int orbits = 0, matched = 0, applied = 0;
  double sumRadial2 = 0, sumAlong2 = 0, sumCross2 = 0, maxOrbit = 0;
  std::map<System, int> perSystem;
  for (const SsrMessage& m : s.ssr) {
    if (m.header.kind != SsrKind::kCombined) continue;
    for (const SsrSatellite& sat : m.satellites) {
      ASSERT_TRUE(sat.orbit && sat.clock);
      // The service corrects unhealthy satellites too (G11 and G21 here, G21 by up to 18 m); the
      // store does not use them.
      EphemerisSelection all;
      all.allowUnhealthy = true;
      const auto b = s.nav.satelliteState(sat.sat, m.header.epoch, all);
      if (!b || !b->healthy) continue;
      ++orbits;
      ++perSystem[sat.sat.system];
      if (recordWithIod(s.nav, sat.sat, sat.orbit->issueOfData, m.header.epoch)) ++matched;
      sumRadial2 += std::pow(sat.orbit->rac.x(), 2);
      sumAlong2 += std::pow(sat.orbit->rac.y(), 2);
      sumCross2 += std::pow(sat.orbit->rac.z(), 2);
      maxOrbit = std::max(maxOrbit, sat.orbit->rac.norm());
    }
  }
  EphemerisStore nav = s.nav;
  for (const SsrMessage& m : s.ssr) nav.addSsr(m);
  // Every 60 s over the stream: SSR states for the satellites that have corrections.
  const GpsTime first = s.ssr.front().header.epoch, last = s.ssr.back().header.epoch;
  int asked = 0;
  for (GpsTime t = first + 10.0; t < last; t += 60.0)
    for (SatId sat : nav.satellites()) {
      if (!nav.ssr().select(sat, t) || !s.nav.satelliteState(sat, t)) continue;  // healthy ones
      ++asked;
      const auto st = nav.satelliteState(sat, t);
      if (st && st->ssr) ++applied;
    }
  const double n = std::max(orbits, 1);
  std::printf("SSR real stream: %d satellite corrections (G %d, E %d), %d name a record of the stream; "
              "RMS radial %.3f along %.3f cross %.3f m, largest %.3f m; SSR states %d of %d asked\n",
              orbits, perSystem[System::Gps], perSystem[System::Galileo], matched, std::sqrt(sumRadial2 / n),
              std::sqrt(sumAlong2 / n), std::sqrt(sumCross2 / n), maxOrbit, applied, asked);
  EXPECT_GT(perSystem[System::Gps], 1000);
  EXPECT_GT(perSystem[System::Galileo], 1000);
  EXPECT_GT(matched, 0.97 * orbits);
  EXPECT_GT(applied, 0.97 * asked);
  EXPECT_GT(asked, 500);
  // Broadcast orbit errors: decimetres, radial smallest. Measured (healthy satellites): RMS radial
  // 0.150, along 0.673, cross 0.502 m, largest 2.64 m; every correction but one names a record.
  EXPECT_LT(std::sqrt(sumRadial2 / n), 0.3);
  EXPECT_LT(std::sqrt(sumAlong2 / n), 1.5);
  EXPECT_LT(maxOrbit, 5.0);
  EXPECT_GT(std::sqrt((sumRadial2 + sumAlong2 + sumCross2) / n), 0.02);  // not all zero
}

TEST(SsrRealData, CorrectedOrbitAndClockAreContinuousAcrossIssueOfDataChanges) {
  const Stream& s = stream();
  std::map<std::uint32_t, Timed> lastOf;  // by satellite
  int changes = 0;
  double sumOrbit2 = 0, sumClock2 = 0, sumBroadcastOrbit2 = 0, sumBroadcastClock2 = 0;
  double worstOrbit = 0, worstClock = 0;
  constexpr double kC = constants::kSpeedOfLight;
  for (const SsrMessage& m : s.ssr) {
    if (m.header.kind != SsrKind::kCombined) continue;
    for (const SsrSatellite& sat : m.satellites) {
      const std::uint32_t key = static_cast<std::uint32_t>(satIndex(sat.sat));
      const Timed now{m.header, *sat.orbit, *sat.clock};
      auto it = lastOf.find(key);
      if (it != lastOf.end() && it->second.orbit.issueOfData != now.orbit.issueOfData &&
          m.header.epoch - it->second.header.epoch <= 30.0) {  // consecutive messages (10 s apart here)
        const Timed& old = it->second;
        const GpsTime t = m.header.epoch + 0.5 * m.header.updateInterval;  // new reference time
        const KeplerEphemeris* ro = recordWithIod(s.nav, sat.sat, old.orbit.issueOfData, t);
        const KeplerEphemeris* rn = recordWithIod(s.nav, sat.sat, now.orbit.issueOfData, t);
        if (ro && rn) {
          const SatelliteState bo = keplerSatelliteState(*ro, t), bn = keplerSatelliteState(*rn, t);
          SsrSelection so{old.header, old.orbit, old.header, old.clock, {}, {}};
          SsrSelection sn{now.header, now.orbit, now.header, now.clock, {}, {}};
          const auto co = applySsr(bo, so, t), cn = applySsr(bn, sn, t);
          ASSERT_TRUE(co && cn);
          const double dOrbit = (co->position - cn->position).norm();
          const double dClock = std::abs(co->clockBias - cn->clockBias) * kC;
          sumOrbit2 += dOrbit * dOrbit;
          sumClock2 += dClock * dClock;
          sumBroadcastOrbit2 += (bo.position - bn.position).squaredNorm();
          sumBroadcastClock2 += std::pow((bo.clockBias - bn.clockBias) * kC, 2);
          worstOrbit = std::max(worstOrbit, dOrbit);
          worstClock = std::max(worstClock, dClock);
          ++changes;
        }
      }
      lastOf[key] = now;
    }
  }
  ASSERT_GT(changes, 20);
  const double rmsOrbit = std::sqrt(sumOrbit2 / changes), rmsClock = std::sqrt(sumClock2 / changes);
  const double rmsBO = std::sqrt(sumBroadcastOrbit2 / changes), rmsBC = std::sqrt(sumBroadcastClock2 / changes);
  std::printf("IOD changes: %d; corrected orbit jump RMS %.3f m (worst %.3f), clock %.3f m (worst %.3f); "
              "broadcast jumps orbit %.3f m, clock %.3f m\n",
              changes, rmsOrbit, worstOrbit, rmsClock, worstClock, rmsBO, rmsBC);
  // Measured: 127 changes; corrected jumps orbit 0.4 mm RMS (worst 1 mm), clock 6 mm (worst
  // 18 mm) where the broadcast orbits jump 0.215 m and the clocks 0.049 m.
  EXPECT_LT(rmsOrbit, 0.01);
  EXPECT_LT(rmsClock, 0.02);
  EXPECT_LT(rmsOrbit, 0.05 * rmsBO);
  EXPECT_LT(rmsClock, 0.3 * rmsBC);
}
