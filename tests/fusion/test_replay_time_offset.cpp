// Camera-IMU time offset end to end: gvins-sim writes a stereo feature-track flight whose images
// are stamped t_d = 15 ms early (cameras.time_offset_s, t_imu = t_cam + t_d), and the replay
// pipeline runs the real SRI-SWF estimator on it (VIO only) as gvins-replay does. Checked against
// the simulation truth: the simulator's stamps and camera poses, the calibrated offset and its
// σ, and the trajectory against runs that ignore the offset or are given it, in double and float.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "gvins/fusion/replay_pipeline.hpp"
#include "gvins/fusion/replay_sri_swf.hpp"
#include "gvins/fusion/sim_dataset_info.hpp"
#include "gvins/sim/dataset_generator.hpp"
#include "gvins/sim/scenario.hpp"
#include "gvins/vio/euroc_csv.hpp"
#include "gvins/vio/sensor_yaml.hpp"
#include "process_scratch_folder.hpp"
#include "sim_feature_dataset.hpp"

namespace gvins::fusion {
namespace {

namespace fs = std::filesystem;

constexpr double kTimeOffset = 0.015;  // s

/// Everything of this process goes below one folder, removed when the process ends.
const fs::path& scratch() { return test::processScratchFolder("gvins_time_offset_"); }

/// The paper-like flight 60m-400m-8m/s (config/uav_60m_400m_8mps.yaml) as feature tracks, no GNSS.
const fs::path& dataset() {
  static const fs::path dir = [] {
    const fs::path d = scratch() / "dataset";
    test::simulateStereoFeatureDataset(
        d, "time_offset_test",
        "trajectory: {type: flight, pattern: lawnmower, height_m: 60, length_m: 400, speed_mps: 8,\n"
        "             climb_rate_mps: 3, rows: 2, row_spacing_m: 50, heading_deg: 300, wobble_deg: 0.3}\n",
        "  time_offset_s: " + std::to_string(kTimeOffset) + "\n", 105);
    return d;
  }();
  return dir;
}

struct ReplayRun {
  ReplaySummary summary;
};

ReplayRun replay(const std::string& name, bool useFloat, bool calibrate, double timeOffset) {
  const fs::path d = dataset();
  vio::SriSwfConfig ec = test::datasetEstimatorConfig(d);
  ec.use_float = useFloat;
  ec.calibrate_time_offset = calibrate;
  ec.time_offset = timeOffset;
  ReplayOptions o;
  o.outDir = (scratch() / name).string();
  o.progress = false;
  o.timeOffsetTruth = kTimeOffset;
  ReplayRun r;
  if (useFloat) {
    SriSwfReplayEstimator<float> est(ec);
    r.summary = runReplay(d.string(), est, nullptr, o);
  } else {
    SriSwfReplayEstimator<double> est(ec);
    r.summary = runReplay(d.string(), est, nullptr, o);
  }
  const ReplaySummary& s = r.summary;
  std::fprintf(stderr, "%-22s RMSE %.3f m, NEES p %.2f th %.2f, t_d %s%.3f ms (sigma %.3f ms)\n", name.c_str(),
               s.local.positionRmse, s.local.positionNeesFirstPose, s.local.orientationNeesFirstPose,
               s.timeOffset ? "" : "(fixed) ", s.timeOffset.value_or(timeOffset) * 1e3, s.timeOffsetSigma.value_or(0.0) * 1e3);
  return r;
}

const ReplayRun& calibratedDouble() {
  static const ReplayRun r = replay("calibrated_double", false, true, 0.0);
  return r;
}

// The simulator: images taken at IMU time t are stamped t − t_d, and the true camera poses are
// those at the IMU time stamp + t_d (not at the stamp: 8 m/s × 15 ms = 12 cm away).
TEST(TimeOffsetSim, StampsAreShiftedAndTruthIsAtImuTime) {
  const fs::path d = dataset();
  const auto info = readSimDatasetInfo(d.string());
  ASSERT_TRUE(info && info->cameraTimeOffset);
  EXPECT_DOUBLE_EQ(*info->cameraTimeOffset, kTimeOffset);
  const auto truth = vio::readGroundTruthCsv((d / "mav0" / "state_groundtruth_estimate0" / "data.csv").string());
  const auto cams = vio::readCameraCsv((d / "mav0" / "cam0" / "data.csv").string());
  const vio::CameraCalibration cal = vio::readCameraSensorYaml((d / "mav0" / "cam0" / "sensor.yaml").string());
  ASSERT_GT(cams.size(), 1000u);
  ASSERT_GT(truth.size(), 10000u);
  // No image before the first IMU sample.
  EXPECT_GE(cams.front().t_ns + static_cast<std::int64_t>(kTimeOffset * 1e9), truth.front().state.t_ns);
  // cam0_poses.csv: p_WC at each stamp.
  std::ifstream in(d / "truth" / "cam0_poses.csv");
  std::string line;
  std::getline(in, line);
  auto truthPositionAt = [&](std::int64_t t) {
    auto it = std::lower_bound(truth.begin(), truth.end(), t,
                               [](const vio::GroundTruthSample& s, std::int64_t x) { return s.state.t_ns < x; });
    const auto& b = *it;
    const auto& a = *(it - 1);
    const double u = static_cast<double>(t - a.state.t_ns) / static_cast<double>(b.state.t_ns - a.state.t_ns);
    const Eigen::Vector3d pB = (1 - u) * a.state.p_WI + u * b.state.p_WI;
    return Eigen::Vector3d(pB + a.state.R_WI * cal.T_BS.topRightCorner<3, 1>());
  };
  double errShifted = 0.0, errStamp = 0.0;
  int n = 0;
  while (std::getline(in, line) && n < 2000) {
    std::int64_t t = 0;
    double x = 0, y = 0, z = 0;
    ASSERT_EQ(std::sscanf(line.c_str(), "%ld,%lf,%lf,%lf", &t, &x, &y, &z), 4) << line;
    if (n % 10 == 0 && t > truth.front().state.t_ns) {
      const Eigen::Vector3d p(x, y, z);
      errShifted = std::max(errShifted, (p - truthPositionAt(t + static_cast<std::int64_t>(kTimeOffset * 1e9))).norm());
      errStamp = std::max(errStamp, (p - truthPositionAt(t)).norm());
    }
    ++n;
  }
  EXPECT_LT(errShifted, 2e-3);  // interpolation of the 250 Hz truth and its rotation only
  EXPECT_GT(errStamp, 0.10);
}

// Calibration from 0: converges to the true 15 ms within 0.2 ms and within 3 σ, and the
// trajectory is as good as with the offset given.
TEST(TimeOffsetReplay, CalibratesFifteenMillisecondsFromZero) {
  const ReplayRun& cal = calibratedDouble();
  const ReplayRun known = replay("known_double", false, false, kTimeOffset);
  const ReplayRun ignored = replay("ignored_double", false, false, 0.0);
  ASSERT_TRUE(cal.summary.timeOffset && cal.summary.timeOffsetSigma);
  const double err = *cal.summary.timeOffset - kTimeOffset;
  const double sigma = *cal.summary.timeOffsetSigma;
  EXPECT_LT(std::abs(err), 2e-4);
  EXPECT_GT(sigma, 1e-6);
  EXPECT_LT(sigma, 2e-4);
  EXPECT_LT(std::abs(err), 3.0 * sigma) << "error " << err * 1e3 << " ms, sigma " << sigma * 1e3 << " ms";
  EXPECT_FALSE(known.summary.timeOffset);  // not estimated: not reported
  const double rc = cal.summary.local.positionRmse, rk = known.summary.local.positionRmse,
               ri = ignored.summary.local.positionRmse;
  EXPECT_LT(rc, 0.30);
  EXPECT_LT(rc, 1.10 * rk);
  EXPECT_GT(ri, 3.0 * rc);  // ignoring 15 ms at 8 m/s and 60 m spoils VIO
  EXPECT_LT(cal.summary.local.positionNeesFirstPose, 6.0);
  EXPECT_LT(cal.summary.local.orientationNeesFirstPose, 6.0);
}

TEST(TimeOffsetReplay, FloatCalibratesAsDouble) {
  const ReplayRun& d = calibratedDouble();
  const ReplayRun f = replay("calibrated_float", true, true, 0.0);
  ASSERT_TRUE(f.summary.timeOffset && d.summary.timeOffset);
  EXPECT_LT(std::abs(*f.summary.timeOffset - kTimeOffset), 2e-4);
  EXPECT_LT(std::abs(*f.summary.timeOffset - *d.summary.timeOffset), 2e-5);
  EXPECT_LT(f.summary.local.positionRmse, 1.05 * d.summary.local.positionRmse);
}

}  // namespace
}  // namespace gvins::fusion
