// SRI-SWF estimator Jacobians against central finite differences: camera points and projection,
// the time-offset column, anchored inverse depth and re-anchoring, and the IMU transition with
// first estimates (applyFirstEstimates).
#include <cmath>

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include "analytic_motion.hpp"
#include "gvins/vio/imu_propagation.hpp"
#include "gvins/vio/so3.hpp"
#include "gvins/vio/sri_swf_estimator.hpp"
#include "gvins/vio/visual_jacobians.hpp"

namespace gvins::vio {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;
PoseEstimate perturbPose(const PoseEstimate& p, const Eigen::Matrix<double, 6, 1>& d) {
  PoseEstimate q;
  q.R_WI = p.R_WI * so3::exp(d.head<3>());
  q.p_WI = p.p_WI + d.tail<3>();
  return q;
}
CameraExtrinsic perturbExt(const CameraExtrinsic& e, const Eigen::Matrix<double, 6, 1>& d) {
  return {e.R_IC * so3::exp(d.head<3>()), e.p_IC + d.tail<3>()};
}

// Central differences of a vector function of a 6-dim or 3-dim perturbation.
template <int N, typename F>
Eigen::MatrixXd numericJacobian(F&& fn, double h = 1e-6) {
  const Eigen::VectorXd f0 = fn(Eigen::Matrix<double, N, 1>::Zero());
  Eigen::MatrixXd J(f0.size(), N);
  for (int k = 0; k < N; ++k) {
    Eigen::Matrix<double, N, 1> d = Eigen::Matrix<double, N, 1>::Zero();
    d(k) = h;
    const Eigen::VectorXd fp = fn(d);
    d(k) = -h;
    const Eigen::VectorXd fm = fn(d);
    J.col(k) = (fp - fm) / (2 * h);
  }
  return J;
}

struct Geometry {
  PoseEstimate pose, anchor;
  CameraExtrinsic ext0, ext1;
  Vector3d p_W;
  Geometry() {
    pose.R_WI = so3::exp(Vector3d(0.3, -0.2, 1.1));
    pose.p_WI = Vector3d(3, -2, 30);
    anchor.R_WI = so3::exp(Vector3d(0.25, -0.1, 0.9));
    anchor.p_WI = Vector3d(1, -3, 29);
    ext0.R_IC = so3::exp(Vector3d(3.0, 0.05, -0.02));
    ext0.p_IC = Vector3d(0.05, 0.02, -0.05);
    ext1.R_IC = so3::exp(Vector3d(3.0, 0.06, -0.01));
    ext1.p_IC = Vector3d(0.45, 0.02, -0.05);
    p_W = Vector3d(5, 4, 1.5);
  }
};

Eigen::Vector2d project(const Vector3d& pc) { return pc.head<2>() / pc.z(); }

TEST(SriSwfJacobians, CameraPointAndProjectionMatchFiniteDifferences) {
  const Geometry g;
  for (const CameraExtrinsic& e : {g.ext0, g.ext1}) {  // mono and the stereo partner
    const CameraPoint cp = cameraPoint(g.pose, e, g.p_W);
    ASSERT_GT(cp.p_C.z(), 10.0);
    const auto Jp = numericJacobian<6>([&](const Eigen::Matrix<double, 6, 1>& d) {
      return Eigen::VectorXd(project(cameraPoint(perturbPose(g.pose, d), e, g.p_W).p_C));
    });
    const auto Je = numericJacobian<6>([&](const Eigen::Matrix<double, 6, 1>& d) {
      return Eigen::VectorXd(project(cameraPoint(g.pose, perturbExt(e, d), g.p_W).p_C));
    });
    const auto Jw = numericJacobian<3>([&](const Vector3d& d) {
      return Eigen::VectorXd(project(cameraPoint(g.pose, e, g.p_W + d).p_C));
    });
    const Eigen::Matrix<double, 2, 3> P = projectionJacobian(cp.p_C);
    EXPECT_LT(((P * cp.J_pose) - Jp).norm(), 1e-7 * Jp.norm());
    EXPECT_LT(((P * cp.J_ext) - Je).norm(), 1e-7 * Je.norm());
    EXPECT_LT(((P * cp.J_point) - Jw).norm(), 1e-7 * Jw.norm());
  }
}

// Camera-IMU time offset: the observation of a clone moved by dt along its angular rate and
// velocity, d(x/z, y/z)/d dt against central differences in dt, at dt = 0 and at 8 ms.
TEST(SriSwfJacobians, TimeOffsetColumnMatchesFiniteDifferences) {
  const Geometry g;
  const Vector3d w(0.4, -0.9, 1.3), v(7.5, -2.0, 0.6);
  for (const double dt0 : {0.0, 0.008}) {
    for (const CameraExtrinsic& e : {g.ext0, g.ext1}) {
      const CameraPoint cp = cameraPoint(poseAfter(g.pose, w, v, dt0), e, g.p_W);
      const Eigen::Vector2d J = projectionJacobian(cp.p_C) * timeOffsetJacobian(cp, w, v);
      const double h = 1e-6;
      const Eigen::Vector2d Jn = (project(cameraPoint(poseAfter(g.pose, w, v, dt0 + h), e, g.p_W).p_C) -
                                  project(cameraPoint(poseAfter(g.pose, w, v, dt0 - h), e, g.p_W).p_C)) /
                                 (2 * h);
      ASSERT_GT(Jn.norm(), 0.01);  // the motion moves the point in the image
      EXPECT_LT((J - Jn).norm(), 1e-6 * Jn.norm()) << "dt0 " << dt0 << ": " << J.transpose() << " vs " << Jn.transpose();
    }
  }
  // poseAfter integrates a constant rate exactly: two steps equal one.
  const PoseEstimate a = poseAfter(poseAfter(g.pose, w, v, 0.003), w, v, 0.005), b = poseAfter(g.pose, w, v, 0.008);
  EXPECT_LT((a.R_WI - b.R_WI).norm(), 1e-12);
  EXPECT_LT((a.p_WI - b.p_WI).norm(), 1e-12);
}

TEST(SriSwfJacobians, InverseDepthFeatureAndReanchoringMatchFiniteDifferences) {
  const Geometry g;
  const Vector3d f = inverseDepthOf(g.p_W, g.anchor, g.ext0);
  // Round trip.
  EXPECT_LT((anchoredPoint(f, g.anchor, g.ext0).p_W - g.p_W).norm(), 1e-9);
  // SLAM observation in cam1 of another clone: z(f, anchor, pose, ext0, ext1).
  auto obs = [&](const Vector3d& ff, const PoseEstimate& a, const PoseEstimate& p, const CameraExtrinsic& e0,
                 const CameraExtrinsic& e1) {
    return Eigen::VectorXd(project(cameraPoint(p, e1, anchoredPoint(ff, a, e0).p_W).p_C));
  };
  const AnchoredPoint ap = anchoredPoint(f, g.anchor, g.ext0);
  const CameraPoint cp = cameraPoint(g.pose, g.ext1, ap.p_W);
  const Eigen::Matrix<double, 2, 3> A = projectionJacobian(cp.p_C) * cp.J_point;
  const auto Jf = numericJacobian<3>([&](const Vector3d& d) { return obs(f + d, g.anchor, g.pose, g.ext0, g.ext1); }, 1e-7);
  const auto Ja = numericJacobian<6>([&](const Eigen::Matrix<double, 6, 1>& d) {
    return obs(f, perturbPose(g.anchor, d), g.pose, g.ext0, g.ext1);
  });
  const auto Je0 = numericJacobian<6>([&](const Eigen::Matrix<double, 6, 1>& d) {
    return obs(f, g.anchor, g.pose, perturbExt(g.ext0, d), g.ext1);
  });
  EXPECT_LT((A * ap.J_feature - Jf).norm(), 1e-6 * Jf.norm());
  EXPECT_LT((A * ap.J_anchor - Ja).norm(), 1e-6 * Ja.norm());
  EXPECT_LT((A * ap.J_ext - Je0).norm(), 1e-6 * Je0.norm());
  // Re-anchoring map f' = g(f, anchor, new anchor) and its chain-rule Jacobians.
  auto re = [&](const Vector3d& ff, const PoseEstimate& a, const PoseEstimate& b) {
    return Eigen::VectorXd(inverseDepthOf(anchoredPoint(ff, a, g.ext0).p_W, b, g.ext0));
  };
  Matrix3d D;
  CameraPoint cb;
  inverseDepthOf(ap.p_W, g.pose, g.ext0, &D, &cb);
  const auto Rf = numericJacobian<3>([&](const Vector3d& d) { return re(f + d, g.anchor, g.pose); }, 1e-7);
  const auto Rb = numericJacobian<6>([&](const Eigen::Matrix<double, 6, 1>& d) {
    return re(f, g.anchor, perturbPose(g.pose, d));
  });
  EXPECT_LT((D * cb.J_point * ap.J_feature - Rf).norm(), 1e-6 * Rf.norm());
  EXPECT_LT((D * cb.J_pose - Rb).norm(), 1e-6 * Rb.norm());
  // With respect to the extrinsic of camera 0, which both anchors use (online calibration).
  const auto Re = numericJacobian<6>([&](const Eigen::Matrix<double, 6, 1>& d) {
    const CameraExtrinsic e = perturbExt(g.ext0, d);
    return Eigen::VectorXd(inverseDepthOf(anchoredPoint(f, g.anchor, e).p_W, g.pose, e));
  });
  ASSERT_GT(Re.norm(), 1e-3);
  EXPECT_LT((D * (cb.J_point * ap.J_ext + cb.J_ext) - Re).norm(), 1e-6 * Re.norm());
}

TEST(SriSwfJacobians, PropagationTransitionMatchesFiniteDifferences) {
  // Φ used for the block row [V₁ −Q'^(−½)] against central differences of the propagator.
  test::AnalyticMotion m;
  const auto samples = m.samples(2.0, 200.0, Vector3d(0.01, -0.02, 0.005), Vector3d(0.05, 0.02, -0.03));
  ImuPropagator prop(ImuNoise{}, m.g);
  ImuState s0 = m.state(0.5);
  s0.bg = Vector3d(0.01, -0.02, 0.0);
  s0.ba = Vector3d(0.04, 0.0, -0.02);
  const std::int64_t t1 = 550'000'000;
  ImuState s1 = s0;
  Matrix15d Phi, Qd;
  prop.propagate(s1, samples, t1, &Phi, &Qd);
  Matrix15d Jn;
  for (int k = 0; k < 15; ++k) {
    Vector15d d = Vector15d::Zero();
    const double h = 1e-6;
    d(k) = h;
    ImuState a = s0, b = s0;
    boxPlus(a, d);
    boxPlus(b, -d);
    prop.propagate(a, samples, t1);
    prop.propagate(b, samples, t1);
    Jn.col(k) = (boxMinus(a, s1) - boxMinus(b, s1)) / (2 * h);
  }
  EXPECT_LT((Phi - Jn).cwiseAbs().maxCoeff(), 1e-6);
  // First-estimate transition: at the propagator's own linearisation point it reproduces Φ; at
  // another first estimate (R₀, p₀, v₀) it maps the yaw direction of that estimate,
  // [R₀ᵀe_z; e_z × p₀; e_z × v₀; 0; 0], onto the one of the propagated state in p and v
  // (observability, Li & Mourikis 2013).
  {
    Matrix15d P2 = Phi;
    applyFirstEstimates(P2, s0.R_WI, s0.p_WI, s0.v_WI, s1.R_WI, s1.p_WI, s1.v_WI, 0.05, m.g);
    EXPECT_LT((P2 - Phi).cwiseAbs().maxCoeff(), 1e-9);
    const Matrix3d R0 = s0.R_WI * so3::exp(Vector3d(0.02, -0.01, 0.03));
    const Vector3d p0 = s0.p_WI + Vector3d(0.3, -0.2, 0.1), v0 = s0.v_WI + Vector3d(0.05, 0.02, -0.04);
    applyFirstEstimates(P2, R0, p0, v0, s1.R_WI, s1.p_WI, s1.v_WI, 0.05, m.g);
    const Vector3d ez = Vector3d::UnitZ();
    Vector15d n0 = Vector15d::Zero();
    n0.segment<3>(ImuErr::kTheta) = R0.transpose() * ez;
    n0.segment<3>(ImuErr::kPos) = ez.cross(p0);
    n0.segment<3>(ImuErr::kVel) = ez.cross(v0);
    const Vector15d n1 = P2 * n0;
    EXPECT_LT((n1.segment<3>(ImuErr::kPos) - ez.cross(s1.p_WI)).norm(), 1e-9);
    EXPECT_LT((n1.segment<3>(ImuErr::kVel) - ez.cross(s1.v_WI)).norm(), 1e-9);
    EXPECT_LT((n1.segment<3>(ImuErr::kTheta) - s1.R_WI.transpose() * ez).norm(), 1e-12);
    // Without first estimates the same direction is not preserved (the test can fail).
    const Vector15d n1c = Phi * n0;
    EXPECT_GT((n1c.segment<3>(ImuErr::kPos) - ez.cross(s1.p_WI)).norm(), 1e-4);
    EXPECT_GT((n1c.segment<3>(ImuErr::kTheta) - s1.R_WI.transpose() * ez).norm(), 1e-3);
  }
  // Q' is symmetric positive definite (the row needs Q'^(−½)).
  EXPECT_LT((Qd - Qd.transpose()).norm(), 1e-15);
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<Matrix15d>(Qd).eigenvalues()(0), 0.0);
}

}  // namespace
}  // namespace gvins::vio
