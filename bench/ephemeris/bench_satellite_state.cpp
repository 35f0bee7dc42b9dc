// Satellite state computation speed: ns per satellite and system (Keplerian for GPS, Galileo,
// BeiDou MEO/IGSO and GEO, QZSS; GLONASS RK4 for several distances from tb), the full store path
// (record selection + state), precise-orbit interpolation (11-node Lagrange, SP3 positions with and
// without velocity records) and RINEX navigation parsing.
#include <benchmark/benchmark.h>

#include <string>
#include <vector>

#include "gvins/ephemeris/broadcast_sp3.hpp"
#include "gvins/ephemeris/ephemeris_store.hpp"
#include "gvins/ephemeris/precise_ephemeris.hpp"

using namespace gvins;

namespace {

const std::string kNav = std::string(GVINS_TEST_DATA) + "/gnss/nagoya_static_2024/base.nav.gz";

const NavData& nav() {
  static const NavData n = readRinexNav(kNav);
  return n;
}

std::vector<KeplerEphemeris> records(System s, int geo) {
  std::vector<KeplerEphemeris> out;
  for (const auto& e : nav().kepler) {
    if (e.sat.system != s) continue;
    if (geo >= 0 && static_cast<int>(isBeiDouGeo(e.sat)) != geo) continue;
    out.push_back(e);
  }
  return out;
}

void keplerBench(benchmark::State& state, System s, int geo) {
  const auto recs = records(s, geo);
  if (recs.empty()) {
    state.SkipWithError("no records");
    return;
  }
  std::size_t i = 0;
  double dt = 0.0;
  for (auto _ : state) {
    const KeplerEphemeris& e = recs[i];
    benchmark::DoNotOptimize(keplerSatelliteState(e, e.toe + 900.0 + dt));
    if (++i == recs.size()) i = 0;
    dt += 1e-3;
  }
  state.SetItemsProcessed(state.iterations());
  state.SetLabel(std::to_string(recs.size()) + " records");
}

void BM_KeplerGps(benchmark::State& s) { keplerBench(s, System::Gps, -1); }
void BM_KeplerGalileo(benchmark::State& s) { keplerBench(s, System::Galileo, -1); }
void BM_KeplerBeiDouMeoIgso(benchmark::State& s) { keplerBench(s, System::BeiDou, 0); }
void BM_KeplerBeiDouGeo(benchmark::State& s) { keplerBench(s, System::BeiDou, 1); }
void BM_KeplerQzss(benchmark::State& s) { keplerBench(s, System::Qzss, -1); }
BENCHMARK(BM_KeplerGps);
BENCHMARK(BM_KeplerGalileo);
BENCHMARK(BM_KeplerBeiDouMeoIgso);
BENCHMARK(BM_KeplerBeiDouGeo);
BENCHMARK(BM_KeplerQzss);

// GLONASS: integration from tb over range(0) seconds with the default 30 s step.
void BM_GlonassRk4(benchmark::State& state) {
  const auto& recs = nav().glonass;
  const double span = static_cast<double>(state.range(0));
  std::size_t i = 0;
  for (auto _ : state) {
    const GlonassEphemeris& g = recs[i];
    benchmark::DoNotOptimize(glonassSatelliteState(g, g.toe + span));
    if (++i == recs.size()) i = 0;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_GlonassRk4)->Arg(60)->Arg(300)->Arg(900)->Arg(1800);

// Store: selection of the record and state, per satellite of the file (79, of which 66 have a
// usable record at 08:20; the others cost only the failed selection).
void BM_StoreSatelliteState(benchmark::State& state) {
  EphemerisStore store;
  store.add(nav());
  const std::vector<SatId> sats = store.satellites();
  const GpsTime t0 = GpsTime::fromWeekTow(2320, 116400.0);  // 2024-06-24 08:20 GPST
  std::size_t i = 0, found = 0;
  double dt = 0.0;
  for (auto _ : state) {
    const auto st = store.satelliteState(sats[i], t0 + dt);
    found += st.has_value();
    benchmark::DoNotOptimize(st);
    if (++i == sats.size()) {
      i = 0;
      dt = dt >= 299.0 ? 0.0 : dt + 1.0;  // 08:20-08:25, the span of the nagoya observations
    }
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["usable"] = static_cast<double>(found) / static_cast<double>(state.iterations());
}
BENCHMARK(BM_StoreSatelliteState);

// Precise products: the broadcast orbits of the file sampled as a 15-min SP3 table (positions,
// Arg 1: also velocity records), interpolated per satellite at 1 s steps over 08:20-08:25.
void BM_PreciseSatelliteState(benchmark::State& state) {
  EphemerisStore store;
  store.add(nav());
  const GpsTime t0 = GpsTime::fromWeekTow(2320, 116400.0);
  Sp3Data sp3 = broadcastSp3(store, t0 - 3 * 3600.0, t0 + 3 * 3600.0, 900.0);
  if (state.range(0) != 0) {
    for (auto& e : sp3.epochs) {
      for (auto& r : e.records) {
        const auto st = store.satelliteState(r.sat, e.time);
        if (st) r.velocity = st->velocity;
      }
    }
  }
  PreciseEphemeris pe;
  pe.add(sp3);
  const std::vector<SatId> sats = pe.satellites();
  std::size_t i = 0;
  double dt = 0.0;
  for (auto _ : state) {
    const auto st = pe.satelliteState(sats[i], t0 + dt);
    benchmark::DoNotOptimize(st);
    if (++i == sats.size()) {
      i = 0;
      dt = dt >= 299.0 ? 0.0 : dt + 1.0;
    }
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_PreciseSatelliteState)->Arg(0)->Arg(1);

void BM_ReadRinexNav(benchmark::State& state) {
  std::size_t records = 0;
  for (auto _ : state) {
    const NavData n = readRinexNav(kNav);
    records += n.kepler.size() + n.glonass.size();
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(records));
}
BENCHMARK(BM_ReadRinexNav)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
