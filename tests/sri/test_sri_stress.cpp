// Numerical stress: posterior covariance with condition number ~1e12 (mm-level rows against
// km-level priors, part of the state only weakly observed). Truth is a covariance Kalman filter
// in long double (64-bit mantissa). The float covariance-form EKF (standard and Joseph) must
// lose positive definiteness or accuracy; the float SRI filter must stay close to the truth.
// Also compares Householder and Givens in float on this stiff weighting (the measurement
// behind RotationScheme::kAuto, docs/sri_core.md).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <random>
#include <vector>

#include <Eigen/Eigenvalues>
#include <Eigen/QR>

#include "covariance_kf.hpp"
#include "gvins/sri/sri_filter.hpp"

namespace gvins::sri {
namespace {

using Ld = long double;
using Ml = Eigen::Matrix<Ld, Eigen::Dynamic, Eigen::Dynamic>;
using Vl = Eigen::Matrix<Ld, Eigen::Dynamic, 1>;

constexpr int kBlocks = 4;
constexpr int kDim = 3 * kBlocks;

struct Step {
  Ml H;      // m × kDim
  Vl z;      // m
  Vl sigma;  // m
};

/// Prior σ = 1e3 on everything; precise rows (σ = 1e-3, like carrier phase) only see a
/// 9-dimensional subspace; weak rows (σ = 30) see everything. Posterior standard deviations range
/// from ~1e-3 to 1e3 before the weak rows arrive and to ~30 after: cond(P) up to ~1e12.
std::vector<Step> makeSteps(unsigned seed, const Vl& xTrue) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  Ml B(9, kDim);
  for (int i = 0; i < 9; ++i) {
    for (int j = 0; j < kDim; ++j) B(i, j) = g(rng);
  }
  std::vector<Step> steps;
  for (int s = 0; s < 12; ++s) {
    Step st;
    const bool precise = s % 3 != 2;
    const int m = precise ? 3 : 2;
    st.H.resize(m, kDim);
    st.sigma.resize(m);
    if (precise) {
      Ml A(m, 9);
      for (int i = 0; i < m; ++i) {
        for (int j = 0; j < 9; ++j) A(i, j) = g(rng);
      }
      st.H = A * B;
      st.sigma.setConstant(Ld(1e-3));
    } else {
      for (int i = 0; i < m; ++i) {
        for (int j = 0; j < kDim; ++j) st.H(i, j) = g(rng);
      }
      st.sigma.setConstant(Ld(30));
    }
    for (int i = 0; i < m; ++i) st.H.row(i).normalize();  // unit-norm rows: σ sets the weight
    st.z = st.H * xTrue;
    for (int i = 0; i < m; ++i) st.z(i) += st.sigma(i) * Ld(g(rng));
    steps.push_back(st);
  }
  return steps;
}

struct Accuracy {
  Ld whitenedError = 0;  ///< max over steps of ‖L⁻¹(x − x_true)‖, P_true = L Lᵀ
  Ld covError = 0;       ///< max over steps of ‖L⁻¹ P L⁻ᵀ − I‖₂
  Ld sigmaError = 0;     ///< max over steps and states of |σ_i / σ_true,i − 1| (marginal σ)
  bool lostDefiniteness = false;
  double maxCondition = 0;  ///< of the true covariance
};

void score(Accuracy& acc, const Vl& x, const Ml& P, const Vl& xt, const Ml& Pt) {
  Eigen::LLT<Ml> llt(Pt);
  const Ml L = llt.matrixL();
  const Vl e = L.triangularView<Eigen::Lower>().solve(x - xt);
  Ml Wm = L.triangularView<Eigen::Lower>().solve(P);
  Wm = L.triangularView<Eigen::Lower>().solve(Wm.transpose()).transpose();
  const Ml D = Wm - Ml::Identity(kDim, kDim);
  Eigen::SelfAdjointEigenSolver<Ml> es((D + D.transpose()) / 2);
  const Ld dn = es.eigenvalues().cwiseAbs().maxCoeff();
  acc.whitenedError = std::max(acc.whitenedError, std::isfinite(static_cast<double>(e.norm())) ? e.norm() : Ld(1e30));
  acc.covError = std::max(acc.covError, std::isfinite(static_cast<double>(dn)) ? dn : Ld(1e30));
  for (int i = 0; i < kDim; ++i) {
    const Ld ratio = P(i, i) > 0 ? std::sqrt(P(i, i) / Pt(i, i)) : Ld(0);
    acc.sigmaError = std::max(acc.sigmaError, std::abs(ratio - 1));
  }
  Eigen::SelfAdjointEigenSolver<Ml> ep(P);
  if (!(ep.eigenvalues().minCoeff() > 0) || !P.allFinite()) acc.lostDefiniteness = true;
  Eigen::SelfAdjointEigenSolver<Ml> et(Pt);
  acc.maxCondition = std::max(acc.maxCondition, static_cast<double>(et.eigenvalues().maxCoeff() / et.eigenvalues().minCoeff()));
}

template <typename S>
Accuracy runSri(const std::vector<Step>& steps, RotationScheme scheme, const Vl& x0,
                const std::vector<Vl>& xt, const std::vector<Ml>& Pt, bool* usedGivens = nullptr) {
  SriFilter<S> f;
  std::vector<BlockId> ids;
  for (int b = 0; b < kBlocks; ++b) {
    ids.push_back(f.addBlock(BlockSpec::vector("x", 3),
                             BlockEstimate<S>::fromVector(x0.segment(3 * b, 3).template cast<S>()),
                             Prior<S>::stdDev(3, S(1e3))));
  }
  Accuracy acc;
  for (std::size_t s = 0; s < steps.size(); ++s) {
    const Step& st = steps[s];
    const int m = static_cast<int>(st.H.rows());
    Measurement<S> z(m);
    Eigen::Matrix<S, Eigen::Dynamic, 1> pred = Eigen::Matrix<S, Eigen::Dynamic, 1>::Zero(m);
    for (int b = 0; b < kBlocks; ++b) {
      const auto Hb = st.H.middleCols(3 * b, 3).template cast<S>();
      z.jacobian(ids[static_cast<std::size_t>(b)], 3) = Hb;
      pred += Hb * f.estimate(ids[static_cast<std::size_t>(b)]).vector;
    }
    z.residual() = st.z.template cast<S>() - pred;
    z.whitenStdDevs(st.sigma.template cast<S>());
    UpdateOptions opt;
    opt.scheme = scheme;
    const auto res = f.update(z, opt);
    if (usedGivens && res.scheme == RotationScheme::kGivens) *usedGivens = true;
    f.correct();
    Vl x(kDim);
    for (int b = 0; b < kBlocks; ++b) {
      x.segment(3 * b, 3) = f.estimate(ids[static_cast<std::size_t>(b)]).vector.template cast<Ld>();
    }
    // The distribution the filter holds: covariance of its (float) R, evaluated in long double.
    const Ml R = f.squareRootInformation().template cast<Ld>();
    const Ml Rinv = R.triangularView<Eigen::Upper>().solve(Ml::Identity(kDim, kDim));
    score(acc, x, Rinv * Rinv.transpose(), xt[s], Pt[s]);
    if (std::getenv("SRI_STRESS_VERBOSE")) {
      Accuracy one;
      score(one, x, Rinv * Rinv.transpose(), xt[s], Pt[s]);
      std::printf("  %s step %zu: state %.2e cov %.2e sigma %.2e scheme %d\n", sizeof(S) == 4 ? "float" : "double", s,
                  static_cast<double>(one.whitenedError), static_cast<double>(one.covError),
                  static_cast<double>(one.sigmaError), static_cast<int>(res.scheme));
    }
  }
  return acc;
}

Accuracy runFloatKf(const std::vector<Step>& steps, bool joseph, const Vl& x0,
                    const std::vector<Vl>& xt, const std::vector<Ml>& Pt) {
  test::CovarianceKf<float> kf;
  kf.joseph = joseph;
  kf.x = x0.cast<float>();
  kf.P = Eigen::MatrixXf::Identity(kDim, kDim) * 1e6f;
  Accuracy acc;
  for (std::size_t s = 0; s < steps.size(); ++s) {
    const Step& st = steps[s];
    kf.update(st.H.cast<float>(), st.z.cast<float>(),
              Eigen::MatrixXf(st.sigma.cast<float>().cwiseAbs2().asDiagonal()));
    score(acc, kf.x.cast<Ld>(), kf.P.cast<Ld>(), xt[s], Pt[s]);
  }
  return acc;
}

struct Truth {
  Vl x0;
  std::vector<Step> steps;
  std::vector<Vl> x;
  std::vector<Ml> P;
  std::vector<Ml> R;  ///< upper-triangular square-root information after each step
};

/// Truth without any recursion: after every step, the batch least-squares solution of the prior
/// and all rows so far, by Eigen's Householder QR of the whole whitened stack in long double
/// (64-bit mantissa). For this linear problem without process noise it is the exact posterior;
/// the square-root form keeps its error near eps·√cond ≈ 1e-13 (a long double covariance filter
/// would be at eps·cond ≈ 3e-7, too coarse to judge a double filter).
Truth makeTruth(unsigned seed) {
  std::mt19937 rng(seed * 7 + 1);
  std::normal_distribution<double> g(0.0, 1.0);
  Truth t;
  Vl xTrue(kDim);
  t.x0.resize(kDim);
  // Values of order 1 (as in a local frame): float must be able to hold the estimate to a fraction
  // of the smallest posterior σ (|x| · 6e-8 ≪ 1e-3); the difficulty is the spread of σ.
  for (int i = 0; i < kDim; ++i) {
    xTrue(i) = Ld(g(rng));
    t.x0(i) = xTrue(i) + Ld(g(rng));
  }
  t.steps = makeSteps(seed, xTrue);
  Ml A = Ml::Identity(kDim, kDim) / Ld(1e3);
  Vl b = A * t.x0;
  for (const Step& st : t.steps) {
    const int m0 = static_cast<int>(A.rows());
    const int m = static_cast<int>(st.H.rows());
    A.conservativeResize(m0 + m, Eigen::NoChange);
    b.conservativeResize(m0 + m);
    A.bottomRows(m) = st.sigma.cwiseInverse().asDiagonal() * st.H;
    b.tail(m) = st.sigma.cwiseInverse().asDiagonal() * st.z;
    Eigen::HouseholderQR<Ml> qr(A);
    const Ml R = qr.matrixQR().topRows(kDim).triangularView<Eigen::Upper>();
    const Vl qtb = (qr.householderQ().transpose() * b).head(kDim);
    const Ml Rinv = R.triangularView<Eigen::Upper>().solve(Ml::Identity(kDim, kDim));
    t.R.push_back(R);
    t.x.push_back(Rinv * qtb);
    t.P.push_back(Rinv * Rinv.transpose());
  }
  return t;
}

/// What float storage alone costs: the true R rounded to float, scored like the filters.
Accuracy floatRoundingFloor(const Truth& t) {
  Accuracy acc;
  for (std::size_t s = 0; s < t.steps.size(); ++s) {
    const Ml Rf = t.R[s].cast<float>().cast<Ld>();
    const Ml Rinv = Rf.triangularView<Eigen::Upper>().solve(Ml::Identity(kDim, kDim));
    score(acc, t.x[s].cast<float>().cast<Ld>(), Rinv * Rinv.transpose(), t.x[s], t.P[s]);
  }
  return acc;
}

TEST(SriStress, FloatSriMatchesTruthWhereFloatCovarianceEkfFails) {
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const Truth t = makeTruth(seed);
    bool usedGivens = false;
    const Accuracy sriF = runSri<float>(t.steps, RotationScheme::kAuto, t.x0, t.x, t.P, &usedGivens);
    const Accuracy sriD = runSri<double>(t.steps, RotationScheme::kAuto, t.x0, t.x, t.P);
    const Accuracy kfStd = runFloatKf(t.steps, false, t.x0, t.x, t.P);
    const Accuracy kfJos = runFloatKf(t.steps, true, t.x0, t.x, t.P);
    const Accuracy floor = floatRoundingFloor(t);
    std::printf(
        "seed %u, cond(P) up to %.1e. Whitened state error | marginal σ error | ‖whitened P − I‖:\n"
        "  SRI float  %.1e | %.1e | %.1e   (true R rounded to float: %.1e | %.1e | %.1e)\n"
        "  SRI double %.1e | %.1e | %.1e\n"
        "  EKF float  %.1e | %.1e | %.1e%s\n"
        "  EKF Joseph %.1e | %.1e | %.1e%s\n",
        seed, sriD.maxCondition, double(sriF.whitenedError), double(sriF.sigmaError), double(sriF.covError),
        double(floor.whitenedError), double(floor.sigmaError), double(floor.covError),
        double(sriD.whitenedError), double(sriD.sigmaError), double(sriD.covError),
        double(kfStd.whitenedError), double(kfStd.sigmaError), double(kfStd.covError),
        kfStd.lostDefiniteness ? "  NOT POSITIVE DEFINITE" : "", double(kfJos.whitenedError),
        double(kfJos.sigmaError), double(kfJos.covError),
        kfJos.lostDefiniteness ? "  NOT POSITIVE DEFINITE" : "");
    EXPECT_GT(sriD.maxCondition, 1e12);
    // Float SRI: mean within 0.15 posterior σ, marginal σ within 0.5 %, joint covariance within
    // an order of magnitude of what float storage of the exact factor allows (ε_float·√cond,
    // not ε_float·cond as the covariance form).
    EXPECT_LT(sriF.whitenedError, 0.15);
    EXPECT_LT(sriF.sigmaError, 5e-3);
    EXPECT_LT(sriF.covError, 10 * floor.covError);
    EXPECT_FALSE(sriF.lostDefiniteness);
    EXPECT_TRUE(usedGivens);  // kAuto recognised the stiff rows
    // Double SRI.
    EXPECT_LT(sriD.whitenedError, 1e-8);
    EXPECT_LT(sriD.sigmaError, 1e-9);
    EXPECT_LT(sriD.covError, 1e-6);
    // Float covariance filters: indefinite, or wrong by more than a posterior σ.
    EXPECT_TRUE(kfStd.lostDefiniteness || kfStd.whitenedError > 1 || kfStd.covError > 1);
    EXPECT_TRUE(kfJos.lostDefiniteness || kfJos.whitenedError > 1 || kfJos.covError > 1);
  }
}

