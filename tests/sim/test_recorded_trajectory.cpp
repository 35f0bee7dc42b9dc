// Trajectory driven by the real EuRoC V1_02 IMU log and ground truth: the spline follows the
// ground truth to millimetres, its derivatives are consistent, and the real IMU (with the
// ground-truth biases) agrees with the truth's angular rate and specific force within the
// IMU's noise and vibration, and integrates to the truth over short windows.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "gvins/base/parse_error.hpp"
#include "gvins/sim/ground_truth_lag.hpp"
#include "gvins/sim/recorded_trajectory.hpp"
#include "gvins/vio/imu_propagation.hpp"
#include "gvins/vio/so3.hpp"

namespace gvins::sim {
namespace {

RecordedTrajectoryConfig v102() {
  RecordedTrajectoryConfig c;
  const std::string dir = std::string(GVINS_TEST_DATA) + "/euroc/v102_imu_groundtruth/";
  c.imuCsv = dir + "imu0.csv.gz";
  c.groundTruthCsv = dir + "state_groundtruth_estimate0.csv.gz";
  return c;
}

const RecordedTrajectory& trajectory() {
  static const RecordedTrajectory tr(v102());
  return tr;
}

double median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

TEST(RecordedTrajectory, FollowsTheGroundTruth) {
  const RecordedTrajectory& tr = trajectory();
  EXPECT_GT(tr.duration(), 35.0);  // the bundled subset: 40 s of V1_02
  std::printf("fit residual: position RMS %.2f mm (max %.2f mm), rotation RMS %.3f deg\n", tr.positionRms() * 1e3,
              tr.positionMax() * 1e3, tr.rotationRms() * 180 / M_PI);
  EXPECT_LT(tr.positionRms(), 1.5e-3);
  EXPECT_LT(tr.positionMax(), 10e-3);
  EXPECT_LT(tr.rotationRms(), 0.2 * M_PI / 180);
  // Velocity against the ground truth's own velocity column.
  const auto gt = vio::readGroundTruthCsv(v102().groundTruthCsv);
  std::vector<double> dv;
  for (std::size_t i = 100; i + 100 < gt.size(); i += 50) {
    const double t = static_cast<double>(gt[i].state.t_ns - tr.startStamp()) * 1e-9;
    dv.push_back((tr.velocity(t) - gt[i].state.v_WI).norm());
  }
  std::printf("velocity vs ground-truth column: median %.3f m/s\n", median(dv));
  EXPECT_LT(median(dv), 0.03);
}

TEST(RecordedTrajectory, DerivativesAreConsistent) {
  const RecordedTrajectory& tr = trajectory();
  const double h = 1e-4;
  for (double t = 1.0; t < tr.duration() - 1.0; t += 3.7) {
    const TrajectoryState a = tr.evaluate(t - h), b = tr.evaluate(t), c = tr.evaluate(t + h);
    EXPECT_LT(((c.p_WB - a.p_WB) / (2 * h) - b.v_WB).norm(), 1e-6);
    EXPECT_LT(((c.v_WB - a.v_WB) / (2 * h) - b.a_WB).norm(), 1e-4);
    const Eigen::Vector3d w = (vio::so3::log(b.R_WB.transpose() * c.R_WB) - vio::so3::log(b.R_WB.transpose() * a.R_WB)) / (2 * h);
    EXPECT_LT((w - b.omega_B).norm(), 1e-6);
    EXPECT_LT(((c.omega_B - a.omega_B) / (2 * h) - b.alpha_B).norm(), 1e-3);
  }
}

TEST(RecordedTrajectory, RealImuAgreesWithTheTruthSignals) {
  // Sample by sample the real gyro/accel differ from the truth by the airframe's vibration
  // (rotor harmonics, ~1 m/s^2 and ~0.05 rad/s on the EuRoC MAV) plus white noise; averaged over
  // 0.1 s (20 samples) the vibration cancels and what remains is the truth.
  const RecordedTrajectory& tr = trajectory();
  std::vector<double> eg, ea;
  Eigen::Vector3d sg = Eigen::Vector3d::Zero(), sa = Eigen::Vector3d::Zero();
  int n = 0;
  for (const vio::ImuSample& m : tr.imuSamples()) {
    const double t = static_cast<double>(m.t_ns - tr.startStamp()) * 1e-9;
    if (t < 1.0 || t > tr.duration() - 1.0) continue;
    const TrajectoryState s = tr.evaluate(t);
    Eigen::Vector3d bg, ba;
    tr.biases(t, bg, ba);
    sg += m.gyro - bg - s.omega_B;
    sa += m.accel - ba - s.R_WB.transpose() * (s.a_WB + Eigen::Vector3d(0, 0, 9.81));
    if (++n == 20) {
      eg.push_back(sg.norm() / n);
      ea.push_back(sa.norm() / n);
      sg.setZero();
      sa.setZero();
      n = 0;
    }
  }
  std::printf("0.1 s means: median |gyro - truth| %.4f rad/s, |accel - truth| %.3f m/s^2 over %zu windows\n",
              median(eg), median(ea), eg.size());
  EXPECT_LT(median(eg), 0.02);
  EXPECT_LT(median(ea), 0.15);
}

TEST(RecordedTrajectory, RealImuIntegratesToTheTruth) {
  const RecordedTrajectory& tr = trajectory();
  vio::ImuNoise noise;
  const vio::ImuPropagator prop(noise, 9.81);
  std::vector<double> ep;
  for (double t0 = 2.0; t0 + 1.0 < tr.duration() - 1.0; t0 += 4.0) {
    const TrajectoryState s0 = tr.evaluate(t0), s1 = tr.evaluate(t0 + 1.0);
    vio::ImuState x;
    x.t_ns = tr.startStamp() + static_cast<std::int64_t>(std::llround(t0 * 1e9));
    x.R_WI = s0.R_WB;
    x.p_WI = s0.p_WB;
    x.v_WI = s0.v_WB;
    tr.biases(t0, x.bg, x.ba);
    prop.propagate(x, tr.imuSamples(), x.t_ns + 1'000'000'000);
    ep.push_back((x.p_WI - s1.p_WB).norm());
  }
  std::printf("1 s of real IMU from the spline truth: median position error %.1f mm (%zu windows)\n",
              median(ep) * 1e3, ep.size());
  EXPECT_LT(median(ep), 0.05);
}

// The EuRoC ground truth's clock against the IMU's: the lag τ that best matches the real gyro
// (bias removed) to the truth's angular rate, ω_gyro(t) ≈ ω_truth(t + τ), on 50 ms means. On the
// bundled 40 s of V1_02 the truth lags by about 0.7 ms (0.655 ms). A camera simulated from this
// truth with offset t_d is therefore offset by t_d − τ on the IMU's clock, which is what the
// replay's time-offset calibration must recover (tests/fusion/test_replay_time_offset.cpp).
TEST(RecordedTrajectory, GroundTruthLagsTheGyroByAboutOneMillisecond) {
  const RecordedTrajectory& tr = trajectory();
  const std::vector<double> cost = gyroLagCost(tr, -3e-3, 3e-3, 0.25e-3);
  const auto best = std::min_element(cost.begin(), cost.end()) - cost.begin();
  ASSERT_GT(best, 0);
  ASSERT_LT(best, static_cast<long>(cost.size()) - 1);
  const double lag = gyroLag(tr);
  std::printf("gyro against truth angular rate: lag %.3f ms, mean squared residual %.6f (rad/s)^2 at the lag, "
              "%.6f at 0, %.6f at -3 ms, %.6f at +3 ms\n",
              lag * 1e3, cost[static_cast<std::size_t>(best)], cost[cost.size() / 2], cost.front(), cost.back());
  EXPECT_GT(lag, 0.4e-3);
  EXPECT_LT(lag, 1.0e-3);
  // A clear minimum: 3 ms either side costs 4-10 % more (what the 50 ms means leave of the
  // vibration, ~0.034 rad/s RMS, is the floor).
  EXPECT_GT(cost.front(), cost[static_cast<std::size_t>(best)] * 1.05);
  EXPECT_GT(cost.back(), cost[static_cast<std::size_t>(best)] * 1.02);
}

// The lag estimate follows a known shift of the IMU stamps: stamping every sample 1.5 ms late
// makes the gyro lag the truth by 1.5 ms more (τ − 1.5 ms).
TEST(RecordedTrajectory, GyroLagFollowsShiftedImuStamps) {
  const RecordedTrajectoryConfig c = v102();
  std::vector<vio::ImuSample> imu = vio::readImuCsv(c.imuCsv);
  const auto truth = vio::readGroundTruthCsv(c.groundTruthCsv);
  const double base = gyroLag(trajectory());
  for (vio::ImuSample& m : imu) m.t_ns += 1'500'000;
  const RecordedTrajectory shifted(imu, truth, c);
  const double lag = gyroLag(shifted);
  std::printf("lag %.3f ms, with the IMU stamped 1.5 ms late %.3f ms\n", base * 1e3, lag * 1e3);
  EXPECT_NEAR(lag, base - 1.5e-3, 0.1e-3);
  EXPECT_THROW(gyroLagCost(shifted, 1e-3, 0.0, 1e-4), std::invalid_argument);
  EXPECT_THROW(gyroLag(shifted, 0.0), std::invalid_argument);
}

TEST(RecordedTrajectory, RejectsBadSpans) {
  RecordedTrajectoryConfig c = v102();
  c.startOffset = 500.0;
  EXPECT_THROW((RecordedTrajectory(c)), std::invalid_argument);
  c = v102();
  c.knotInterval = 0.0;
  EXPECT_THROW((RecordedTrajectory(c)), std::invalid_argument);
  c = v102();
  c.imuCsv = "/nonexistent/imu.csv";
  EXPECT_THROW((RecordedTrajectory(c)), ParseError);
}

}  // namespace
}  // namespace gvins::sim
