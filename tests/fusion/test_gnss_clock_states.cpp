// GnssClockStates against the clock model written out by hand: the systems and their order, the
// values after creation and propagation, the clock block's covariance Φ P Φᵀ + Q of the two-state
// clock model (Brown & Hwang, "Introduction to Random Signals and Applied Kalman Filtering",
// 4th ed., sec. 9.3) and the ISB random walk stepped only every isbRenewalInterval.
#include <gtest/gtest.h>

#include <array>
#include <vector>

#include "gvins/fusion/gnss_clock_states.hpp"
#include "imu_gnss_test_backend.hpp"

namespace gvins::fusion {
namespace {

TEST(GnssClockStates, FollowTheTwoStateClockModel) {
  const std::vector<vio::ImuSample> samples;  // no IMU propagation here
  testing::ImuGnssTestBackend<double> be(vio::ImuNoise{}, 9.81, samples, vio::ImuState{},
                                         Eigen::Matrix<double, 15, 1>::Ones());
  GnssClockStates<double> c;
  EXPECT_FALSE(c.valid());
  const std::array<SatId, 4> sats{SatId(System::Galileo, 3), SatId(System::Gps, 5), SatId(System::Qzss, 2),
                                  SatId(System::Galileo, 11)};
  ASSERT_TRUE(c.setSystems(sats));
  EXPECT_EQ(c.systems(), (std::vector<System>{System::Gps, System::Galileo}));  // sorted; QZSS on GPS's clock
  EXPECT_EQ(c.index(SatId(System::Qzss, 2)), 0);
  EXPECT_EQ(c.index(SatId(System::Galileo, 30)), 1);
  EXPECT_EQ(c.index(SatId(System::BeiDou, 1)), -1);

  // b_GPS = 1000 m (σ 5), b_GAL = 1012.5 m (σ 7), drift 0.4 m/s (σ 0.3).
  const GpsTime t0 = GpsTime::fromWeekTow(2320, 116400.0);
  c.create(be, {1000.0, 1012.5, 0.4}, {5.0, 7.0, 0.3}, t0);
  ASSERT_TRUE(c.valid());
  EXPECT_LT((c.values(be) - Eigen::Vector3d(1000.0, 1012.5, 0.4)).norm(), 1e-9);
  const std::array<sri::BlockId, 1> clock0{c.clockBlock()};
  const std::array<sri::BlockId, 1> isb0{c.isbBlock()};
  ASSERT_TRUE(be.informed(clock0));
  ASSERT_TRUE(be.informed(isb0));
  // The ISB row c + i = x_GAL ties the uninformed i to c: it adds nothing to c's marginal, and
  // var(i) = σ_GAL² + σ_GPS².
  const Eigen::Matrix2d P0 = be.covariance(clock0);
  EXPECT_LT((P0 - Eigen::Vector2d(25.0, 0.09).asDiagonal().toDenseMatrix()).norm(), 1e-9);
  EXPECT_NEAR(be.covariance(isb0)(0, 0), 49.0 + 25.0, 1e-9);

  GnssFusionConfig cfg;
  cfg.clockBiasRandomWalk = 0.2;
  cfg.clockDriftRandomWalk = 0.05;
  cfg.isbRandomWalk = 0.01;
  cfg.isbRenewalInterval = 5.0;
  const double dt = 2.0, qb = 0.04, qd = 0.0025;
  c.propagate(be, t0 + dt, cfg);
  EXPECT_LT((c.values(be) - Eigen::Vector3d(1000.8, 1013.3, 0.4)).norm(), 1e-9);  // b += ḋ·Δt
  Eigen::Matrix2d Phi, Q;
  Phi << 1.0, dt, 0.0, 1.0;
  Q << qb * dt + qd * dt * dt * dt / 3.0, qd * dt * dt / 2.0, qd * dt * dt / 2.0, qd * dt;
  const std::array<sri::BlockId, 1> clock1{c.clockBlock()};
  EXPECT_NE(clock1[0], clock0[0]);  // the block is replaced
  EXPECT_LT((be.covariance(clock1) - (Phi * P0 * Phi.transpose() + Q)).norm(), 1e-9);
  EXPECT_EQ(c.isbBlock(), isb0[0]);  // 2 s < isbRenewalInterval: the ISBs are not stepped
  EXPECT_DOUBLE_EQ(c.time() - t0, dt);

  // At 6 s the ISB block takes one step of q²·6 s.
  const double varIsb = be.covariance(isb0)(0, 0);
  c.propagate(be, t0 + 6.0, cfg);
  const std::array<sri::BlockId, 1> isb1{c.isbBlock()};
  EXPECT_NE(isb1[0], isb0[0]);
  EXPECT_NEAR(be.covariance(isb1)(0, 0), varIsb + 0.0001 * 6.0, 1e-9);
  EXPECT_LT((c.values(be) - Eigen::Vector3d(1002.4, 1014.9, 0.4)).norm(), 1e-9);

  // An outage drops the blocks but keeps the systems; a new state forgets both.
  c.marginalize(be);
  EXPECT_FALSE(c.valid());
  EXPECT_FALSE(be.contains(isb1[0]));
  EXPECT_EQ(c.systems().size(), 2u);
  c.forget();
  EXPECT_TRUE(c.systems().empty());
}

}  // namespace
}  // namespace gvins::fusion
