// Simulator speed. The headline: generating the default two-minute stereo UAV flight (rendered
// images of both cameras, IMU, truth, GNSS rover 10 Hz + base with RTCM) into a folder must take
// well under the flight's own duration; the counter `x_realtime` is flight seconds per wall-clock
// second (> 1 = faster than the flight) and `x_realtime_2cores_cpu` the same from the process CPU
// time spread over two cores (independent of other load on the machine). Also the parts: one rendered image, one feature-only
// image, the trajectory + IMU of the flight, the GNSS part, and the feature-only dataset.
//
//   build-<you>/bench/bench_sim --benchmark_filter=Default   (threads: all cores)
#include <benchmark/benchmark.h>

#include <ctime>
#include <filesystem>
#include <memory>
#include <string>
#include <unistd.h>

#include "gvins/sim/camera_renderer.hpp"
#include "gvins/sim/dataset_generator.hpp"
#include "gvins/sim/feature_simulator.hpp"
#include "gvins/sim/gnss_simulator.hpp"
#include "gvins/sim/imu_simulator.hpp"
#include "gvins/sim/random.hpp"
#include "gvins/sim/scenario.hpp"

namespace {

namespace fs = std::filesystem;
using gvins::sim::GenerationOptions;
using gvins::sim::GenerationSummary;

fs::path scratch(const std::string& name) {
  return fs::temp_directory_path() / ("gvins_bench_sim_" + name + "_" + std::to_string(::getpid()));
}

void generateDefault(benchmark::State& st, bool features, bool gnss) {
  const gvins::sim::Scenario sc = gvins::sim::defaultScenario();
  const fs::path dir = scratch("default");
  GenerationOptions opt;
  opt.seed = 1;
  opt.featuresOnly = features;
  opt.gnss = gnss;
  double flight = 0.0, wall = 0.0, cameras = 0.0, gnssSeconds = 0.0, mb = 0.0, cpu = 0.0;
  for (auto _ : st) {
    fs::remove_all(dir);
    const std::clock_t c0 = std::clock();  // CPU time of the whole process (all threads)
    const GenerationSummary s = gvins::sim::generateDataset(sc, dir, opt);
    cpu += static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
    flight += s.duration;
    wall += s.secondsTotal;
    cameras += s.secondsCameras;
    gnssSeconds += s.secondsGnss;
    mb += static_cast<double>(s.bytes) / 1e6;
    st.counters["images"] = static_cast<double>(s.framesPerCamera * static_cast<std::size_t>(s.cameras));
  }
  fs::remove_all(dir);
  const double n = static_cast<double>(st.iterations());
  st.counters["flight_s"] = flight / n;
  st.counters["x_realtime"] = flight / wall;
  st.counters["cameras_s"] = cameras / n;
  st.counters["gnss_s"] = gnssSeconds / n;
  st.counters["MB"] = mb / n;
  // CPU seconds of all threads: on a shared machine the wall time depends on the load, the CPU
  // time does not; flight / (cpu / 2) is what two idle cores would take.
  st.counters["cpu_s"] = cpu / n;
  st.counters["x_realtime_2cores_cpu"] = flight / (cpu / 2.0);
}

void BM_DefaultTwoMinuteStereoFlight(benchmark::State& st) { generateDefault(st, false, true); }
BENCHMARK(BM_DefaultTwoMinuteStereoFlight)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();

void BM_DefaultFlightFeaturesOnly(benchmark::State& st) { generateDefault(st, true, true); }
BENCHMARK(BM_DefaultFlightFeaturesOnly)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();

void BM_DefaultFlightGnssOnly(benchmark::State& st) {
  const gvins::sim::Scenario sc = gvins::sim::defaultScenario();
  const auto traj = gvins::sim::buildTrajectory(sc, 1);
  const fs::path dir = scratch("gnss");
  gvins::sim::GnssSimulator sim(*sc.gnss);
  for (auto _ : st) {
    fs::remove_all(dir);
    benchmark::DoNotOptimize(sim.run(*traj, sc.frame, sc.leverArm, 1, dir));
  }
  fs::remove_all(dir);
  st.counters["x_realtime"] = benchmark::Counter(traj->duration() * static_cast<double>(st.iterations()),
                                                 benchmark::Counter::kIsRate);
}
BENCHMARK(BM_DefaultFlightGnssOnly)->Unit(benchmark::kSecond)->Iterations(2)->UseRealTime();

void BM_TrajectoryAndImu(benchmark::State& st) {
  const gvins::sim::Scenario sc = gvins::sim::defaultScenario();
  for (auto _ : st) {
    const auto traj = gvins::sim::buildTrajectory(sc, 1);
    benchmark::DoNotOptimize(gvins::sim::simulateImu(*traj, sc.frame, sc.imu, 1));
  }
}
BENCHMARK(BM_TrajectoryAndImu)->Unit(benchmark::kMillisecond)->UseRealTime();

/// One 752 x 480 image of the default flight at cruise (one thread), PNG encoding excluded;
/// argument 0: the scalar per-pixel loop instead of the AVX2 kernel (same pixels).
void BM_RenderImage(benchmark::State& st) {
  const gvins::sim::Scenario sc = gvins::sim::defaultScenario();
  const auto traj = gvins::sim::buildTrajectory(sc, 1);
  gvins::sim::GroundTextureConfig tc = sc.texture;
  const gvins::sim::GroundTexture texture(tc);
  gvins::sim::CameraRenderer r(sc.cameras[0], sc.imaging, texture);
  r.setVectorized(st.range(0) != 0);
  // Warm-up: the texture tiles of the first view (generated once, then cached); later images
  // along the flight generate the tiles that come into view, as in a real run.
  r.render(*traj, 29.95, 1.0, 7);
  double t = 30.0;
  for (auto _ : st) {
    benchmark::DoNotOptimize(r.render(*traj, t, 1.0, 7));
    t += 0.05;
  }
  st.counters["images/s"] = benchmark::Counter(static_cast<double>(st.iterations()), benchmark::Counter::kIsRate);
  st.counters["tiles"] = static_cast<double>(texture.tilesGenerated());
}
BENCHMARK(BM_RenderImage)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond)->Iterations(40);

void BM_FeatureImage(benchmark::State& st) {
  const gvins::sim::Scenario sc = gvins::sim::defaultScenario();
  const auto traj = gvins::sim::buildTrajectory(sc, 1);
  const double density = gvins::sim::autoLandmarkDensity(sc.cameras[0].intrinsics, 40.0, sc.features.landmarksPerImage);
  const gvins::sim::LandmarkField field(density, 0.0, 3);
  const gvins::sim::FeatureSimulator fs(sc.cameras[0], sc.features, field);
  double t = 30.0;
  std::uint64_t k = 0;
  for (auto _ : st) {
    benchmark::DoNotOptimize(fs.observe(*traj, t, ++k));
    t += 0.05;
  }
  st.counters["images/s"] = benchmark::Counter(static_cast<double>(st.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_FeatureImage)->Unit(benchmark::kMicrosecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
