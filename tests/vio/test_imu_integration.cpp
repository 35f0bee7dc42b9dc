// IMU integration terms gamma, beta, alpha (paper Sec. III-C): identities with the propagator,
// bias Jacobians vs finite differences, the noise covariance Sigma_g and the earlier-state
// prediction's covariance vs Monte Carlo, its Jacobian vs finite differences, and delayed-state
// prediction on real EuRoC V1_02 data against ground truth.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <random>

#include <Eigen/Cholesky>

#include "analytic_motion.hpp"
#include "gvins/vio/euroc_csv.hpp"
#include "gvins/vio/imu_integration.hpp"
#include "gvins/vio/imu_propagation.hpp"
#include "gvins/vio/so3.hpp"

using namespace gvins::vio;
using Eigen::Matrix3d;
using Eigen::Vector3d;

namespace {
double rotErr(const Matrix3d& a, const Matrix3d& b) { return so3::log(a.transpose() * b).norm(); }

Eigen::Matrix<double, 9, 1> earlierMinus(const EarlierImuState& a, const EarlierImuState& b) {
  Eigen::Matrix<double, 9, 1> d;
  d << so3::log(b.R_WI.transpose() * a.R_WI), a.p_WI - b.p_WI, a.v_WI - b.v_WI;
  return d;
}

const Vector3d kG(0, 0, -9.81);
}  // namespace

TEST(ImuIntegration, TermsReproduceThePropagator) {
  const test::AnalyticMotion m;
  const auto samples = m.samples(2.0, 200.0);
  ImuState a = m.state(0.3217);
  a.bg = {0.003, -0.002, 0.01};
  a.ba = {0.05, 0.02, -0.08};
  const std::int64_t tb = 1'523'456'789;
  ImuIntegration integ(ImuNoise{}, a.bg, a.ba);
  integ.integrate(samples, a.t_ns, tb);
  ImuState b = a;
  ImuPropagator(ImuNoise{}, 9.81).propagate(b, samples, tb);
  const double dt = integ.dt();
  EXPECT_DOUBLE_EQ(dt, (tb - a.t_ns) * 1e-9);
  EXPECT_LT(rotErr(a.R_WI * integ.gamma(), b.R_WI), 1e-13);
  EXPECT_LT((a.v_WI + kG * dt + a.R_WI * integ.beta() - b.v_WI).norm(), 1e-11);
  EXPECT_LT((a.p_WI + a.v_WI * dt + 0.5 * kG * dt * dt + a.R_WI * integ.alpha() - b.p_WI).norm(), 1e-11);
  // And backwards (paper's delayed form).
  const EarlierImuState e = predictEarlierState(b, integ, kG);
  EXPECT_EQ(e.t_ns, a.t_ns);
  EXPECT_LT(rotErr(e.R_WI, a.R_WI), 1e-13);
  EXPECT_LT((e.v_WI - a.v_WI).norm(), 1e-10);
  EXPECT_LT((e.p_WI - a.p_WI).norm(), 1e-10);
}

