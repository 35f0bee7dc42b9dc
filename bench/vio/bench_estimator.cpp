// SRI-SWF estimator time per camera frame on the simulated stereo UAV circle of the tests
// (tests/vio/vio_sim_scene.hpp): 11 clones, up to 50 (20, 0) SLAM features, ~150 tracked features per
// frame, 0.5 px noise. The estimator is warmed up for 10 s (window and SLAM features full), then
// every processFrame call is timed. Manual time = CPU time of the calling thread (the machine is
// shared: wall time under load measures the other jobs); counters give the median CPU and wall
// (FrameResult::estimator_ms) time per frame and the average MSCKF/SLAM feature counts.
#include <algorithm>
#include <ctime>
#include <chrono>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "gvins/vio/sri_swf_estimator.hpp"
#include "vio_sim_scene.hpp"

namespace {

double threadCpuMs() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
}

using gvins::vio::FrameResult;
using gvins::vio::SriSwfEstimator;

const gvins::vio::test::SimScene& scene() {
  static const auto sc = [] {
    auto s = std::make_unique<gvins::vio::test::SimScene>();
    s->duration = 60.0;
    s->seed = 7;
    s->build();
    return s;
  }();
  return *sc;
}

template <typename Scalar>
void BM_EstimatorFrame(benchmark::State& state) {
  const auto& sc = scene();
  auto cfg = sc.config();
  cfg.max_slam_features = static_cast<int>(state.range(0));
  std::unique_ptr<SriSwfEstimator<Scalar>> est;
  std::size_t frame = 0, k = 0;
  const std::size_t warm = 200;  // 10 s at 20 Hz
  // CPU time per estimator step (the observer fires at the end of each step), summed over the
  // timed frames: where the time goes.
  std::map<std::string, double> step_ms;
  bool timing = false;
  double step_t0 = 0;
  auto restart = [&] {
    est = std::make_unique<SriSwfEstimator<Scalar>>(cfg);
    est->setStepObserver([&](const char* name) {
      const double t = threadCpuMs();
      if (timing) step_ms[name] += t - step_t0;
      step_t0 = t;
    });
    frame = 0;
    k = 0;
  };
  auto step = [&]() -> FrameResult {
    const auto& fr = sc.frames[frame++];
    while (k < sc.imu.size() && sc.imu[k].t_ns <= fr.t_ns + 20'000'000) est->addImu(sc.imu[k++]);
    return est->processFrame(fr);
  };
  restart();
  std::vector<double> ms, wall;
  double msckf = 0, slam = 0, feats = 0;
  for (auto _ : state) {
    if (frame == 0 || frame >= sc.frames.size()) {
      restart();
      while (frame < warm) step();
    }
    feats += static_cast<double>(sc.frames[frame].features.size());
    const double c0 = threadCpuMs();
    step_t0 = c0;
    timing = true;
    const FrameResult r = step();
    timing = false;
    const double c1 = threadCpuMs();
    const double cpu = c1 - c0;
    step_ms["rest"] += c1 - step_t0;
    state.SetIterationTime(cpu * 1e-3);
    ms.push_back(cpu);
    wall.push_back(r.estimator_ms);
    msckf += r.msckf_features;
    slam += r.slam_features;
  }
  std::nth_element(ms.begin(), ms.begin() + static_cast<std::ptrdiff_t>(ms.size() / 2), ms.end());
  const double n = static_cast<double>(state.iterations());
  state.counters["median_cpu_ms"] = ms[ms.size() / 2];
  std::nth_element(wall.begin(), wall.begin() + static_cast<std::ptrdiff_t>(wall.size() / 2), wall.end());
  state.counters["median_wall_ms"] = wall[wall.size() / 2];
  state.counters["msckf"] = msckf / n;
  state.counters["slam"] = slam / n;
  state.counters["tracked"] = feats / n;
  for (const auto& [name, total] : step_ms) state.counters["ms_" + name] = total / n;
}

// Argument: max SLAM features (50 = the target configuration; 20 and 0 show their share).
BENCHMARK_TEMPLATE(BM_EstimatorFrame, double)
    ->Arg(50)->Arg(20)->Arg(0)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(800);
BENCHMARK_TEMPLATE(BM_EstimatorFrame, float)
    ->Arg(50)->Arg(20)->Arg(0)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(800);

}  // namespace

BENCHMARK_MAIN();
