// GnssInsAlignment (gnss_ins_alignment.hpp) against simulation truth: an exact IMU and exact
// GNSS velocities/positions of a circle flown with the body yawed 30° off the velocity and a gyro
// bias, and of a straight line at constant velocity (yaw unobservable), also over many window
// slides.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdio>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "gvins/fusion/gnss_ins_alignment.hpp"
#include "gvins/vio/so3.hpp"

namespace gvins::fusion {
namespace {

constexpr double kG = 9.81;
const Eigen::Vector3d kEcef0(-3737000.0, 3482000.0, 3648000.0);
const Eigen::Vector3d kBias(0.004, -0.003, 0.002);  // rad/s gyro bias in the IMU readings

struct Truth {
  Eigen::Matrix3d R;     // R_NI
  Eigen::Vector3d p, v;  // ENU at kEcef0
};

// Circle of radius r at angular rate w (w = 0: straight line at 8 m/s along x), tilted body.
Truth truthAt(double t, double r, double w) {
  const Eigen::Matrix3d tilt = (Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitX()) *
                                Eigen::AngleAxisd(-0.03, Eigen::Vector3d::UnitY())).toRotationMatrix();
  Truth x;
  if (w == 0.0) {
    x.p = Eigen::Vector3d(8.0 * t, 0, 0);
    x.v = Eigen::Vector3d(8.0, 0, 0);
    x.R = Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()).toRotationMatrix() * tilt;
    return x;
  }
  x.p = Eigen::Vector3d(r * std::sin(w * t), r * (1.0 - std::cos(w * t)), 0);
  x.v = Eigen::Vector3d(r * w * std::cos(w * t), r * w * std::sin(w * t), 0);
  x.R = Eigen::AngleAxisd(w * t + 0.5236, Eigen::Vector3d::UnitZ()).toRotationMatrix() * tilt;
  return x;
}

std::vector<vio::ImuSample> imuOf(double r, double w, double T) {
  std::vector<vio::ImuSample> out;
  for (int i = 0; i <= static_cast<int>(T * 200); ++i) {
    const double t = i / 200.0;
    const Truth x = truthAt(t, r, w);
    const Eigen::Vector3d a = w == 0.0 ? Eigen::Vector3d::Zero()
                                       : Eigen::Vector3d(-r * w * w * std::sin(w * t), r * w * w * std::cos(w * t), 0);
    vio::ImuSample s;
    s.t_ns = static_cast<std::int64_t>(i) * 5'000'000;
    s.gyro = x.R.transpose() * Eigen::Vector3d(0, 0, w) + kBias;
    s.accel = x.R.transpose() * (a - Eigen::Vector3d(0, 0, -kG));
    out.push_back(s);
  }
  return out;
}

SppSolution sppAt(const Truth& x) {
  const GnssAnchor an = GnssAnchor::at(kEcef0);
  SppSolution s;
  s.status = SppStatus::Ok;
  s.position = kEcef0 + an.R_EN * x.p;
  s.positionCovariance = Eigen::Matrix3d::Identity() * 4.0;
  s.velocity.valid = true;
  s.velocity.velocity = an.R_EN * x.v;
  s.velocity.covariance = Eigen::Matrix3d::Identity() * 0.0025;
  return s;
}

TEST(GnssInsAlignment, TurnGivesTheAttitude) {
  const double r = 20.0, w = 0.4;  // 8 m/s, 3.2 m/s² centripetal: a UAV's turn
  const auto imu = imuOf(r, w, 6.0);
  GnssInsAlignment al({}, vio::ImuNoise{}, kG);
  std::optional<vio::ExternalInitialState> s;
  double t = 0.0;
  for (; t <= 5.0 + 1e-9 && !s; t += 0.2) {
    s = al.add(static_cast<std::int64_t>(std::llround(t * 1e9)), sppAt(truthAt(t, r, w)), imu, Eigen::Vector3d::Zero());
  }
  ASSERT_TRUE(s.has_value()) << gnssInsStatusText(al.status()) << " yaw σ " << al.yawSigmaDeg() << " tilt σ " << al.tiltSigmaDeg();
  const Truth x = truthAt(static_cast<double>(s->state.t_ns) * 1e-9, r, w);
  // The alignment's ENU is at its first fix, which is kEcef0 (t = 0).
  const double err = vio::so3::log(x.R.transpose() * s->state.R_WI).norm() * 57.29577951308232;
  std::printf("accepted after %.1f s: attitude error %.3f deg, yaw sigma %.2f deg, bg error %.4f rad/s\n", t, err,
              al.yawSigmaDeg(), (s->state.bg - kBias).norm());
  // Measured: accepted after 3.2 s (yaw σ 3.7°), attitude error 2.1°: the gyro bias is not
  // observable within the window of a constant-rate turn, and its prior is what the σ carries.
  EXPECT_LT(err, 2.0 * al.yawSigmaDeg()) << "attitude error deg";
  EXPECT_LT(err, 5.0);
  EXPECT_LT((s->state.v_WI - x.v).norm(), 1e-4);  // the epoch's Doppler velocity (exact here)
  EXPECT_LT(al.yawSigmaDeg(), 5.0);
  EXPECT_LT(t, 5.0);  // accepted within 5 s of the first epoch
}

