// Simulated IMU: noise-free samples integrated by vio's ImuPropagator reproduce the truth
// (< 1 mm after 60 s); the rotating-Earth model against finite differences in an inertial
// frame; white-noise and bias-walk statistics; reproducibility from the seed.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "gvins/base/constants.hpp"
#include "gvins/sim/flight_pattern.hpp"
#include "gvins/sim/imu_simulator.hpp"
#include "gvins/sim/normal_gravity.hpp"
#include "gvins/vio/imu_propagation.hpp"
#include "gvins/vio/so3.hpp"

namespace gvins::sim {
namespace {

using V3 = Eigen::Vector3d;

LocalFrame nagoya() {
  LocalFrame f;
  f.origin = geodeticFromDegrees(35.1347, 136.9776, 104.85);
  f.startTime = GpsTime::fromCalendar({2024, 6, 24, 8, 20, 0.0});
  return f;
}

ImuSimConfig noiseFree(double rate) {
  ImuSimConfig c;
  c.rateHz = rate;
  c.whiteNoise = false;
  c.biasRandomWalk = false;
  c.gyroBiasSigma = 0.0;
  c.accelBiasSigma = 0.0;
  return c;
}

vio::ImuState truthState(const Trajectory& tr, const LocalFrame& f, double t) {
  const TrajectoryState s = tr.evaluate(t);
  vio::ImuState x;
  x.t_ns = f.stampNs(t);
  x.R_WI = s.R_WB;
  x.p_WI = s.p_WB;
  x.v_WI = s.v_WB;
  return x;
}

void expectIntegrationReproducesTruth(const FlightSpec& spec, double rate, double t0, double span) {
  const auto tr = buildFlight(spec, 11);
  ASSERT_GT(tr->duration(), t0 + span + 1.0);
  const LocalFrame f = nagoya();
  const ImuSimConfig cfg = noiseFree(rate);
  const SimulatedImu imu = simulateImu(*tr, f, cfg, 1);
  vio::ImuNoise noise;
  noise.rate_hz = rate;
  const vio::ImuPropagator prop(noise, imu.gravity);
  vio::ImuState x = truthState(*tr, f, t0);
  prop.propagate(x, imu.samples, f.stampNs(t0 + span));
  const vio::ImuState truth = truthState(*tr, f, t0 + span);
  const double dp = (x.p_WI - truth.p_WI).norm();
  const double dv = (x.v_WI - truth.v_WI).norm();
  const double dth = vio::so3::log(truth.R_WI.transpose() * x.R_WI).norm();
  std::printf("%s %.0f Hz, %.0f s: |dp| = %.3g m, |dv| = %.3g m/s, |dtheta| = %.3g rad\n", toString(spec.pattern),
              rate, span, dp, dv, dth);
  EXPECT_LT(dp, 1e-3);
  EXPECT_LT(dv, 1e-4);
  EXPECT_LT(dth, 1e-6);
}

TEST(ImuSimulator, NoiseFreeLawnmowerIntegratesToTruth200Hz) {
  FlightSpec spec;
  spec.height = 60.0;
  spec.length = 1000.0;
  spec.speed = 10.0;
  spec.wobbleDeg = 1.0;
  // 60 s through take-off, rows and turns.
  expectIntegrationReproducesTruth(spec, 200.0, 5.0, 60.0);
}

TEST(ImuSimulator, NoiseFreeFigureEightIntegratesToTruth250Hz) {
  FlightSpec spec;
  spec.pattern = FlightPattern::FigureEight;
  spec.length = 900.0;
  spec.speed = 12.0;
  spec.wobbleDeg = 0.5;
  expectIntegrationReproducesTruth(spec, 250.0, 10.0, 60.0);
}

TEST(ImuSimulator, NoiseFreeDriveIntegratesToTruth) {
  FlightSpec spec;
  spec.pattern = FlightPattern::Drive;
  spec.length = 1000.0;
  spec.speed = 12.0;
  spec.restHeight = 1.0;
  spec.height = 2.0;
  expectIntegrationReproducesTruth(spec, 200.0, 0.0, 60.0);
}

TEST(ImuSimulator, SamplesAtStampsAndAtRestMeasureGravity) {
  FlightSpec spec;
  spec.length = 400;
  spec.rows = 2;
  const auto tr = buildFlight(spec, 1);
  const LocalFrame f = nagoya();
  const SimulatedImu imu = simulateImu(*tr, f, noiseFree(200.0), 1);
  ASSERT_GT(imu.samples.size(), 100u);
  EXPECT_EQ(imu.period_ns, 5'000'000);
  EXPECT_EQ(imu.samples[0].t_ns, f.startStampNs());
  for (std::size_t i = 1; i < imu.samples.size(); ++i) ASSERT_EQ(imu.samples[i].t_ns - imu.samples[i - 1].t_ns, 5'000'000);
  EXPECT_LE(static_cast<double>(imu.samples.back().t_ns - f.startStampNs()) * 1e-9, tr->duration());
  // Default flat gravity = normal gravity at the origin; independent value from the 1980
  // international gravity formula (GRS 80) with the free-air gradient -3.086e-6 s^-2:
  // 9.780327 (1 + 0.0053024 sin^2 phi - 0.0000058 sin^2 2 phi) - 3.086e-6 h = 9.797129.
  EXPECT_NEAR(imu.gravity, 9.797129, 2e-5);
  EXPECT_NEAR((imu.samples[0].accel - V3(0, 0, imu.gravity)).norm(), 0.0, 1e-12);
  EXPECT_NEAR(imu.samples[0].gyro.norm(), 0.0, 1e-15);
}

TEST(NormalGravity, SomiglianaValues) {
  // NIMA TR8350.2: gamma_e = 9.7803253359 at the equator, gamma_p = 9.8321849378 at the poles.
  EXPECT_NEAR(normalGravity(geodeticFromDegrees(0, 0, 0)), 9.7803253359, 1e-10);
  EXPECT_NEAR(normalGravity(geodeticFromDegrees(90, 0, 0)), 9.8321849378, 1e-9);
  // Free-air gradient ~ -3.086e-6 s^-2.
  const double g0 = normalGravity(geodeticFromDegrees(45, 0, 0)), g1 = normalGravity(geodeticFromDegrees(45, 0, 1000));
  EXPECT_NEAR((g1 - g0) / 1000.0, -3.086e-6, 0.01e-6);
}

TEST(ImuSimulator, RotatingEarthMatchesInertialFiniteDifferences) {
  // Independent derivation: the IMU's ECEF position r_E(t) seen from an inertial frame aligned
  // with ECEF at t is r_I(t) = Rz(w t) r_E(t); specific force = r_I'' - gravitation, with
  // gravitation = normal gravity + w x (w x r) (normal gravity includes the centrifugal term).
  // Gyro = angular velocity of B w.r.t. the inertial frame.
  FlightSpec spec;
  spec.pattern = FlightPattern::Circle;
  spec.length = 600;
  spec.laps = 1;
  spec.speed = 12;
  spec.takeoffLanding = false;
  const auto tr = buildFlight(spec, 1);
  const LocalFrame f = nagoya();
  ImuSimConfig cfg = noiseFree(200.0);
  cfg.earth = EarthModel::Rotating;
  const Eigen::Matrix3d R_EW = f.rotationEcefFromW();
  const double w = constants::kWgs84OmegaE;
  auto rz = [&](double a) {
    Eigen::Matrix3d m;
    m << std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a), 0, 0, 0, 1;
    return m;
  };
  auto rI = [&](double t) { return V3(rz(w * t) * f.toEcef(tr->position(t))); };
  auto RIB = [&](double t) { return Eigen::Matrix3d(rz(w * t) * R_EW * tr->orientation(t)); };
  for (double t : {20.0, 35.5, 51.25}) {
    // 5-point second difference of a ~6e6 m vector: differences relative to r_I(t) and a step
    // where truncation (h^4) and rounding (1e-9 m / h^2) balance.
    const double h = 0.05;
    const V3 r0 = rI(t);
    const V3 acc = (-(rI(t + 2 * h) - r0) + 16.0 * (rI(t + h) - r0) + 16.0 * (rI(t - h) - r0) - (rI(t - 2 * h) - r0)) /
                   (12.0 * h * h);
    const V3 rE = f.toEcef(tr->position(t));
    const V3 gravitationE = normalGravityEcef(ecefToGeodetic(rE)) + V3(0, 0, w).cross(V3(0, 0, w).cross(rE));
    const V3 fI = acc - rz(w * t) * gravitationE;
    const V3 fB = RIB(t).transpose() * fI;
    const double hr = 1e-4;
    const V3 omegaFd = vio::so3::log(RIB(t).transpose() * RIB(t + hr)) / hr -
                       vio::so3::log(RIB(t).transpose() * RIB(t - hr)) / hr;
    V3 gyro, accel;
    idealImu(tr->evaluate(t), f, cfg, 0.0, gyro, accel);
    EXPECT_LT((accel - fB).norm(), 1e-5) << t;
    EXPECT_LT((gyro - 0.5 * omegaFd).norm(), 1e-7) << t;
    // The Earth rate is visible: differs from the flat model by ~7e-5 rad/s.
    EXPECT_NEAR((gyro - tr->evaluate(t).omega_B).norm(), w, 1e-12);
  }
}

TEST(ImuSimulator, NoiseStatisticsFollowTheDensities) {
  FlightSpec spec;
  spec.length = 400;
  spec.rows = 2;
  spec.takeoffLanding = false;
  spec.hoverStart = 400.0;  // 400 s at rest
  const auto tr = buildFlight(spec, 1);
  const LocalFrame f = nagoya();
  ImuSimConfig cfg;  // defaults: EuRoC ADIS16448 noise, random turn-on biases
  cfg.rateHz = 200.0;
  const SimulatedImu imu = simulateImu(*tr, f, cfg, 42);
  const SimulatedImu clean = simulateImu(*tr, f, noiseFree(200.0), 42);
  const std::size_t n = 70000;  // 350 s at rest
  ASSERT_GT(imu.samples.size(), n);
  double sg = 0, sa = 0, sbg = 0, sba = 0;
  for (std::size_t i = 0; i < n; ++i) {
    sg += (imu.samples[i].gyro - clean.samples[i].gyro - imu.gyroBias[i]).squaredNorm();
    sa += (imu.samples[i].accel - clean.samples[i].accel - imu.accelBias[i]).squaredNorm();
    sbg += (imu.gyroBias[i + 1] - imu.gyroBias[i]).squaredNorm();
    sba += (imu.accelBias[i + 1] - imu.accelBias[i]).squaredNorm();
  }
  const double dt = 0.005;
  const vio::ImuNoise q;
  // Per-axis standard deviations within 1 % (210000 draws each).
  EXPECT_NEAR(std::sqrt(sg / (3 * n)), q.gyroscope_noise_density / std::sqrt(dt), 0.01 * q.gyroscope_noise_density / std::sqrt(dt));
  EXPECT_NEAR(std::sqrt(sa / (3 * n)), q.accelerometer_noise_density / std::sqrt(dt),
              0.01 * q.accelerometer_noise_density / std::sqrt(dt));
  EXPECT_NEAR(std::sqrt(sbg / (3 * n)), q.gyroscope_random_walk * std::sqrt(dt), 0.01 * q.gyroscope_random_walk * std::sqrt(dt));
  EXPECT_NEAR(std::sqrt(sba / (3 * n)), q.accelerometer_random_walk * std::sqrt(dt),
              0.01 * q.accelerometer_random_walk * std::sqrt(dt));
  // Turn-on biases are drawn (not zero) and reproducible; another seed gives others.
  EXPECT_GT(imu.gyroBias[0].norm(), 1e-4);
  const SimulatedImu again = simulateImu(*tr, f, cfg, 42), other = simulateImu(*tr, f, cfg, 43);
  EXPECT_EQ(again.samples[1234].gyro, imu.samples[1234].gyro);
  EXPECT_EQ(again.samples[1234].accel, imu.samples[1234].accel);
  EXPECT_NE(other.samples[1234].gyro, imu.samples[1234].gyro);
}

}  // namespace
}  // namespace gvins::sim
