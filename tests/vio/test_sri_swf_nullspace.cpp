// SRI-SWF float vs double: information along the four unobservable directions of VIO (global
// yaw about the z axis and global translation, SriSwfEstimator::unobservableDirections(), built
// from the first estimates). With exact arithmetic and first-estimate Jacobians:
//   - an update with rows H (H N = 0) keeps the Gram matrix G = (R N)ᵀ(R N) (4×4): the rotation
//     Q of [R; H] gives Q [R N; 0] = [R' N; 0];
//   - a propagation appends rows with zero product with N (FEJ transition) and marginalizes the
//     old IMU extra, a re-anchoring likewise; a marginalization is a Schur complement: these
//     only reduce G.
// The observer measures, per step kind, Σ log det(G_after / G_before) (signed: > 0 is
// information gained) and the largest relative gain of one step, in double and in float.
// Measured (25 s circle below; docs/vio_estimator.md "Float"): double updates change log det G
// by ~1e-11 in total; float updates add +1.57 (SLAM re-observations +0.75, new SLAM features
// +0.59, MSCKF +0.23; one SLAM update up to +0.95 % along one direction) and float
// marginalizations remove 1.6 more than double's (-10.3 vs -8.7). The rows themselves are fine
// (‖H N‖² of the float rows: 1e-8 of G); it is the float rounding of R in the QR steps: the
// stiff IMU-chain rows (|R_ij| up to 1.5e5 on the clone columns, their products with N cancel)
// perturb R·N by ~1e-7·|R|·|N| at every step. The fix is the position random walk
// (SriSwfConfig::position_random_walk, 4.5e-3 m/√s): it bounds the stiffness of those rows and
// brings the float gain to +0.0026 (FloatUpdatesKeepTheNullspace).
#include <cmath>
#include <cstdio>
#include <map>
#include <string>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include "gvins/vio/external_initial_state.hpp"
#include "gvins/vio/sri_swf_estimator.hpp"
#include "vio_sim_scene.hpp"

namespace gvins::vio {
namespace {

struct StepStats {
  double logdet = 0;    // Σ log det(G_after) − log det(G_before)
  double max_gain = 0;  // largest λ_max(G_before⁻¹ G_after) − 1 of one step
  int steps = 0;
};

struct NullspaceRun {
  std::map<std::string, StepStats> step;
  Eigen::Matrix4d G = Eigen::Matrix4d::Zero();  // at the end
  double yaw_sigma = 0;                          // newest pose, rad
  double max_R = 0;                              // largest |R_ij| in the clone/IMU columns at the end

