// Issue 43: a monocular downward camera on a lawnmower flight that takes off from the ground.
// On the ground the camera (0.34 m up) tracks nothing and in the steady climb and cruise the
// accelerometer cannot give the mono scale, so before the IMU-only standstill
// (SriSwfConfig::init_static_without_tracks) such a flight initialised only in the landing
// hover, if at all. Checked against the simulator's ground truth.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "gvins/fusion/replay_feature_tracks.hpp"
#include "gvins/fusion/replay_pipeline.hpp"
#include "gvins/fusion/replay_sri_swf.hpp"
#include "gvins/fusion/sim_dataset_info.hpp"
#include "gvins/vio/sensor_yaml.hpp"
#include "process_scratch_folder.hpp"
#include "sim_feature_dataset.hpp"

namespace gvins::fusion {
namespace {

namespace fs = std::filesystem;

const fs::path& scratch() { return test::processScratchFolder("gvins_replay_init_"); }

// 20 m lawnmower with take-off (2 s on the ground, climb at 3 m/s), cam0 only, feature tracks.
const fs::path& dataset() {
  static const fs::path dir = [] {
    const fs::path d = scratch() / "dataset";
    const std::string y = test::monoTakeoffScenario("mono_takeoff_test", "gnss: none\n");
    const sim::GenerationSummary s = test::generateScenario(d, y, "mono_takeoff_test", 3);
    std::fprintf(stderr, "dataset: %.1f s, %.0f m, %zu frames\n", s.duration, s.pathLength, s.framesPerCamera);
    return d;
  }();
  return dir;
}

// The same flight at 60 m (climb 20 s).
const fs::path& dataset60() {
  static const fs::path dir = [] {
    const fs::path d = scratch() / "dataset60";
    std::string y = test::monoTakeoffScenario("mono_takeoff_60_test", "gnss: none\n");
    y.replace(y.find("height_m: 20,"), 13, "height_m: 60,");
    test::generateScenario(d, y, "mono_takeoff_60_test", 3);
    return d;
  }();
  return dir;
}

ReplaySummary replay(const std::string& name, bool imuOnlyStandstill, double start_s = 0.0, bool high = false) {
  const fs::path d = high ? dataset60() : dataset();
  vio::SriSwfConfig ec;
  ec.gravity = *readSimDatasetInfo(d.string())->gravity;
  ec.imu = vio::readImuSensorYaml((d / "mav0" / "imu0" / "sensor.yaml").string()).noise;
  ec.cameras = {test::datasetCamera(d, 0)};
  ec.init_static_without_tracks = imuOnlyStandstill;
  ReplayOptions o;
  o.outDir = (scratch() / name).string();
  o.progress = false;
  o.start_s = start_s;
  SriSwfReplayEstimator<double> est(ec);
  const ReplaySummary s = runReplay(d.string(), est, nullptr, o);
  std::fprintf(stderr, "%-8s init after %.2f s, %zu of %zu frames, RMSE %.3f m over %.0f m, drift %.2f %%\n", name.c_str(),
               s.initSeconds, s.framesInitialized, s.framesProcessed, s.local.positionRmse, s.local.pathLength,
               s.local.driftPercent);
  return s;
}

// Measured (7 Dec 2026): initialised 1.0 s after the first frame (on the ground), 1313 of 1333
// frames, RMSE 0.159 m over 289 m, drift 0.50 %; with the standstill needing tracks (as before)
// 0 of 1333 frames (the landing's ground contact again has no tracks). 9 s in Release.
TEST(InitReplay, MonoTakeOffInitialisesOnTheGround) {
  const ReplaySummary s = replay("imu_only", true);
  EXPECT_LE(s.initSeconds, 1.5);  // the 1 s standstill window on the ground
  EXPECT_GT(static_cast<double>(s.framesInitialized), 0.97 * static_cast<double>(s.framesProcessed));
  EXPECT_GT(s.local.pathLength, 250.0);
  EXPECT_LT(s.local.positionRmse, 0.5);
  EXPECT_LT(s.local.driftPercent, 1.0);
  const ReplaySummary without = replay("tracks", false);
  EXPECT_TRUE(std::isnan(without.initSeconds) || without.initSeconds > 10.0) << without.initSeconds;
  EXPECT_LT(static_cast<double>(without.framesInitialized), 0.5 * static_cast<double>(without.framesProcessed));
}

// Replayed from mid-cruise (3 s after the climb: 2 s + 60 m / 3 m/s + 3 s), the 60 m flight offers
// the mono alignment no window with its scale determined (constant speed, accelerations of
// constant magnitude: docs/vio_estimator.md, "Known limitations") and no standstill until it has
// landed. In the landing descent at 3 m/s the features thin out and are lost by the image's
// expansion while the IMU is quiet: an IMU-only standstill there starts with v = 0 and a local
// RMSE of metres. Measured (7 Dec 2026): initialised 66.15 s after the first frame (on the ground),
// 42 of 1365 frames, RMSE 0.002 m; with the IMU-only standstill accepting features that are seen
// but not tracked through its window (as before), 62.70 s (in the descent), RMSE 5.02 m. 9 s in Release.
TEST(InitReplay, MonoCruiseStartWaitsForTheGround) {
  const ReplaySummary s = replay("cruise60", true, 25.0, true);
  ASSERT_FALSE(std::isnan(s.initSeconds)) << "initialises on the ground after landing";
  EXPECT_LT(s.local.positionRmse, 0.05);
  EXPECT_LT(static_cast<double>(s.framesInitialized), 0.1 * static_cast<double>(s.framesProcessed));
}

TEST(InitReplay, ImageStampsWithoutTracksBecomeEmptyFrames) {
  std::vector<TrackStamp> tracks = parseFeatureTracksCsv("20,7,1.5,2.5\n40,7,3.5,4.5\n40,8,5,6\n", "t.csv");
  const std::vector<TrackStamp> all = withImageStamps(tracks, {10, 20, 30, 40, 50});
  ASSERT_EQ(all.size(), 5u);
  const std::size_t sizes[] = {0, 1, 0, 2, 0};
  for (std::size_t i = 0; i < all.size(); ++i) {
    EXPECT_EQ(all[i].t_ns, static_cast<std::int64_t>(10 * (i + 1)));
    EXPECT_EQ(all[i].obs.size(), sizes[i]) << i;
  }
  EXPECT_DOUBLE_EQ(all[3].obs[1].pixel.y(), 6.0);
  // A stamp of the tracks that no image has stays; no tracks at all stay none.
  EXPECT_EQ(withImageStamps(tracks, {20, 30}).size(), 3u);
  EXPECT_TRUE(withImageStamps({}, {10, 20}).empty());
}

}  // namespace
}  // namespace gvins::fusion