TEST(GnssInsAlignment, ConstantVelocityLeavesTheYawOpen) {
  const auto imu = imuOf(0.0, 0.0, 6.0);
  GnssInsAlignment al({}, vio::ImuNoise{}, kG);
  for (double t = 0.0; t <= 5.8; t += 0.2) {
    EXPECT_FALSE(al.add(static_cast<std::int64_t>(std::llround(t * 1e9)), sppAt(truthAt(t, 0.0, 0.0)), imu,
                        Eigen::Vector3d::Zero()));
  }
  EXPECT_EQ(al.status(), GnssInsStatus::kNoAcceleration);
  EXPECT_LT(al.tiltSigmaDeg(), 1.0);  // the tilt is known from gravity
}

// Two epochs fix v_0 and the attitude about one velocity change only: whatever the thresholds,
// no state, and no yaw σ from the singular information (the inverse reported 0° on a walk).
TEST(GnssInsAlignment, TwoEpochsAreNotEnough) {
  const double r = 20.0, w = 0.4;
  const auto imu = imuOf(r, w, 1.0);
  GnssInsAlignmentConfig c;
  c.maxYawSigmaDeg = 180.0;
  c.maxTiltSigmaDeg = 180.0;
  GnssInsAlignment al(c, vio::ImuNoise{}, kG);
  EXPECT_FALSE(al.add(100'000'000, sppAt(truthAt(0.1, r, w)), imu, Eigen::Vector3d::Zero()));
  EXPECT_FALSE(al.add(200'000'000, sppAt(truthAt(0.2, r, w)), imu, Eigen::Vector3d::Zero()));
  EXPECT_EQ(al.status(), GnssInsStatus::kCollecting);
  EXPECT_FALSE(al.yawSigmaDeg() < 180.0);  // none (NaN)
  // A third epoch gives the yaw from the turn's second velocity change: a σ, large after 0.2 s.
  EXPECT_FALSE(al.add(300'000'000, sppAt(truthAt(0.3, r, w)), imu, Eigen::Vector3d::Zero()));
  EXPECT_TRUE(std::isfinite(al.yawSigmaDeg()));
  EXPECT_GT(al.yawSigmaDeg(), 180.0);
}

// A window that slides for a long time (10 Hz epochs, 30 s of a straight line: 250 re-basings)
// must keep its fit: before the re-basing kept R_0k a rotation, the products compounded their
// rounding and the fit went to NaN after about 60 slides (seen on a simulated walk).
TEST(GnssInsAlignment, LongSlidingWindowStaysFinite) {
  const auto imu = imuOf(0.0, 0.0, 31.0);
  GnssInsAlignment al({}, vio::ImuNoise{}, kG);
  for (int k = 0; k <= 300; ++k) {
    const double t = 0.1 * k;
    ASSERT_FALSE(al.add(static_cast<std::int64_t>(k) * 100'000'000, sppAt(truthAt(t, 0.0, 0.0)), imu,
                        Eigen::Vector3d::Zero()));
    if (k < 10) continue;  // the tilt needs a second of epochs
    ASSERT_EQ(al.status(), GnssInsStatus::kNoAcceleration) << "t " << t;
    ASSERT_TRUE(std::isfinite(al.yawSigmaDeg())) << "t " << t;
    ASSERT_LT(al.tiltSigmaDeg(), 1.0) << "t " << t;
  }
}

}  // namespace
}  // namespace gvins::fusion