TEST(ImuIntegration, ExtendContinuesTheIntegration) {
  // Integrating to three frame times in turn (one pass) against integrating to each from the start,
  // and against the analytic motion; the extension splits the sample interval at each frame time.
  const test::AnalyticMotion m;
  const Vector3d bg(0.003, -0.002, 0.01), ba(0.05, 0.02, -0.08);
  const auto samples = m.samples(2.0, 200.0, bg, ba);
  const ImuState a = m.state(0.3217);
  ImuIntegration chained(ImuNoise{}, bg, ba);
  chained.integrate(samples, a.t_ns, a.t_ns);
  EXPECT_EQ(chained.intervals(), 0);
  std::int64_t splits = 0;
  for (const std::int64_t t : {std::int64_t{812'345'678}, std::int64_t{1'100'000'000}, std::int64_t{1'523'456'789}}) {
    chained.extend(samples, t);
    ImuIntegration once(ImuNoise{}, bg, ba);
    once.integrate(samples, a.t_ns, t);
    EXPECT_EQ(chained.tTo(), t);
    EXPECT_LT(rotErr(chained.gamma(), once.gamma()), 1e-14);
    EXPECT_LT((chained.beta() - once.beta()).norm(), 1e-12);
    EXPECT_LT((chained.alpha() - once.alpha()).norm(), 1e-12);
    EXPECT_LT((chained.biasJacobian() - once.biasJacobian()).norm(), 1e-11);
    EXPECT_LT((chained.covariance() - once.covariance()).norm(), 1e-7 * once.covariance().norm());
    // Work: the intervals of the one-shot integration plus one per split inside a sample interval.
    EXPECT_EQ(chained.intervals(), once.intervals() + splits);
    splits += t % 5'000'000 != 0 ? 1 : 0;
    // And the analytic truth (noise-free samples with constant biases).
    const ImuState b = m.state(static_cast<double>(t) * 1e-9);
    const double dt = chained.dt();
    EXPECT_LT(rotErr(a.R_WI * chained.gamma(), b.R_WI), 3e-11);
    EXPECT_LT((a.v_WI + kG * dt + a.R_WI * chained.beta() - b.v_WI).norm(), 5e-9);
    EXPECT_LT((a.p_WI + a.v_WI * dt + 0.5 * kG * dt * dt + a.R_WI * chained.alpha() - b.p_WI).norm(), 5e-9);
  }
  EXPECT_THROW(chained.extend(samples, 1'000'000'000), std::invalid_argument) << "backwards";
}

TEST(ImuIntegration, BiasJacobiansMatchReintegration) {
  const test::AnalyticMotion m;
  const auto samples = m.samples(1.0, 200.0);
  const Vector3d bg(0.01, 0.02, -0.03), ba(0.1, -0.1, 0.2);
  ImuIntegration ref(ImuNoise{}, bg, ba);
  ref.integrate(samples, 100'000'000, 700'000'000);
  Eigen::Matrix<double, 9, 6> num;
  for (int j = 0; j < 6; ++j) {
    const double eps = 1e-6;
    Vector3d dg = Vector3d::Zero(), da = Vector3d::Zero();
    (j < 3 ? dg : da)[j % 3] = eps;
    ImuIntegration p(ImuNoise{}, bg + dg, ba + da), q(ImuNoise{}, bg - dg, ba - da);
    p.integrate(samples, 100'000'000, 700'000'000);
    q.integrate(samples, 100'000'000, 700'000'000);
    num.block<3, 1>(ImuIntegrationErr::kGamma, j) =
        (so3::log(ref.gamma().transpose() * p.gamma()) - so3::log(ref.gamma().transpose() * q.gamma())) / (2 * eps);
    num.block<3, 1>(ImuIntegrationErr::kAlpha, j) = (p.alpha() - q.alpha()) / (2 * eps);
    num.block<3, 1>(ImuIntegrationErr::kBeta, j) = (p.beta() - q.beta()) / (2 * eps);
  }
  const double rel = (ref.biasJacobian() - num).norm() / num.norm();
  std::fprintf(stderr, "bias Jacobian vs re-integration: relative error %.2e\n", rel);
  EXPECT_LT(rel, 1e-7);
  // The first-order correction removes almost all of the effect of a small bias change.
  const Vector3d dbg(2e-3, -1e-3, 1e-3), dba(0.02, 0.01, -0.02);
  ImuIntegration moved(ImuNoise{}, bg + dbg, ba + dba);
  moved.integrate(samples, 100'000'000, 700'000'000);
  EXPECT_LT(rotErr(ref.gammaFor(bg + dbg), moved.gamma()), 0.01 * rotErr(ref.gamma(), moved.gamma()));
  EXPECT_LT((ref.betaFor(bg + dbg, ba + dba) - moved.beta()).norm(), 0.01 * (ref.beta() - moved.beta()).norm());
  EXPECT_LT((ref.alphaFor(bg + dbg, ba + dba) - moved.alpha()).norm(), 0.01 * (ref.alpha() - moved.alpha()).norm());
}

TEST(ImuIntegration, EarlierStateJacobianMatchesFiniteDifferences) {
  const test::AnalyticMotion m;
  const auto samples = m.samples(1.0, 200.0);
  ImuState newest = m.state(0.85);
  newest.bg = {0.01, -0.01, 0.02};
  newest.ba = {0.1, 0.2, -0.1};
  ImuIntegration integ(ImuNoise{}, {0.012, -0.008, 0.018}, {0.08, 0.21, -0.12});  // other linearisation point
  integ.integrate(samples, 520'000'000, newest.t_ns);
  const EarlierImuState ref = predictEarlierState(newest, integ, kG);
  Eigen::Matrix<double, 9, 15> num;
  for (int j = 0; j < 15; ++j) {
    const double eps = 1e-6;
    Vector15d d = Vector15d::Zero();
    d[j] = eps;
    ImuState a = newest, b = newest;
    boxPlus(a, d);
    boxPlus(b, -d);
    num.col(j) = (earlierMinus(predictEarlierState(a, integ, kG), ref) -
                  earlierMinus(predictEarlierState(b, integ, kG), ref)) / (2 * eps);
  }
  const double rel = (ref.H - num).norm() / num.norm();
  std::fprintf(stderr, "earlier-state Jacobian vs finite differences: relative error %.2e\n", rel);
  EXPECT_LT(rel, 1e-7);
  ImuState wrong = newest;
  wrong.t_ns += 1;
  EXPECT_THROW(predictEarlierState(wrong, integ, kG), std::invalid_argument);
}

TEST(ImuIntegration, CovariancesMatchMonteCarlo) {
  const test::AnalyticMotion m;
  ImuNoise noise;
  noise.gyroscope_noise_density *= 10;
  noise.accelerometer_noise_density *= 10;
  const double rate = 200.0, dt = 1.0 / rate;
  const auto clean = m.samples(1.0, rate);
  const std::int64_t ta = 150'000'000, tb = 850'000'000;
  ImuIntegration ref(noise, Vector3d::Zero(), Vector3d::Zero());
  ref.integrate(clean, ta, tb);
  const ImuState newest = m.state(tb * 1e-9);
  const EarlierImuState eref = predictEarlierState(newest, ref, kG);

  std::mt19937 rng(7);
  std::normal_distribution<double> n01;
  const int runs = 2000;
  Eigen::Matrix<double, 9, Eigen::Dynamic> Eg(9, runs), Ex(9, runs);
  for (int r = 0; r < runs; ++r) {
    auto noisy = clean;
    for (auto& s : noisy) {
      for (int k = 0; k < 3; ++k) {
        s.gyro[k] += noise.gyroscope_noise_density / std::sqrt(dt) * n01(rng);
        s.accel[k] += noise.accelerometer_noise_density / std::sqrt(dt) * n01(rng);
      }
    }
    ImuIntegration it(noise, Vector3d::Zero(), Vector3d::Zero());
    it.integrate(noisy, ta, tb);
    // Error convention: true = measured (+) error.
    Eg.block<3, 1>(ImuIntegrationErr::kGamma, r) = so3::log(it.gamma().transpose() * ref.gamma());
    Eg.block<3, 1>(ImuIntegrationErr::kAlpha, r) = ref.alpha() - it.alpha();
    Eg.block<3, 1>(ImuIntegrationErr::kBeta, r) = ref.beta() - it.beta();
    Ex.col(r) = earlierMinus(eref, predictEarlierState(newest, it, kG));
  }
  auto check = [&](const Eigen::Matrix<double, 9, Eigen::Dynamic>& E, const Eigen::Matrix<double, 9, 9>& P,
                   const char* what) {
    const Eigen::Matrix<double, 9, 9> C = E * E.transpose() / runs;
    const Eigen::LLT<Eigen::Matrix<double, 9, 9>> llt(P);
    double nees = 0.0;
    for (int r = 0; r < runs; ++r) nees += E.col(r).dot(llt.solve(E.col(r)));
    nees /= runs;
    std::fprintf(stderr, "%s: Monte Carlo mean NEES %.2f (expected 9)\n", what, nees);
    for (int i = 0; i < 9; ++i) {
      EXPECT_GT(C(i, i) / P(i, i), 0.85) << what << " diag " << i;
      EXPECT_LT(C(i, i) / P(i, i), 1.15) << what << " diag " << i;
    }
    EXPECT_GT(nees, 8.3) << what;
    EXPECT_LT(nees, 9.7) << what;
  };
  check(Eg, ref.covariance(), "Sigma_g");
  check(Ex, eref.covariance, "earlier state");
}

TEST(ImuIntegration, RealEurocV102DelayedStatePrediction) {
  // From the ground-truth state at t_i (with its biases) predict the state 0.2 s and 1 s
  // earlier, as the fusion does for a delayed GNSS epoch, and compare with ground truth.
  const std::string dir = std::string(GVINS_TEST_DATA) + "/euroc/v102_imu_groundtruth/";
  const auto imu = readImuCsv(dir + "imu0.csv.gz", 200.0);
  const auto gt = readGroundTruthCsv(dir + "state_groundtruth_estimate0.csv.gz");
  for (const int delay : {40, 200}) {
    std::vector<double> ep, ev, er;
    for (std::size_t i = 200; i < gt.size(); i += 400) {
      const ImuState& newest = gt[i].state;
      const ImuState& truth = gt[i - static_cast<std::size_t>(delay)].state;
      ImuIntegration integ(ImuNoise{}, newest.bg, newest.ba);
      integ.integrate(imu, truth.t_ns, newest.t_ns);
      const EarlierImuState e = predictEarlierState(newest, integ, kG);
      ep.push_back((e.p_WI - truth.p_WI).norm());
      ev.push_back((e.v_WI - truth.v_WI).norm());
      er.push_back(rotErr(e.R_WI, truth.R_WI));
    }
    std::sort(ep.begin(), ep.end());
    std::sort(ev.begin(), ev.end());
    std::sort(er.begin(), er.end());
    const std::size_t h = ep.size() / 2;
    std::fprintf(stderr, "V1_02 delayed prediction %.1f s back, %zu cases: median |dp| %.4f m, |dv| %.4f m/s, |dR| %.3f deg\n",
                 delay / 200.0, ep.size(), ep[h], ev[h], er[h] * 180 / M_PI);
    EXPECT_EQ(ep.size(), 20u);
    if (delay == 40) {
      EXPECT_LT(ep[h], 0.005);
      EXPECT_LT(ev[h], 0.03);
      EXPECT_LT(er[h], 0.05 * M_PI / 180);
    } else {
      EXPECT_LT(ep[h], 0.04);
      EXPECT_LT(ev[h], 0.07);
      EXPECT_LT(er[h], 0.15 * M_PI / 180);
    }
  }
}