  double updates() const {
    double s = 0;
    for (const char* k : {"slam_update", "msckf_update", "slam_init"}) {
      if (auto it = step.find(k); it != step.end()) s += it->second.logdet;
    }
    return s;
  }
};

double logdet(const Eigen::Matrix4d& G) { return 2.0 * Eigen::LLT<Eigen::Matrix4d>(G).matrixL().toDenseMatrix().diagonal().array().log().sum(); }

template <typename Scalar>
NullspaceRun runNullspace(const test::SimScene& sc, const SriSwfConfig& cfg, double t_start) {
  SriSwfEstimator<Scalar> est(cfg);
  NullspaceRun run;
  Eigen::Matrix4d Gprev = Eigen::Matrix4d::Zero();
  bool have = false;
  double t_now = 0;
  Eigen::MatrixXd N;
  Eigen::Vector3d ref = Eigen::Vector3d::Zero();
  bool have_ref = false;
  est.setStepObserver([&](const char* step) {
    N = est.unobservableDirections();
    // Yaw about a fixed point near the flight (same span; a better conditioned 4×4 Gram).
    if (!have_ref) ref = est.newestImuState().p_WI;
    have_ref = true;
    N.col(0) -= N.middleCols(1, 3) * Eigen::Vector3d::UnitZ().cross(ref);
    const Eigen::MatrixXd R = est.filter().squareRootInformation().template cast<double>();
    const Eigen::MatrixXd RN = R.template triangularView<Eigen::Upper>() * N;
    const Eigen::Matrix4d G = RN.transpose() * RN;
    if (have && t_now >= t_start && Gprev.determinant() != 0) {
      StepStats& s = run.step[step];
      s.logdet += logdet(G) - logdet(Gprev);
      const Eigen::LLT<Eigen::Matrix4d> L(Gprev);
      Eigen::Matrix4d M = L.matrixL().solve(G);
      M = L.matrixL().solve(M.transpose()).transpose();
      const double l = Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d>(0.5 * (M + M.transpose())).eigenvalues()(3);
      s.max_gain = std::max(s.max_gain, l - 1.0);
      ++s.steps;
    }
    Gprev = G;
    have = true;
  });
  std::size_t k = 0;
  for (const FeatureFrame& fr : sc.frames) {
    while (k < sc.imu.size() && sc.imu[k].t_ns <= fr.t_ns + 20'000'000) est.addImu(sc.imu[k++]);
    t_now = static_cast<double>(fr.t_ns - sc.frames.front().t_ns) * 1e-9;
    est.processFrame(fr);
  }
  run.G = Gprev;
  const Eigen::Matrix3d Rw = est.newestImuState().R_WI;
  const Eigen::Matrix3d Pt = est.poseCovariance().template topLeftCorner<3, 3>();
  run.yaw_sigma = std::sqrt(Eigen::Vector3d::UnitZ().dot(Rw * Pt * Rw.transpose() * Eigen::Vector3d::UnitZ()));
  const Eigen::MatrixXd R = est.filter().squareRootInformation().template cast<double>();
  for (int j = 0; j < R.cols(); ++j) {
    if (N.row(j).squaredNorm() > 0) run.max_R = std::max(run.max_R, R.col(j).cwiseAbs().maxCoeff());
  }
  std::fprintf(stderr, "  %s: |R n| yaw %.4g x %.4g y %.4g z %.4g, yaw sigma %.3f mrad, max |R| on N columns %.3g\n",
               sizeof(Scalar) == 4 ? "float " : "double", std::sqrt(run.G(0, 0)), std::sqrt(run.G(1, 1)),
               std::sqrt(run.G(2, 2)), std::sqrt(run.G(3, 3)), 1e3 * run.yaw_sigma, run.max_R);
  std::fprintf(stderr, "    Σ Δ log det G (largest one-step relative gain) per step:");
  for (const auto& [name, s] : run.step) {
    std::fprintf(stderr, " %s %+.3g (%.2g)/%d", name.c_str(), s.logdet, s.max_gain, s.steps);
  }
  std::fprintf(stderr, "\n");
  return run;
}

struct Scene {
  test::SimScene sc;
  Scene() {
    sc.duration = 25.0;
    sc.seed = 1;
    sc.build();
  }
};
const Scene& scene() {
  static const Scene s;
  return s;
}

// Double: the first-estimate-Jacobian nullspace is kept; updates leave G unchanged to rounding,
// no step increases it beyond rounding.
TEST(SriSwfNullspace, DoubleKeepsTheUnobservableDirections) {
  const test::SimScene& sc = scene().sc;
  const NullspaceRun d = runNullspace<double>(sc, sc.config(), 3.0);
  EXPECT_LT(std::abs(d.updates()), 1e-6);
  for (const char* k : {"slam_update", "msckf_update", "slam_init"}) {
    ASSERT_TRUE(d.step.count(k)) << k;
    EXPECT_GT(d.step.at(k).steps, 100) << k;
    EXPECT_LT(d.step.at(k).max_gain, 1e-8) << k;
  }
  for (const char* k : {"propagate", "marginalize"}) {
    ASSERT_TRUE(d.step.count(k)) << k;
    EXPECT_LT(d.step.at(k).logdet, 0.0) << k;
  }
  // The exact re-anchoring is a change of variables (SriFilter::substitute): no information is
  // added or removed, its sum is rounding (±2e-14 over 440 steps, its sign depends on the QR
  // kernel's operation order).
  ASSERT_TRUE(d.step.count("reanchor"));
  EXPECT_LT(std::abs(d.step.at("reanchor").logdet), 1e-9);
  EXPECT_LT(d.step.at("reanchor").max_gain, 1e-8);
}

// Float without the position random walk (SriSwfConfig::position_random_walk = 0): the stiff
// IMU-chain position rows make the float updates gain information along N (measured +1.57 in
// Σ log det G, float marginalizations -10.3 against double's -8.7). Bounds with a margin so the
// test notices a change either way.
TEST(SriSwfNullspace, FloatWithoutPositionRandomWalkGainsInformationAlongN) {
  const test::SimScene& sc = scene().sc;
  SriSwfConfig cfg = sc.config();
  cfg.position_random_walk = 0.0;
  const NullspaceRun f = runNullspace<float>(sc, cfg, 3.0);
  EXPECT_GT(f.updates(), 0.1);
  EXPECT_LT(f.updates(), 10.0);
}

// Float with the default position random walk (4.5e-3 m/√s): the largest |R| on the clone
// columns drops from 1.5e5 to 3.3e4 and the float updates gain +0.0026 in Σ log det G (measured),
// 600× less than without; float marginalizations remove what double's do (-6.32 vs -6.31).
TEST(SriSwfNullspace, FloatUpdatesKeepTheNullspace) {
  const test::SimScene& sc = scene().sc;
  const SriSwfConfig cfg = sc.config();
  ASSERT_GT(cfg.position_random_walk, 0.0);
  const NullspaceRun d = runNullspace<double>(sc, cfg, 3.0);
  const NullspaceRun f = runNullspace<float>(sc, cfg, 3.0);
  EXPECT_LT(std::abs(f.updates()), 0.02);
  ASSERT_TRUE(f.step.count("marginalize") && d.step.count("marginalize"));
  EXPECT_NEAR(f.step.at("marginalize").logdet, d.step.at("marginalize").logdet, 0.1);
  for (const char* k : {"slam_update", "msckf_update", "slam_init"}) {
    ASSERT_TRUE(f.step.count(k)) << k;
    EXPECT_LT(f.step.at(k).max_gain, 1e-3) << k;
  }
}

// Yaw σ of the newest pose about the world z axis, rad.
double yawSigma(const SriSwfEstimator<double>& est) {
  const Eigen::Matrix3d Rw = est.newestImuState().R_WI;
  const Eigen::Matrix3d Pt = est.poseCovariance().topLeftCorner<3, 3>();
  return std::sqrt(Eigen::Vector3d::UnitZ().dot(Rw * Pt * Rw.transpose() * Eigen::Vector3d::UnitZ()));
}

struct ExternalStartRun {
  double sigma0 = 0;     // yaw σ right after initializeFrom, rad
  double sigma = 0;      // after 4 s of frames, rad
  double visual = 0;     // Σ log(σ_after / σ_before) over the visual steps (< 0: yaw information gained)
  int visual_steps = 0;
};

// Started from outside (EstimatorBackend::initializeFrom, as the GNSS/INS start does) at the
// first frame with the true state turned 4° in yaw, a 10° yaw prior and no information on the
// velocity (σ 20 m/s: a velocity prior in the world frame would carry yaw information that vision
// legitimately turns into the body-frame direction of travel), then 4 s of frames alone.
ExternalStartRun runExternalStart(const test::SimScene& sc, const SriSwfConfig& cfg) {
  SriSwfEstimator<double> est(cfg);
  const std::int64_t t0 = sc.frames.front().t_ns;
  std::size_t k = 0;
  while (k < sc.imu.size() && sc.imu[k].t_ns <= t0 + 20'000'000) est.addImu(sc.imu[k++]);
  ExternalInitialState x;
  x.state = sc.truth(t0);
  const Eigen::Matrix3d Rz = Eigen::AngleAxisd(4.0 * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  x.state.R_WI = Rz * x.state.R_WI;
  x.state.v_WI = Rz * x.state.v_WI;
  const double sy = 10.0 * M_PI / 180.0, st = 0.5 * M_PI / 180.0;
  const Eigen::Matrix3d Pw = Eigen::Vector3d(st * st, st * st, sy * sy).asDiagonal();
  x.covariance.block<3, 3>(ImuErr::kTheta, ImuErr::kTheta) = x.state.R_WI.transpose() * Pw * x.state.R_WI;
  x.covariance.block<3, 3>(ImuErr::kPos, ImuErr::kPos).diagonal().setConstant(1.0);
  x.covariance.block<3, 3>(ImuErr::kVel, ImuErr::kVel).diagonal().setConstant(20.0 * 20.0);
  x.covariance.block<3, 3>(ImuErr::kBg, ImuErr::kBg).diagonal().setConstant(0.005 * 0.005);
  x.covariance.block<3, 3>(ImuErr::kBa, ImuErr::kBa).diagonal().setConstant(0.1 * 0.1);
  ExternalStartRun run;
  if (!est.initializeFrom(x)) return run;
  run.sigma0 = yawSigma(est);
  double before = run.sigma0;
  est.setStepObserver([&](const char* step) {
    const double s = yawSigma(est);
    const std::string name(step);
    if (name == "msckf_update" || name == "slam_update" || name == "slam_init") {
      run.visual += std::log(s / before);
      ++run.visual_steps;
    }
    before = s;
  });
  for (const FeatureFrame& fr : sc.frames) {
    if (fr.t_ns <= t0) continue;
    if (static_cast<double>(fr.t_ns - t0) * 1e-9 > 4.0) break;
    while (k < sc.imu.size() && sc.imu[k].t_ns <= fr.t_ns + 20'000'000) est.addImu(sc.imu[k++]);
    est.processFrame(fr);
  }
  run.sigma = yawSigma(est);
  std::fprintf(stderr, "  first_estimate_delay %.1f s: yaw sigma %.3f deg at the start, %.3f deg after 4 s (%d visual steps, "
               "sum of their log ratios %.3g)\n", cfg.first_estimate_delay, run.sigma0 * 180 / M_PI, run.sigma * 180 / M_PI,
               run.visual_steps, run.visual);
  return run;
}

// Vision alone cannot observe the global yaw: after an external start with a wide yaw prior the
// visual updates must leave the yaw σ as it was. With first estimates from the first clone
// (first_estimate_delay 0) they do (measured 10.000° -> 9.976°, the gyro's share). Within the
// default delay (2 s; docs/vio_estimator.md) the clones are linearised at their current estimates
// while the IMU rows keep the points they were propagated at, and the visual rows then gain yaw
// information no measurement carries (measured 10° -> 0.62° in 4 s); harmless after a visual
// initialisation, whose yaw is the gauge, not after an external start.
TEST(SriSwfNullspace, ExternalStartVisualUpdatesKeepTheYawSigmaWithFirstEstimates) {
  const test::SimScene& sc = scene().sc;
  SriSwfConfig cfg = sc.config();
  cfg.first_estimate_delay = 0.0;
  const ExternalStartRun fej = runExternalStart(sc, cfg);
  ASSERT_NEAR(fej.sigma0, 10.0 * M_PI / 180.0, 1e-3 * fej.sigma0);
  EXPECT_GT(fej.visual_steps, 100);
  EXPECT_GT(fej.sigma, 0.99 * fej.sigma0);
  EXPECT_GT(fej.visual, -0.01);
  // The default delay, for the record of the limitation (a fix makes this fail: then assert as above).
  const ExternalStartRun delayed = runExternalStart(sc, sc.config());
  EXPECT_LT(delayed.sigma, 0.2 * delayed.sigma0);
}

}  // namespace
}  // namespace gvins::vio