// The measurement behind RotationScheme::kAuto: with mm rows on km priors, Householder in float
// buries the light prior information under ε·(heavy row) and the marginal σ of the prior-
// dominated directions drift by percents; with Givens rotations they stay at ~1e-6 while the
// stiff rows only meet priors and within a few 1e-3 later.
TEST(SriStress, GivensVersusHouseholderInFloat) {
  Ld hs = 0, gs = 0, hx = 0, gx = 0;
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const Truth t = makeTruth(seed);
    const Accuracy h = runSri<float>(t.steps, RotationScheme::kBlockedHouseholder, t.x0, t.x, t.P);
    const Accuracy g = runSri<float>(t.steps, RotationScheme::kGivens, t.x0, t.x, t.P);
    hs = std::max(hs, h.sigmaError);
    gs = std::max(gs, g.sigmaError);
    hx = std::max(hx, h.whitenedError);
    gx = std::max(gx, g.whitenedError);
  }
  std::printf("float, worst over 5 seeds: marginal σ error Householder %.1e, Givens %.1e; whitened "
              "state error Householder %.1e, Givens %.1e\n",
              double(hs), double(gs), double(hx), double(gx));
  EXPECT_LT(gs, 5e-3);
  EXPECT_GT(hs, 5 * gs);
  EXPECT_LT(gx, 0.15);
}


