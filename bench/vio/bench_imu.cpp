// IMU propagation and integration cost: one 200 Hz step with and without Phi/Qd, and a 20 Hz
// camera interval (10 steps) with Phi/Qd, on real EuRoC V1_02 data.
#include <benchmark/benchmark.h>

#include "gvins/vio/euroc_csv.hpp"
#include "gvins/vio/imu_integration.hpp"
#include "gvins/vio/imu_propagation.hpp"

using namespace gvins::vio;

namespace {
const std::vector<ImuSample>& imu() {
  static const auto s = readImuCsv(std::string(GVINS_TEST_DATA) + "/euroc/v102_imu_groundtruth/imu0.csv.gz");
  return s;
}
}  // namespace

static void BM_PropagateCameraInterval(benchmark::State& state) {
  const auto& s = imu();
  const ImuPropagator prop(ImuNoise{}, 9.81);
  const bool withJ = state.range(0) != 0;
  std::size_t k = 100;
  Matrix15d Phi, Qd;
  for (auto _ : state) {
    ImuState x;
    x.t_ns = s[k].t_ns + 1'300'000;
    prop.propagate(x, s, x.t_ns + 50'000'000, withJ ? &Phi : nullptr, withJ ? &Qd : nullptr);
    benchmark::DoNotOptimize(x.p_WI.data());
    k = k + 10 < s.size() - 100 ? k + 10 : 100;
  }
  state.SetLabel(withJ ? "50 ms, mean + Phi + Qd" : "50 ms, mean only");
}
BENCHMARK(BM_PropagateCameraInterval)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

static void BM_IntegrationTerms200ms(benchmark::State& state) {
  const auto& s = imu();
  std::size_t k = 100;
  for (auto _ : state) {
    ImuIntegration integ(ImuNoise{}, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
    integ.integrate(s, s[k].t_ns + 2'000'000, s[k].t_ns + 202'000'000);
    benchmark::DoNotOptimize(integ.covariance().data());
    k = k + 10 < s.size() - 100 ? k + 10 : 100;
  }
}
BENCHMARK(BM_IntegrationTerms200ms)->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();
