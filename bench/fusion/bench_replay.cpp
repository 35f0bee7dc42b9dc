// Replay pipeline throughput on the EuRoC V1_01 stereo clip (24 frames of 752x480, 20 Hz):
//   BM_ReplayPipelineNoEstimator: dataset → loader thread → front end thread → outputs, with an
//     estimator that does nothing: the ceiling the pipeline itself allows.
//   BM_ReplayPipelineSriSwf<double/float>: the whole pipeline with the SRI-SWF estimator.
// Counter "rtf" = dataset seconds per wall second (real-time factor; target >= 5).
// A longer sequence (full EuRoC V1_01) is run by bench_replay.sh.
#include <filesystem>

#include <benchmark/benchmark.h>

#include "gvins/fusion/replay_pipeline.hpp"
#include "gvins/fusion/replay_sri_swf.hpp"
#include "gvins/vio/sensor_yaml.hpp"

namespace {

namespace fs = std::filesystem;
const fs::path kClip = fs::path(GVINS_TEST_DATA) / "euroc" / "v101_static_stereo";

class NullEstimator : public gvins::fusion::ReplayEstimator {
 public:
  void addImu(const gvins::vio::ImuSample&) override {}
  FrameOutcome processFrame(const gvins::vio::FeatureFrame&) override { return {}; }
  bool initialized() const override { return false; }
  gvins::vio::ImuState newestImuState() const override { return {}; }
  gvins::vio::Matrix6d poseCovariance() const override { return gvins::vio::Matrix6d::Identity(); }
};

gvins::fusion::ReplayOptions options() {
  gvins::fusion::ReplayOptions o;
  o.outDir = (fs::temp_directory_path() / "gvins_bench_replay").string();
  o.progress = false;
  o.evaluate = false;
  return o;
}

void BM_ReplayPipelineNoEstimator(benchmark::State& state) {
  double data = 0.0, wall = 0.0;
  for (auto _ : state) {
    NullEstimator est;
    const auto s = gvins::fusion::runReplay(kClip.string(), est, nullptr, options());
    data += s.datasetSeconds;
    wall += s.wallSeconds;
  }
  state.counters["rtf"] = data / wall;
}
BENCHMARK(BM_ReplayPipelineNoEstimator)->Unit(benchmark::kMillisecond)->UseRealTime();

template <typename Scalar>
void BM_ReplayPipelineSriSwf(benchmark::State& state) {
  gvins::vio::SriSwfConfig c;
  const fs::path mav0 = kClip / "mav0";
  c.imu = gvins::vio::readImuSensorYaml((mav0 / "imu0" / "sensor.yaml").string()).noise;
  c.cameras = {gvins::vio::readCameraSensorYaml((mav0 / "cam0" / "sensor.yaml").string()),
               gvins::vio::readCameraSensorYaml((mav0 / "cam1" / "sensor.yaml").string())};
  double data = 0.0, wall = 0.0, est = 0.0;
  for (auto _ : state) {
    gvins::fusion::SriSwfReplayEstimator<Scalar> e(c);
    const auto s = gvins::fusion::runReplay(kClip.string(), e, nullptr, options());
    data += s.datasetSeconds;
    wall += s.wallSeconds;
    est += s.estimatorMsMean;
  }
  state.counters["rtf"] = data / wall;
  state.counters["estimator_ms"] = est / static_cast<double>(state.iterations());
}
BENCHMARK(BM_ReplayPipelineSriSwf<double>)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ReplayPipelineSriSwf<float>)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