// Mixed precision (sri_filter.hpp): a float filter keeps its nominal values in double. A position
// 1.5 km from the origin, where float resolves only 1.2e-4 m, refined by 4000 fixes of σ = 2 cm:
// the late corrections (σ²/(n σ_prior²)·innovation, a few 1e-6 m) are below float's resolution
// there. Rounding the estimate to float after every correction (as a float-only filter did) loses
// them and ends ~3e-5 m off the double filter in every run; with the double nominal the float
// filter ends where the double one does (float R and r only round the small error state).
TEST(SriMixedPrecision, FloatFilterKeepsCorrectionsBelowFloatResolution) {
  const Eigen::Vector3d x0(1523.4567, -812.25, 48.0);
  const Eigen::Vector3d truth = x0 + Eigen::Vector3d(0.3, -0.2, 0.1);
  std::mt19937 rng(7);
  std::normal_distribution<double> N(0.0, 1.0);
  SriFilter<float> ff;
  SriFilter<double> fd;
  const BlockId pf = ff.addBlock(BlockSpec::vector("p", 3), BlockEstimate<float>::fromVector(x0.cast<float>()),
                                 Prior<float>::stdDev(3, 1.0f));
  ff.setNominal(pf, BlockEstimate<double>::fromVector(x0));
  const BlockId pd = fd.addBlock(BlockSpec::vector("p", 3), BlockEstimate<double>::fromVector(x0),
                                 Prior<double>::stdDev(3, 1.0));
  Eigen::Vector3f naive = x0.cast<float>();  // a float filter's estimate: rounded after each step
  for (int n = 1; n <= 4000; ++n) {
    const Eigen::Vector3d z = truth + 0.02 * Eigen::Vector3d(N(rng), N(rng), N(rng));
    Measurement<float> mf(3);
    mf.jacobian(pf, 3).setIdentity();
    mf.residual() = (z - ff.nominal(pf).vector).cast<float>();
    mf.whitenStdDev(0.02f);
    ff.update(mf);
    ff.correct();
    Measurement<double> md(3);
    md.jacobian(pd, 3).setIdentity();
    md.residual() = z - fd.estimate(pd).vector;
    md.whitenStdDev(0.02);
    fd.update(md);
    fd.correct();
    // The same recursion (gain 1 / (n + σ²/σ_prior²)) with the estimate stored in float.
    const float gain = 1.0f / (static_cast<float>(n) + 0.02f * 0.02f);
    naive += gain * (z.cast<float>() - naive);
  }
  const Eigen::Vector3d xd = fd.estimate(pd).vector;
  const double mixed_err = (ff.nominal(pf).vector - xd).cwiseAbs().maxCoeff();
  const double naive_err = (naive.cast<double>() - xd).cwiseAbs().maxCoeff();
  std::printf("float filter vs double after 4000 fixes at 1.5 km: double nominal %.1e m, float-rounded "
              "estimate %.1e m\n", mixed_err, naive_err);
  EXPECT_LT(mixed_err, 2e-6);
  EXPECT_GT(naive_err, 1e-5);
  EXPECT_LT((xd - truth).norm(), 0.002);
  // estimate() is the double nominal rounded to float.
  EXPECT_EQ(ff.estimate(pf).vector, ff.nominal(pf).vector.cast<float>());
  // setNominal refuses a value that is not the current one up to rounding.
  EXPECT_THROW(ff.setNominal(pf, BlockEstimate<double>::fromVector(xd + Eigen::Vector3d(0.5, 0, 0))),
               std::invalid_argument);
}

