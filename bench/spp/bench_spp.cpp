// Micro-benchmarks of the SPP pipeline pieces: RINEX observation parsing and the per-epoch
// solution (models, least squares, FDE, robust weighting, Doppler velocity).
#include <benchmark/benchmark.h>

#include <vector>

#include "gvins/base/rinex_obs_reader.hpp"
#include "gvins/ephemeris/rinex_nav.hpp"
#include "gvins/gnss/carrier_smoothing.hpp"
#include "gvins/gnss/spp.hpp"

namespace {
const std::string kData = GVINS_TEST_DATA;

void BM_ReadRinexObsNagoya(benchmark::State& st) {
  std::int64_t epochs = 0;
  for (auto _ : st) {
    gvins::RinexObsReader r(kData + "/gnss/nagoya_static_2024/rover.obs.gz");
    gvins::ObsEpoch e;
    while (r.next(e)) ++epochs;
    benchmark::DoNotOptimize(e);
  }
  st.counters["epochs/s"] = benchmark::Counter(static_cast<double>(epochs), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_ReadRinexObsNagoya)->Unit(benchmark::kMillisecond);

void BM_SppEpoch(benchmark::State& st, const std::string& obs, const std::string& nav) {
  gvins::EphemerisStore store;
  store.add(gvins::readRinexNav(nav));
  std::vector<gvins::ObsEpoch> epochs = gvins::readRinexObs(obs);
  gvins::SppSolver solver(store);
  std::size_t i = 0;
  for (auto _ : st) {
    benchmark::DoNotOptimize(solver.solve(epochs[i]));
    i = (i + 1) % epochs.size();
  }
  st.counters["epochs/s"] = benchmark::Counter(static_cast<double>(st.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK_CAPTURE(BM_SppEpoch, nagoya_42sats, kData + "/gnss/nagoya_static_2024/rover.obs.gz",
                  kData + "/gnss/nagoya_static_2024/base.nav.gz")
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_SppEpoch, kamakura_20sats, kData + "/gnss/kamakura_static_2021/SEPT078M.21O.gz",
                  kData + "/gnss/kamakura_static_2021/SEPT078M.21P.gz")
    ->Unit(benchmark::kMicrosecond);

// Carrier smoothing (slip detection + Hatch update) of one epoch, all signals, in time order; the
// file is replayed from its start (a fresh smoother) when it runs out.
void BM_CarrierSmoothingEpoch(benchmark::State& st, const std::string& obs) {
  gvins::RinexObsHeader header;
  const std::vector<gvins::ObsEpoch> epochs = gvins::readRinexObs(obs, &header);
  gvins::CarrierSmoother smoother;
  std::size_t i = 0;
  gvins::ObsEpoch e;
  for (auto _ : st) {
    st.PauseTiming();
    e = epochs[i];
    st.ResumeTiming();
    smoother.apply(e, header.glonassChannels);
    benchmark::DoNotOptimize(e);
    if (++i == epochs.size()) {
      i = 0;
      smoother.reset();
    }
  }
  st.counters["epochs/s"] = benchmark::Counter(static_cast<double>(st.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK_CAPTURE(BM_CarrierSmoothingEpoch, nagoya_42sats, kData + "/gnss/nagoya_static_2024/rover.obs.gz")
    ->Unit(benchmark::kMicrosecond);
}  // namespace

BENCHMARK_MAIN();
