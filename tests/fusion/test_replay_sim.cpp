// SRI-GVINS end to end on a simulated flight: gvins-sim writes a feature-track dataset (stereo,
// IMU, rover and base GNSS over the real Nagoya broadcast ephemerides, 60 s rover outage), and
// the replay pipeline runs the real SRI-SWF estimator with the real GNSS fusion on it, as
// gvins-replay does. Checked against the simulation's truth: RTK-fixed carrier-phase accuracy
// before and after the outage (re-acquisition resets clocks and ambiguities and fixes again),
// lever-arm calibration from a 0.3 m wrong start, and float against double.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "gvins/base/local_frame.hpp"
#include "gvins/base/geodetic.hpp"
#include "gvins/gnss/pos_reader.hpp"
#include "gvins/fusion/replay_pipeline.hpp"
#include "gvins/fusion/replay_sri_swf.hpp"
#include "gvins/fusion/sim_dataset_info.hpp"
#include "gvins/sim/dataset_generator.hpp"
#include "gvins/sim/scenario.hpp"
#include "gvins/vio/sensor_yaml.hpp"
#include "gvins/vio/tum_trajectory.hpp"
#include "generate_scenario.hpp"
#include "process_scratch_folder.hpp"

namespace gvins::fusion {
namespace {

namespace fs = std::filesystem;

const Eigen::Vector3d kLever(0.08, 0.0, 0.18);
constexpr double kOutageStart = 35.0, kOutageLength = 60.0;  // s of flight time

/// Everything of this process goes below one folder, removed when the process ends.
const fs::path& scratch() { return test::processScratchFolder("gvins_replay_sim_"); }

/// The dataset, simulated once: a 120 s figure-eight at 30 m and 6 m/s with a 3° attitude wobble
/// (rotational excitation for the lever arm), rover 5 Hz, base 1 Hz 3 km away. With
/// `cameraOffset` (s) the images are stamped that much early and the rover has no outage.
fs::path simulate(const std::string& name, double cameraOffset) {
  const fs::path d = scratch() / name;
  fs::remove_all(d);
  std::ostringstream y;
  y << "name: replay_sim_test\n"
       "origin: {latitude_deg: 35.134707705, longitude_deg: 136.977577939, height_m: 104.853}\n"
       "start_gpst: \"2024-06-24 08:20:00\"\n"
       "trajectory: {type: flight, pattern: figure_eight, height_m: 30, length_m: 660, speed_mps: 6, laps: 1,\n"
       "             takeoff_landing: false, hover_start_s: 3, hover_end_s: 2, wobble_deg: 3}\n"
       "imu: {rate_hz: 200}\n"
       "cameras:\n"
       "  rate_hz: 20\n"
       "  time_offset_s: "
    << cameraOffset
    << "\n"
       "  output: features\n"
       "  list:\n"
       "    - {name: cam0, look: down, position_m: [0.06, 0.06, -0.04]}\n"
       "    - {name: cam1, look: down, position_m: [0.06, -0.06, -0.04]}\n"
       "lever_arm_m: ["
    << kLever.x() << ", " << kLever.y() << ", " << kLever.z()
    << "]\n"
       "gnss:\n"
       "  navigation: "
    << GVINS_TEST_DATA
    << "/gnss/nagoya_static_2024/base.nav.gz\n"
       "  rover:\n"
       "    rate_hz: 5\n";
  if (cameraOffset == 0.0) y << "    outages: [{start_s: " << kOutageStart << ", duration_s: " << kOutageLength << "}]\n";
  const sim::GenerationSummary s = test::generateScenario(d, y.str(), "replay_sim_test", 5);
  std::fprintf(stderr, "dataset: %.1f s, %.0f m, %zu frames per camera\n", s.duration, s.pathLength, s.framesPerCamera);
  return d;
}

const fs::path& dataset() {
  static const fs::path dir = simulate("dataset", 0.0);
  return dir;
}

struct ReplayRun {
  ReplaySummary summary;
  fs::path out;
  std::optional<Eigen::Vector3d> lever;
};

template <typename Scalar>
ReplayRun replay(const std::string& name, GnssFusionConfig gc, const fs::path& d = dataset()) {
  vio::SriSwfConfig ec;
  ec.gravity = *readSimDatasetInfo(d.string())->gravity;  // as gvins-replay does
  ec.imu = vio::readImuSensorYaml((d / "mav0" / "imu0" / "sensor.yaml").string()).noise;
  ec.cameras.push_back(vio::readCameraSensorYaml((d / "mav0" / "cam0" / "sensor.yaml").string()));
  ec.cameras.push_back(vio::readCameraSensorYaml((d / "mav0" / "cam1" / "sensor.yaml").string()));
  ec.use_float = std::is_same_v<Scalar, float>;
  ec = estimatorConfigFor(ec, gc.mode);
  SriSwfReplayEstimator<Scalar> est(ec);
  GnssFusionReplayClient<Scalar> gnss(gc, est.estimator());
  const bool vioOnly = gc.mode == GnssFusionMode::kVio;
  ReplayOptions o;
  o.outDir = (scratch() / name).string();
  o.progress = false;
  o.modeName = toString(gc.mode);
  o.leverArmTruth = kLever;
  ReplayRun r;
  r.summary = runReplay(d.string(), est, vioOnly ? nullptr : &gnss, o);
  r.out = o.outDir;
  r.lever = r.summary.leverArm;
  return r;
}

GnssFusionConfig config(GnssFusionMode m) {
  GnssFusionConfig c;
  c.mode = m;
  c.leverArm = kLever;
  return c;
}

struct EpochError {
  double flightTime = 0.0;  ///< s since the first truth sample
  double position = 0.0;    ///< m, antenna
  bool fixed = false;
};

/// Errors of global_ecef.csv against the true antenna track (linear interpolation).
std::vector<EpochError> antennaErrors(const ReplayRun& r) {
  const auto truth = readEcefTruthCsv((dataset() / "truth" / "groundtruth_ecef.csv").string());
  std::vector<EpochError> out;
  std::ifstream in(r.out / "global_ecef.csv");
  std::string line;
  std::size_t j = 1;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    int week = 0, fixed = 0;
    double tow = 0, x = 0, y = 0, z = 0, vx, vy, vz;
    if (std::sscanf(line.c_str(), "%d,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%d", &week, &tow, &x, &y, &z, &vx, &vy, &vz, &fixed) != 9)
      continue;
    const std::int64_t t = static_cast<std::int64_t>(week) * 604800'000'000'000LL + std::llround(tow * 1e9);
    while (j + 1 < truth.size() && truth[j].t_ns < t) ++j;
    if (j >= truth.size() || truth[j - 1].t_ns > t) continue;
    const double w = static_cast<double>(t - truth[j - 1].t_ns) / static_cast<double>(truth[j].t_ns - truth[j - 1].t_ns);
    const Eigen::Vector3d a = (1 - w) * truth[j - 1].antenna + w * truth[j].antenna;
    out.push_back({static_cast<double>(t - truth.front().t_ns) * 1e-9, (Eigen::Vector3d(x, y, z) - a).norm(), fixed != 0});
  }
  return out;
}

TEST(ReplaySim, DatasetYamlGivesTheLeverArmAndGravity) {
  const auto info = readSimDatasetInfo(dataset().string());
  ASSERT_TRUE(info && info->leverArm && info->gravity);
  EXPECT_LT((*info->leverArm - kLever).norm(), 1e-12);
  EXPECT_EQ(info->gravityModel, "flat");
  // WGS 84 normal gravity at 35.13° N, 105 m + 30 m flight height: 9.7972 m/s² (Somigliana).
  EXPECT_NEAR(*info->gravity, 9.7972, 5e-4);
}

TEST(ReplaySim, CarrierPhaseFusionSurvivesASixtySecondOutage) {
  const ReplayRun r = replay<double>("ddcp", config(GnssFusionMode::kDoppDdcp));
  const ReplaySummary& s = r.summary;
  ASSERT_GT(s.framesInitialized, 2000u);
  EXPECT_LT(s.frameInitSeconds, 30.0);
  // Reset after the outage: the first epoch after it says so in gnss_epochs.csv (column 16).
  int resets = 0;
  {
    std::ifstream in(r.out / "gnss_epochs.csv");
    std::string line;
    while (std::getline(in, line)) {
      if (line.empty() || line[0] == '#') continue;
      std::vector<std::string> f;
      std::stringstream ss(line);
      for (std::string c; std::getline(ss, c, ',');) f.push_back(c);
      ASSERT_GE(f.size(), 16u);
      resets += f[15] == "1";
    }
  }
  EXPECT_EQ(resets, 1);
  const auto e = antennaErrors(r);
  double before2 = 0, after2 = 0, worstAfter = 0;
  int nb = 0, na = 0, fixedAfter = 0;
  const double back = kOutageStart + kOutageLength;
  for (const EpochError& x : e) {
    if (x.flightTime < kOutageStart && x.flightTime > s.frameInitSeconds + 10.0) {
      before2 += x.position * x.position;
      ++nb;
    } else if (x.flightTime > back + 10.0) {
      after2 += x.position * x.position;
      worstAfter = std::max(worstAfter, x.position);
      ++na;
      fixedAfter += x.fixed;
    }
  }
  ASSERT_GT(nb, 20);
  ASSERT_GT(na, 20);
  const double before = std::sqrt(before2 / nb), after = std::sqrt(after2 / na);
  std::fprintf(stderr, "ddcp: antenna RMSE %.3f m before the outage, %.3f m (max %.3f) from 10 s after it, %d/%d fixed; "
               "global %.3f m, body velocity %.4f m/s\n",
               before, after, worstAfter, fixedAfter, na, s.global.positionRmse, s.local.bodyVelocityRmse);
  EXPECT_LT(before, 0.05);
  EXPECT_LT(after, 0.10);  // re-acquired: clocks re-initialised, ambiguities fixed again
  EXPECT_GT(fixedAfter, na * 9 / 10);
  EXPECT_LT(s.local.bodyVelocityRmse, 0.05);
}

TEST(ReplaySim, LeverArmConvergesFromAWrongStart) {
  GnssFusionConfig c = config(GnssFusionMode::kDoppPsr);
  c.leverArm = kLever + Eigen::Vector3d(0.3, 0.0, 0.0);
  c.calibrateLeverArm = true;
  const ReplayRun on = replay<double>("lever_on", c);
  c.calibrateLeverArm = false;
  const ReplayRun off = replay<double>("lever_off", c);
  ASSERT_TRUE(on.lever);
  const double err = (*on.lever - kLever).norm();
  std::fprintf(stderr, "lever arm from 0.3 m off: final error %.3f m; antenna velocity RMSE %.4f (calibrated) vs %.4f m/s\n",
               err, on.summary.global.velocityRmse, off.summary.global.velocityRmse);
  EXPECT_LT(err, 0.05);
  EXPECT_LT(on.summary.global.velocityRmse, off.summary.global.velocityRmse);
}

/// Run b against reference run a: the global antenna RMSE within rel·a + abs and the body-frame
/// velocity RMSE within 5 % (both free of the VIO frame's gauge).
void expectSameAccuracy(const char* what, const ReplayRun& a, const ReplayRun& b, double rel, double abs) {
  std::fprintf(stderr, "%s: global RMSE %.4f / %.4f m, body velocity %.4f / %.4f m/s\n", what,
               a.summary.global.positionRmse, b.summary.global.positionRmse, a.summary.local.bodyVelocityRmse,
               b.summary.local.bodyVelocityRmse);
  EXPECT_NEAR(b.summary.global.positionRmse, a.summary.global.positionRmse, rel * a.summary.global.positionRmse + abs);
  EXPECT_NEAR(b.summary.local.bodyVelocityRmse, a.summary.local.bodyVelocityRmse, 0.05 * a.summary.local.bodyVelocityRmse);
}

TEST(ReplaySim, FloatAgreesWithDouble) {
  const ReplayRun d = replay<double>("ddcp_d", config(GnssFusionMode::kDoppDdcp));
  const ReplayRun f = replay<float>("ddcp_f", config(GnssFusionMode::kDoppDdcp));
  expectSameAccuracy("ddcp double / float", d, f, 0.05, 0.002);
}

// Re-anchoring the VIO in ENU at the frame's convergence (frame_reanchor, default) against
// keeping the frame block as a state: the same estimate to first order (docs/gnss_fusion.md,
// "Re-anchoring in ENU"; measured global 0.1880 against 0.1881 m). Dpsr, whose global accuracy
// depends most on the yaw. The local trajectory stays in the start's VIO frame: no jump where the
// estimator moves into ENU. (It carries the GNSS corrections of the poses from then on: local
// RMSE 0.217 against 0.165 m with the frame kept, which absorbed part of them.)
TEST(ReplaySim, ReanchoringInEnuAgreesWithKeepingTheFrame) {
  GnssFusionConfig keep = config(GnssFusionMode::kDoppDpsr);
  keep.frameReanchor = false;
  const ReplayRun k = replay<double>("dpsr_keep", keep);
  const ReplayRun r = replay<double>("dpsr_reanchor", config(GnssFusionMode::kDoppDpsr));
  expectSameAccuracy("dpsr frame kept / re-anchored", k, r, 0.1, 0.005);
  // The largest speed between two local poses, and when (s after the first pose).
  auto maxSpeed = [](const ReplayRun& run) {
    const std::vector<vio::TumPose> t = vio::readTumTrajectory((fs::path(run.out) / "trajectory.tum").string());
    std::pair<double, double> m{0.0, 0.0};
    for (std::size_t i = 1; i < t.size(); ++i) {
      const double dt = static_cast<double>(t[i].t_ns - t[i - 1].t_ns) * 1e-9;
      const double v = (t[i].p - t[i - 1].p).norm() / dt;
      if (v > m.first) m = {v, static_cast<double>(t[i].t_ns - t[0].t_ns) * 1e-9};
    }
    return m;
  };
  const auto sk = maxSpeed(k), sr = maxSpeed(r);
  std::fprintf(stderr,
               "largest local speed: kept %.2f m/s at %.2f s, re-anchored %.2f m/s at %.2f s; local RMSE %.3f / %.3f m\n",
               sk.first, sk.second, sr.first, sr.second, k.summary.local.positionRmse, r.summary.local.positionRmse);
  // The flight's top speed is 6 m/s; in both runs a GNSS correction at 94.85 s shows as one
  // 10.0–10.1 m/s step. Moving into ENU at the frame's convergence instead of once its position
  // is known to frame_reanchor_position_sigma: 34.7 m/s at 3.6 s (the SPP-level frame position
  // corrected by the first raw rows, after the local map was fixed).
  EXPECT_LT(sr.first, sk.first + 0.5);
}

// Visual lock-out with and without GNSS: the same flight with the images stamped 80 ms early and
// the offset ignored. VIO alone locks out and starts again (the local evaluation covers the
// last state, which still runs with the 80 ms error, 0.5 m of motion at 6 m/s: 0.118 m with two
// resets at 62ca80c, 0.240 m with three since the re-anchoring fix 03de91b, which changes where
// the last segment starts; the bound is a sanity check of the restarted state, not an accuracy
// target); with VIO+Dopp+Ddcp the GNSS rows hold the state, so the
// rejected features do not count as a lock-out (a restart would throw the GNSS state away) and
// the antenna stays at cm level (0.029 m).
TEST(ReplaySim, LockOutResetsVioButNotWhileGnssHoldsTheState) {
  const fs::path d = simulate("dataset_offset", -0.08);
  const ReplayRun vio = replay<double>("offset_vio", config(GnssFusionMode::kVio), d);
  const ReplayRun ddcp = replay<double>("offset_ddcp", config(GnssFusionMode::kDoppDdcp), d);
  std::fprintf(stderr, "80 ms ignored: VIO %zu resets, RMSE %.3f m; Ddcp %zu resets, antenna %.3f m\n",
               vio.summary.estimatorResets, vio.summary.local.positionRmse, ddcp.summary.estimatorResets,
               ddcp.summary.global.positionRmse);
  EXPECT_GE(vio.summary.estimatorResets, 1u);
  EXPECT_LT(vio.summary.local.positionRmse, 0.3);
  EXPECT_EQ(ddcp.summary.estimatorResets, 0u);
  EXPECT_LT(ddcp.summary.global.positionRmse, 0.1);
}

// global.pos carries the estimator's antenna position and velocity covariance (the joint marginal
// covariance of the blocks they depend on, GnssFusion::antennaCovariance): nonzero in every row, growing over the 60 s outage (VIO alone), and compared per east/north/up axis with the
// actual error against the simulation's truth of each rover epoch.
TEST(ReplaySim, GlobalPosCovarianceDescribesTheError) {
  const ReplayRun r = replay<double>("cov", config(GnssFusionMode::kDoppDpsr));
  const PosFile f = readPosFile((r.out / "global.pos").string());
  // The true antenna at the true time of each rover epoch (the rows are at the receiver's time
  // tag; the estimate is at the tag minus the estimated receiver clock), by tag.
  std::map<std::int64_t, Eigen::Vector3d> truth;
  {
    std::ifstream in(dataset() / "gnss" / "truth" / "rover_antenna.csv");
    std::string line;
    while (std::getline(in, line)) {
      if (line.empty() || line[0] == '#' || line[0] == 't') continue;
      long long tag = 0, gpst = 0;
      double x, y, z;
      if (std::sscanf(line.c_str(), "%lld,%lld,%lf,%lf,%lf", &tag, &gpst, &x, &y, &z) == 5) truth[tag] = {x, y, z};
    }
  }
  ASSERT_GT(truth.size(), 400u);
  ASSERT_GT(f.solutions.size(), 200u);
  const Geodetic g0 = ecefToGeodetic(truth.begin()->second);
  const Eigen::Matrix3d R = ecefToEnuRotation(g0.lat, g0.lon);
  std::array<std::array<int, 3>, 3> within{};
  std::array<std::vector<double>, 3> ratio;
  Eigen::Vector3d sum2 = Eigen::Vector3d::Zero(), var = Eigen::Vector3d::Zero();
  int n = 0, zero = 0;
  double sigmaBefore = 0.0, sigmaBack = 0.0;  // east sigma at the last epoch before / first after the outage
  std::int64_t lastTag = 0;
  for (const PositionSolution& s : f.solutions) {
    const std::int64_t tag = static_cast<std::int64_t>(s.time.week()) * 604800'000'000'000LL + std::llround(s.time.tow() * 1e3) * 1'000'000;
    const auto it = truth.find(tag);
    if (it == truth.end()) continue;
    const Eigen::Vector3d e = R * (s.position - it->second);
    const Eigen::Matrix3d C = R * s.positionCovariance * R.transpose();
    // The velocity covariance rides along (same marginal, rows 3..5 of the kinematics).
    if (C.diagonal().minCoeff() <= 0.0 || (s.velocity && s.velocityCovariance.diagonal().minCoeff() <= 0.0)) {
      ++zero;
      continue;
    }
    if (lastTag > 0 && tag - lastTag > 30'000'000'000LL) sigmaBack = std::sqrt(C(0, 0));
    else if (sigmaBack == 0.0) sigmaBefore = std::sqrt(C(0, 0));
    lastTag = tag;
    ++n;
    sum2 += e.cwiseAbs2();
    var += C.diagonal();
    for (int a = 0; a < 3; ++a) {
      const double q = std::abs(e[a]) / std::sqrt(C(a, a));
      ratio[a].push_back(q);
      for (int k = 0; k < 3; ++k) within[a][k] += q <= k + 1;
    }
  }
  ASSERT_GT(n, 200);
  EXPECT_EQ(zero, 0);
  for (int a = 0; a < 3; ++a) {
    std::sort(ratio[a].begin(), ratio[a].end());
    const double median = ratio[a][ratio[a].size() / 2];
    std::fprintf(stderr,
                 "global.pos %c: %d epochs, error RMS %.4f m, sigma RMS %.4f m, within 1/2/3 sigma %.1f / %.1f / %.1f %%, "
                 "median |e|/sigma %.2f\n",
                 "ENU"[a], n, std::sqrt(sum2[a] / n), std::sqrt(var[a] / n), 100.0 * within[a][0] / n,
                 100.0 * within[a][1] / n, 100.0 * within[a][2] / n, median);
    // A Gaussian error with an honest sigma: 68 / 95 / 99.7 %, median 0.67. Measured (Dpsr,
    // 7 Dec 2026): E 58/81/100 % (median 0.41), N 16/29/48 % (3.04), U 28/79/100 % (1.33): the
    // filter's own covariance is up to 3x optimistic in north on this flight, whose slowly
    // varying north error of 0.1-0.15 m it does not know of (VIO+Dopp+Ddcp: 2-5x, mm-level
    // sigma against 1-2 cm errors). The bounds hold the sigma to within a factor 4 of the error.
    EXPECT_GT(within[a][2], n * 4 / 10) << "ENU"[a];
    EXPECT_GT(median, 0.2) << "ENU"[a];  // not uselessly pessimistic
    EXPECT_LT(median, 4.0) << "ENU"[a];
  }
  // 60 s of VIO alone: the first epoch back has a larger sigma than the last before the outage.
  std::fprintf(stderr, "east sigma: %.4f m before the outage, %.4f m at the first epoch after it\n", sigmaBefore, sigmaBack);
  EXPECT_GT(sigmaBack, 2.0 * sigmaBefore);
}

}  // namespace
}  // namespace gvins::fusion
