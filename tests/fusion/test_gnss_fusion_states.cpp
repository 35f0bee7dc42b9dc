// The GNSS fusion's owners of the zenith wet delay, lever-arm and float ambiguity blocks
// (gnss_zwd_state.hpp, gnss_lever_arm_state.hpp, gnss_ambiguity_states.hpp) against the values
// written out by hand: the prior at creation, a scalar Kalman update x' = x + K (z − x), P' = P −
// K P for a measurement on the block (the filter's information form gives the same), the random
// walk P + q²·Δt, the lever arm's carry-over test (3 prior σ per axis) and the removal of blocks.
#include <gtest/gtest.h>

#include <array>
#include <map>
#include <stdexcept>
#include <vector>

#include "gvins/fusion/gnss_ambiguity_states.hpp"
#include "gvins/fusion/gnss_lever_arm_state.hpp"
#include "gvins/fusion/gnss_zwd_state.hpp"
#include "imu_gnss_test_backend.hpp"

namespace gvins::fusion {
namespace {

using Backend = testing::ImuGnssTestBackend<double>;

Backend makeBackend() {
  static const std::vector<vio::ImuSample> samples;  // no IMU propagation here
  return Backend(vio::ImuNoise{}, 9.81, samples, vio::ImuState{}, Eigen::Matrix<double, 15, 1>::Ones());
}

/// Applies z = a·x_1 (+ b·x_2) with noise σ to the blocks (one row, no gate).
void measure(Backend& be, sri::BlockId x1, double a, double z, double sigma, sri::BlockId x2 = {}, double b = 0.0,
             double h = 0.0) {
  sri::Measurement<double> m(1);
  m.jacobian(x1, 1)(0, 0) = a / sigma;
  if (x2.valid()) m.jacobian(x2, 1)(0, 0) = b / sigma;
  m.residual()[0] = (z - h) / sigma;  // h: the prediction at the current estimates
  m.setWhitened();
  ASSERT_TRUE(be.update(m, 1.0).applied);
}

double variance(const Backend& be, sri::BlockId id) {
  const std::array<sri::BlockId, 1> ids{id};
  return be.covariance(ids)(0, 0);
}

const GpsTime kT0 = GpsTime::fromWeekTow(2320, 116400.0);

TEST(GnssZwdState, PriorRandomWalkAndRemoval) {
  Backend be = makeBackend();
  GnssZwdState<double> z;
  EXPECT_FALSE(z.valid());
  z.create(be, kT0, 0.05);
  ASSERT_TRUE(z.valid());
  EXPECT_EQ(z.value(be), 0.0);  // the model's wet delay
  EXPECT_NEAR(variance(be, z.block()), 0.0025, 1e-15);
  EXPECT_DOUBLE_EQ(z.time() - kT0, 0.0);

  // A measurement of the residual, 0.03 m ± 0.05: K = 0.0025 / 0.005 = 0.5.
  measure(be, z.block(), 1.0, 0.03, 0.05);
  EXPECT_NEAR(z.value(be), 0.015, 1e-12);
  EXPECT_NEAR(variance(be, z.block()), 0.00125, 1e-15);

  // No step backwards or at the same time.
  const sri::BlockId b0 = z.block();
  z.propagate(be, kT0 - 1.0, 2e-4);
  z.propagate(be, kT0, 2e-4);
  EXPECT_EQ(z.block(), b0);

  // 100 s of a 2e-4 m/√s random walk: one step of 4e-6 m², the estimate stays.
  z.propagate(be, kT0 + 100.0, 2e-4);
  EXPECT_NE(z.block(), b0);
  EXPECT_FALSE(be.contains(b0));
  EXPECT_NEAR(z.value(be), 0.015, 1e-12);
  EXPECT_NEAR(variance(be, z.block()), 0.00125 + 4e-6, 1e-15);
  EXPECT_DOUBLE_EQ(z.time() - kT0, 100.0);

  const sri::BlockId b1 = z.block();
  z.marginalize(be);
  EXPECT_FALSE(z.valid());
  EXPECT_FALSE(be.contains(b1));
  z.create(be, kT0 + 200.0, 0.05);  // after an outage: a new block with the prior again
  EXPECT_EQ(z.value(be), 0.0);
  EXPECT_NEAR(variance(be, z.block()), 0.0025, 1e-15);
  const sri::BlockId b2 = z.block();
  z.forget();  // the estimator's state is gone: the block is not touched
  EXPECT_FALSE(z.valid());
  EXPECT_TRUE(be.contains(b2));
}

TEST(GnssLeverArmState, PriorConstantAndCarryOver) {
  const Eigen::Vector3d configured(0.1, 0.2, 0.3);
  GnssLeverArmState<double> l(configured, 0.2);
  EXPECT_FALSE(l.valid());
  EXPECT_EQ(l.value(nullptr), configured);  // no block: the configured value
  EXPECT_EQ(l.start(), configured);

  Backend be = makeBackend();
  l.create(be);
  ASSERT_TRUE(l.valid());
  const sri::BlockId b0 = l.block();
  l.create(be);  // exists: kept
  EXPECT_EQ(l.block(), b0);
  const std::array<sri::BlockId, 1> ids{b0};
  EXPECT_LT((be.covariance(ids) - 0.04 * Eigen::Matrix3d::Identity()).norm(), 1e-15);
  EXPECT_LT((l.value(&be) - configured).norm(), 1e-15);
  EXPECT_EQ(l.value(nullptr), configured);  // without the state: nothing recorded yet

  // x measured 0.5 ± 0.2: K = 0.5, x = 0.3, var 0.02; y and z untouched. Constant: the block
  // stays what it is while the epochs go by.
  sri::Measurement<double> m(1);
  m.jacobian(b0, 3)(0, 0) = 1.0 / 0.2;
  m.residual()[0] = (0.5 - 0.1) / 0.2;
  m.setWhitened();
  ASSERT_TRUE(be.update(m, 1.0).applied);
  EXPECT_LT((l.value(&be) - Eigen::Vector3d(0.3, 0.2, 0.3)).norm(), 1e-12);
  EXPECT_LT((be.covariance(ids) - Eigen::Vector3d(0.02, 0.04, 0.04).asDiagonal().toDenseMatrix()).norm(), 1e-15);
  EXPECT_EQ(l.block(), b0);

  // The estimator starts a new state: the estimate, 0.2 m from the configured value (< 3σ = 0.6
  // m), is the next block's start.
  l.record(be);
  EXPECT_LT((l.carried() - Eigen::Vector3d(0.3, 0.2, 0.3)).norm(), 1e-12);
  l.forget();
  EXPECT_FALSE(l.valid());
  EXPECT_LT((l.start() - Eigen::Vector3d(0.3, 0.2, 0.3)).norm(), 1e-12);
  EXPECT_LT((l.value(nullptr) - l.start()).norm(), 1e-15);

  Backend be2 = makeBackend();
  l.create(be2);
  const std::array<sri::BlockId, 1> ids2{l.block()};
  EXPECT_LT((l.value(&be2) - Eigen::Vector3d(0.3, 0.2, 0.3)).norm(), 1e-12);
  EXPECT_LT((be2.covariance(ids2) - 0.04 * Eigen::Matrix3d::Identity()).norm(), 1e-15);  // the prior again
  // A state that runs away: x measured 2.0 ± 0.1 gives (0.3/0.04 + 2/0.01) / (1/0.04 + 1/0.01) = 1.66 m,
  // 1.56 m from the configured 0.1 (> 0.6): not carried over, the start stays.
  sri::Measurement<double> m2(1);
  m2.jacobian(l.block(), 3)(0, 0) = 1.0 / 0.1;
  m2.residual()[0] = (2.0 - 0.3) / 0.1;
  m2.setWhitened();
  ASSERT_TRUE(be2.update(m2, 1.0).applied);
  EXPECT_NEAR(l.value(&be2).x(), 1.66, 1e-12);
  l.record(be2);
  EXPECT_LT((l.carried() - Eigen::Vector3d(0.3, 0.2, 0.3)).norm(), 1e-12);
  l.forget();
  EXPECT_LT((l.start() - Eigen::Vector3d(0.3, 0.2, 0.3)).norm(), 1e-12);
}

TEST(GnssAmbiguityStates, PriorRandomWalkOfBroadcastSatellitesAndRemoval) {
  Backend be = makeBackend();
  GnssAmbiguityStates<double> a;
  const SatId g5(System::Gps, 5), e11(System::Galileo, 11), c1(System::BeiDou, 1);
  EXPECT_TRUE(a.empty());
  EXPECT_FALSE(a.block(g5).valid());
  EXPECT_EQ(a.arc(g5), nullptr);
  GnssAmbiguityArc& arcG = a.add(be, g5, 12.5, 3.0, kT0 - 40.0);
  EXPECT_DOUBLE_EQ(arcG.start - kT0, -40.0);
  a.add(be, e11, -4.0, 30.0, kT0);
  EXPECT_THROW(a.add(be, e11, 0.0, 30.0, kT0), std::logic_error);  // one state per satellite
  ASSERT_EQ(a.size(), 2u);
  EXPECT_TRUE(a.contains(g5));
  EXPECT_FALSE(a.contains(c1));
  EXPECT_EQ(a.values(be), (std::map<SatId, double>{{g5, 12.5}, {e11, -4.0}}));
  EXPECT_NEAR(variance(be, a.block(g5)), 9.0, 1e-12);
  EXPECT_NEAR(variance(be, a.block(e11)), 900.0, 1e-9);

  // A row on the difference N_G5 − N_E11 = 20 ± 1 (prediction 16.5): with P = diag(9, 900),
  // h = [1, −1], S = h P hᵀ + 1 = 910, P hᵀ = [9, −900]: x' = x + P hᵀ (20 − 16.5) / S and
  // P' = P − P hᵀ h P / S.
  measure(be, a.block(g5), 1.0, 20.0, 1.0, a.block(e11), -1.0, 16.5);
  const Eigen::Vector2d Ph(9.0, -900.0);
  const Eigen::Vector2d x1 = Eigen::Vector2d(12.5, -4.0) + Ph * (3.5 / 910.0);
  const Eigen::Matrix2d P1 = Eigen::Vector2d(9.0, 900.0).asDiagonal().toDenseMatrix() - Ph * Ph.transpose() / 910.0;
  EXPECT_NEAR(a.value(be, g5), x1[0], 1e-9);
  EXPECT_NEAR(a.value(be, e11), x1[1], 1e-9);

  // The first call only sets the time; then G5 (on broadcast records) takes one step of
  // q²·Δt = 0.005²·4 m², E11 (on products, not listed) and C1 (no state) none; the correlation stays.
  const sri::BlockId g0 = a.block(g5), e0 = a.block(e11);
  a.propagate(be, {g5, e11, c1}, kT0, 0.005);
  EXPECT_EQ(a.block(g5), g0);
  EXPECT_EQ(a.block(e11), e0);
  a.propagate(be, {g5, c1}, kT0 + 4.0, 0.005);
  EXPECT_NE(a.block(g5), g0);
  EXPECT_FALSE(be.contains(g0));
  EXPECT_EQ(a.block(e11), e0);
  EXPECT_NEAR(a.value(be, g5), x1[0], 1e-9);
  const std::array<sri::BlockId, 2> both{a.block(g5), a.block(e11)};
  const Eigen::Matrix2d P2 = P1 + Eigen::Vector2d(0.0001, 0.0).asDiagonal().toDenseMatrix();
  EXPECT_LT((be.covariance(both) - P2).norm(), 1e-9);
  EXPECT_EQ(a.size(), 2u);

  // The arcs' bookkeeping stays with the states; E11's last phase row is 12 s old, G5's 8 s.
  a.arc(g5)->lastRow = kT0 + 4.0;
  a.arc(e11)->lastRow = kT0;
  a.arc(g5)->rejections = 2;
  EXPECT_EQ(a.arc(g5)->rejections, 2);
  a.dropStale(be, kT0 + 12.0, 10.0);
  EXPECT_FALSE(a.contains(e11));
  EXPECT_FALSE(be.contains(e0));
  ASSERT_TRUE(a.contains(g5));
  EXPECT_NEAR(variance(be, a.block(g5)), P2(0, 0), 1e-9);  // marginalizing E11 leaves G5's marginal
  a.drop(be, c1);  // none: nothing
  EXPECT_EQ(a.size(), 1u);

  // An outage drops every state and the random-walk time: the next call only sets it again.
  a.add(be, c1, 1.0, 2.0, kT0 + 12.0);
  const sri::BlockId g1 = a.block(g5), c0 = a.block(c1);
  a.dropAll(be);
  EXPECT_TRUE(a.empty());
  EXPECT_FALSE(be.contains(g1));
  EXPECT_FALSE(be.contains(c0));
  a.add(be, g5, 7.0, 3.0, kT0 + 80.0);
  const sri::BlockId g2 = a.block(g5);
  a.propagate(be, {g5}, kT0 + 80.0, 0.005);
  EXPECT_EQ(a.block(g5), g2);
  a.propagate(be, {g5}, kT0 + 81.0, 0.005);
  EXPECT_NEAR(variance(be, a.block(g5)), 9.0 + 0.000025, 1e-12);
  // Without a random walk (products everywhere) no step at all.
  const sri::BlockId g3 = a.block(g5);
  a.propagate(be, {g5}, kT0 + 90.0, 0.0);
  EXPECT_EQ(a.block(g5), g3);

  // A new estimator state: forgotten, the old state's blocks are not touched.
  a.forget();
  EXPECT_TRUE(a.empty());
  EXPECT_TRUE(be.contains(g3));
}

}  // namespace
}  // namespace gvins::fusion
