// SO(3) exponential/logarithm, boxplus/boxminus conventions of rotation and pose blocks
// (checked against Eigen::AngleAxis and finite differences of the documented Jacobians), and a
// rotation block estimated by the filter from vector observations.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "gvins/sri/block_estimate.hpp"
#include "gvins/sri/so3.hpp"
#include "gvins/sri/sri_filter.hpp"

namespace gvins::sri {
namespace {

constexpr double kPi = 3.14159265358979323846;

Eigen::Matrix3d angleAxis(const Eigen::Vector3d& phi) {
  const double a = phi.norm();
  if (a == 0) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(a, phi / a).toRotationMatrix();
}

TEST(So3, ExpMatchesAngleAxisAndLogInverts) {
  // Analytic case: a quarter turn about z.
  const Eigen::Matrix3d Rz = so3::exp<double>(Eigen::Vector3d(0, 0, kPi / 2));
  Eigen::Matrix3d expect;
  expect << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  EXPECT_LT((Rz - expect).norm(), 1e-15);
  std::mt19937 rng(3);
  std::normal_distribution<double> g(0.0, 1.0);
  for (double scale : {1e-12, 1e-7, 1e-3, 0.5, 2.0, 3.1}) {
    for (int k = 0; k < 20; ++k) {
      Eigen::Vector3d phi(g(rng), g(rng), g(rng));
      phi *= scale / phi.norm();
      EXPECT_LT((so3::exp<double>(phi) - angleAxis(phi)).norm(), 1e-14) << scale;
      EXPECT_LT((so3::log<double>(so3::exp<double>(phi)) - phi).norm(), 1e-13 * std::max(1.0, scale))
          << scale;
      // float
      const Eigen::Vector3f pf = phi.cast<float>();
      EXPECT_LT((so3::exp<float>(pf).cast<double>() - angleAxis(phi)).norm(), 1e-6) << scale;
      EXPECT_LT((so3::log<float>(so3::exp<float>(pf)) - pf).norm(), 2e-6f * std::max(1.0f, pf.norm()));
    }
  }
  // Near π: log returns an angle of π (either sign of the axis is the same rotation).
  const Eigen::Vector3d nearPi(0, kPi - 1e-9, 0);
  EXPECT_NEAR(so3::log<double>(so3::exp<double>(nearPi)).norm(), kPi - 1e-9, 1e-8);
  EXPECT_LT((so3::hat<double>(Eigen::Vector3d(1, 2, 3)) * Eigen::Vector3d(4, 5, 6) -
             Eigen::Vector3d(1, 2, 3).cross(Eigen::Vector3d(4, 5, 6)))
                .norm(),
            1e-15);
}

BlockInfo info(BlockKind kind, int dim, RotationPerturbation p) {
  BlockInfo b;
  b.kind = kind;
  b.dim = dim;
  b.perturbation = p;
  b.name = "t";
  return b;
}

TEST(BlockEstimate, BoxplusConventionsAndBoxminus) {
  std::mt19937 rng(5);
  std::normal_distribution<double> g(0.0, 1.0);
  const Eigen::Quaterniond q0(angleAxis(Eigen::Vector3d(0.3, -1.2, 0.7)));
  for (int k = 0; k < 20; ++k) {
    const Eigen::Vector3d d(0.4 * g(rng), 0.4 * g(rng), 0.4 * g(rng));
    // Right: R̂·Exp(δ).
    auto x = BlockEstimate<double>::fromRotation(q0);
    boxplus<double>(info(BlockKind::kRotation, 3, RotationPerturbation::kRight), x, d);
    EXPECT_LT((x.rotation.toRotationMatrix() - q0.toRotationMatrix() * angleAxis(d)).norm(), 1e-14);
    EXPECT_LT((boxminus<double>(info(BlockKind::kRotation, 3, RotationPerturbation::kRight), x,
                                BlockEstimate<double>::fromRotation(q0)) -
               d)
                  .norm(),
              1e-13);
    // Left: Exp(δ)·R̂.
    auto y = BlockEstimate<double>::fromRotation(q0);
    boxplus<double>(info(BlockKind::kRotation, 3, RotationPerturbation::kLeft), y, d);
    EXPECT_LT((y.rotation.toRotationMatrix() - angleAxis(d) * q0.toRotationMatrix()).norm(), 1e-14);
    EXPECT_LT((boxminus<double>(info(BlockKind::kRotation, 3, RotationPerturbation::kLeft), y,
                                BlockEstimate<double>::fromRotation(q0)) -
               d)
                  .norm(),
              1e-13);
    // Pose: [δθ; δp].
    Eigen::Matrix<double, 6, 1> dp;
    dp << d, Eigen::Vector3d(g(rng), g(rng), g(rng));
    auto p = BlockEstimate<double>::fromPose(q0, Eigen::Vector3d(1, 2, 3));
    const auto p0 = p;
    boxplus<double>(info(BlockKind::kPose, 6, RotationPerturbation::kRight), p, dp);
    EXPECT_LT((p.rotation.toRotationMatrix() - q0.toRotationMatrix() * angleAxis(d)).norm(), 1e-14);
    EXPECT_LT((p.vector - Eigen::Vector3d(1, 2, 3) - dp.tail<3>()).norm(), 1e-15);
    EXPECT_LT((boxminus<double>(info(BlockKind::kPose, 6, RotationPerturbation::kRight), p, p0) - dp).norm(),
              1e-13);
  }
  // Vectors, shape checks.
  auto v = BlockEstimate<double>::fromVector(Eigen::Vector3d(1, 2, 3));
  boxplus<double>(info(BlockKind::kVector, 3, RotationPerturbation::kRight), v, Eigen::Vector3d(1, 1, 1));
  EXPECT_EQ(v.vector, Eigen::Vector3d(2, 3, 4));
  EXPECT_THROW(boxplus<double>(info(BlockKind::kVector, 3, RotationPerturbation::kRight), v,
                               Eigen::Vector2d(1, 1)),
               std::invalid_argument);
  EXPECT_TRUE(hasShape(BlockEstimate<float>::zero(BlockKind::kPose, 6), BlockKind::kPose, 6));
  EXPECT_FALSE(hasShape(BlockEstimate<float>::zero(BlockKind::kRotation, 3), BlockKind::kPose, 6));
}

// The documented error-state Jacobians of h(R) = R v: −R[v]× for R = R̂·Exp(δθ) and −[R v]× for
// R = Exp(δθ)·R̂, checked by central differences through boxplus.
TEST(BlockEstimate, JacobiansOfTheConventionsByFiniteDifferences) {
  const Eigen::Quaterniond q(angleAxis(Eigen::Vector3d(-0.4, 0.9, 0.2)));
  const Eigen::Vector3d v(0.3, -0.5, 0.8);
  for (auto conv : {RotationPerturbation::kRight, RotationPerturbation::kLeft}) {
    const BlockInfo b = info(BlockKind::kRotation, 3, conv);
    Eigen::Matrix3d J;
    const double h = 1e-6;
    for (int c = 0; c < 3; ++c) {
      auto xp = BlockEstimate<double>::fromRotation(q);
      auto xm = xp;
      boxplus<double>(b, xp, Eigen::Vector3d::Unit(c) * h);
      boxplus<double>(b, xm, -Eigen::Vector3d::Unit(c) * h);
      J.col(c) = (xp.rotation * v - xm.rotation * v) / (2 * h);
    }
    const Eigen::Matrix3d R = q.toRotationMatrix();
    const Eigen::Matrix3d analytic = conv == RotationPerturbation::kRight ? Eigen::Matrix3d(-R * so3::hat<double>(v))
                                                                          : Eigen::Matrix3d(-so3::hat<double>(R * v));
    EXPECT_LT((J - analytic).norm(), 1e-9);
  }
}

// A rotation block (each convention) and a position, observed through noise-free vectors from
// an estimate 2 mrad off: one pass of updates/corrections must land within the linearization
// error O(θ²) of the truth, which only happens if correct() applies the block's convention.
template <typename S>
void estimateRotation(RotationPerturbation conv, double tol) {
  using Vec3 = Eigen::Matrix<S, 3, 1>;
  const Eigen::Matrix3d Rt = angleAxis(Eigen::Vector3d(0.7, -0.2, 1.1));
  const Eigen::Vector3d pt(1.0, -2.0, 0.5);
  SriFilter<S> f;
  const Eigen::Quaterniond q0(Rt * angleAxis(Eigen::Vector3d(0.0012, -0.001, 0.0013)));
  const BlockId rot = f.addBlock(BlockSpec::rotation("R", conv),
                                 BlockEstimate<S>::fromRotation(q0.cast<S>()),
                                 Prior<S>::stdDev(3, S(0.5)));
  const BlockId pos = f.addBlock(BlockSpec::vector("p", 3),
                                 BlockEstimate<S>::fromVector(Vec3(1.002, -2.001, 0.499)),
                                 Prior<S>::stdDev(3, S(1)));
  const std::vector<Eigen::Vector3d> vs{{1, 0, 0}, {0, 1, 0}, {0.3, 0.4, -0.8}, {-0.5, 0.1, 0.2}};
  {
    for (const Eigen::Vector3d& v : vs) {
      // z = R v + p (noise-free), σ = 1e-3.
      const Eigen::Matrix3d R = f.estimate(rot).rotation.toRotationMatrix().template cast<double>();
      const Eigen::Vector3d p = f.estimate(pos).vector.template cast<double>();
      Measurement<S> m(3);
      m.jacobian(rot, 3) = (conv == RotationPerturbation::kRight ? Eigen::Matrix3d(-R * so3::hat<double>(v))
                                                                 : Eigen::Matrix3d(-so3::hat<double>(R * v)))
                               .template cast<S>();
      m.jacobian(pos, 3).setIdentity();
      m.residual() = ((Rt * v + pt) - (R * v + p)).template cast<S>();
      m.whitenStdDev(S(1e-3));
      f.update(m);
      f.correct();
    }
  }
  const Eigen::Matrix3d R = f.estimate(rot).rotation.toRotationMatrix().template cast<double>();
  EXPECT_LT(so3::log<double>(Eigen::Matrix3d(Rt.transpose() * R)).norm(), tol);
  EXPECT_LT((f.estimate(pos).vector.template cast<double>() - pt).norm(), tol);
}

TEST(SriFilterRotation, ConvergesWithEitherConvention) {
  estimateRotation<double>(RotationPerturbation::kRight, 2e-5);
  estimateRotation<double>(RotationPerturbation::kLeft, 2e-5);
  estimateRotation<float>(RotationPerturbation::kRight, 2e-5);
  estimateRotation<float>(RotationPerturbation::kLeft, 2e-5);
}

}  // namespace
}  // namespace gvins::sri