// The double nominal values follow the blocks through reorder, marginalize and setEstimate.
TEST(SriMixedPrecision, NominalFollowsReorderMarginalizeAndSetEstimate) {
  SriFilter<float> f;
  const Eigen::Vector3d a(1000.0001, 2, 3), b(-2000.0003, 5, 6), c(7, 8, 3000.0007);
  std::vector<BlockId> ids;
  for (const Eigen::Vector3d& v : {a, b, c}) {
    ids.push_back(f.addBlock(BlockSpec::vector("v", 3), BlockEstimate<float>::fromVector(v.cast<float>()),
                             Prior<float>::stdDev(3, 1.0f)));
    f.setNominal(ids.back(), BlockEstimate<double>::fromVector(v));
  }
  const BlockId q = f.addBlock(BlockSpec::pose("q"), BlockEstimate<float>::zero(BlockKind::kPose, 6),
                               Prior<float>::stdDev(6, 1.0f));
  f.reorder(std::vector<BlockId>{q, ids[2], ids[0], ids[1]});
  EXPECT_EQ(f.nominal(ids[0]).vector, a);
  EXPECT_EQ(f.nominal(ids[1]).vector, b);
  EXPECT_EQ(f.nominal(ids[2]).vector, c);
  f.marginalize(ids[2]);
  EXPECT_EQ(f.nominal(ids[0]).vector, a);
  EXPECT_EQ(f.nominal(ids[1]).vector, b);
  f.setEstimate(ids[0], BlockEstimate<float>::fromVector(Eigen::Vector3f(1, 1, 1)));
  EXPECT_EQ(f.nominal(ids[0]).vector, Eigen::Vector3d(1, 1, 1));
  EXPECT_EQ(f.nominal(ids[1]).vector, b);
  EXPECT_TRUE(f.nominal(q).rotation.coeffs().isApprox(Eigen::Quaterniond::Identity().coeffs()));
}

}  // namespace
}  // namespace gvins::sri
