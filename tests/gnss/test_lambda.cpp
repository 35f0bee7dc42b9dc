// LAMBDA, the ILS search and ambiguity validation against independent truth: the published
// three-dimensional example of de Jonge & Tiberius (1996) and Teunissen (1995), brute-force
// enumeration of small random problems, Monte Carlo success rates and simulated GNSS-like
// problems with known integers.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/LU>

#include "gvins/gnss/ambiguity_resolution.hpp"
#include "gvins/gnss/lambda.hpp"

namespace gvins {
namespace {

Eigen::MatrixXd exampleQ() {
  Eigen::MatrixXd Q(3, 3);
  Q << 6.290, 5.978, 0.544,  //
      5.978, 6.292, 2.340,   //
      0.544, 2.340, 6.288;
  return Q;
}

struct BruteForce {
  std::vector<Eigen::VectorXd> best;  // two best
  std::vector<double> norms;
};

/// Enumerates every integer vector in the box that must contain the two best solutions: any z
/// with (â−z)ᵀQ⁻¹(â−z) ≤ R² has |â_i − z_i| ≤ R √Q_ii, and R² is taken from two distinct integer
/// vectors (so the best two lie inside). Returns nothing if the box is too large.
std::optional<BruteForce> bruteForce(const Eigen::VectorXd& a, const Eigen::MatrixXd& Q, long maxPoints = 400000) {
  const int n = static_cast<int>(a.size());
  const Eigen::MatrixXd Qi = Q.inverse();
  auto norm = [&](const Eigen::VectorXd& z) { return (a - z).dot(Qi * (a - z)); };
  Eigen::VectorXd r = a.array().round().matrix();
  Eigen::VectorXd r2 = r;
  r2[0] += 1.0;
  const double R2 = std::max(norm(r), norm(r2));
  std::vector<long> lo(n), hi(n);
  double points = 1.0;
  for (int i = 0; i < n; ++i) {
    const double w = std::sqrt(R2 * Q(i, i));
    lo[i] = static_cast<long>(std::ceil(a[i] - w));
    hi[i] = static_cast<long>(std::floor(a[i] + w));
    points *= static_cast<double>(hi[i] - lo[i] + 1);
  }
  if (points > static_cast<double>(maxPoints)) return std::nullopt;
  BruteForce bf;
  std::vector<std::pair<double, Eigen::VectorXd>> all;
  Eigen::VectorXd z(n);
  std::vector<long> idx(lo);
  double b1 = 1e300, b2 = 1e300;
  Eigen::VectorXd z1, z2;
  for (;;) {
    for (int i = 0; i < n; ++i) z[i] = static_cast<double>(idx[i]);
    const double v = norm(z);
    if (v < b1) {
      b2 = b1;
      z2 = z1;
      b1 = v;
      z1 = z;
    } else if (v < b2) {
      b2 = v;
      z2 = z;
    }
    int i = 0;
    while (i < n && ++idx[i] > hi[i]) {
      idx[i] = lo[i];
      ++i;
    }
    if (i == n) break;
  }
  bf.best = {z1, z2};
  bf.norms = {b1, b2};
  return bf;
}

/// Random SPD matrix with strong correlations, like GNSS DD ambiguities after a few epochs:
/// Q = s (A Aᵀ + ε I) with A having a few dominant directions.
Eigen::MatrixXd randomCorrelatedQ(std::mt19937& rng, int n, double scale) {
  std::normal_distribution<double> g(0.0, 1.0);
  Eigen::MatrixXd A(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) A(i, j) = g(rng);
  // A common (nearly singular) direction makes the problem highly correlated.
  Eigen::VectorXd c(n);
  for (int i = 0; i < n; ++i) c[i] = 1.0 + 0.3 * g(rng);
  Eigen::MatrixXd Q = 0.05 * A * A.transpose() + 4.0 * c * c.transpose() + 0.02 * Eigen::MatrixXd::Identity(n, n);
  return scale * Q;
}

TEST(Lambda, LtdlReconstructsTheMatrix) {
  std::mt19937 rng(7);
  for (int n : {1, 2, 5, 12, 40}) {
    const Eigen::MatrixXd Q = randomCorrelatedQ(rng, n, 0.7);
    const auto f = ltdlFactorize(Q);
    ASSERT_TRUE(f);
    const Eigen::MatrixXd back = f->L.transpose() * f->d.asDiagonal() * f->L;
    EXPECT_LT((back - Q).cwiseAbs().maxCoeff(), 1e-11 * Q.cwiseAbs().maxCoeff()) << n;
    EXPECT_TRUE(f->L.isLowerTriangular());
    for (int i = 0; i < n; ++i) EXPECT_EQ(f->L(i, i), 1.0);
    // d[n-1] is the unconditional variance of the last ambiguity.
    EXPECT_NEAR(f->d[n - 1], Q(n - 1, n - 1), 1e-12 * Q(n - 1, n - 1));
  }
  Eigen::MatrixXd notPd = Eigen::MatrixXd::Identity(2, 2);
  notPd(0, 1) = notPd(1, 0) = 1.5;
  EXPECT_FALSE(ltdlFactorize(notPd));
}

// de Jonge & Tiberius (1996, LGR series 12, the example of sections 3.8/4.x; also Teunissen 1995):
// Q_â as below, â = (5.45, 3.10, 2.97). The decorrelated covariance Q_ẑ has diagonal
// 4.476, 1.146, 0.626 (to three decimals) and the ILS solution is ǎ = (5, 3, 4); the two best
// squared norms (checked here also by enumeration) are 0.2183 and 0.3073 with (6, 4, 4) second.
TEST(Lambda, PublishedThreeDimensionalExample) {
  const Eigen::MatrixXd Q = exampleQ();
  Eigen::VectorXd a(3);
  a << 5.45, 3.10, 2.97;
  const LambdaResult r = lambda(a, Q);
  ASSERT_TRUE(r.ok);
  ASSERT_EQ(r.fixed.size(), 2u);
  EXPECT_EQ(r.fixed[0], Eigen::Vector3d(5, 3, 4));
  EXPECT_EQ(r.fixed[1], Eigen::Vector3d(6, 4, 4));
  EXPECT_NEAR(r.squaredNorms[0], 0.2183, 5e-5);
  EXPECT_NEAR(r.squaredNorms[1], 0.3073, 5e-5);
  EXPECT_NEAR(r.ratio, 0.3073 / 0.2183, 1e-3);
  // Z is integer and unimodular, Q_z = ZᵀQZ equals the transformed factor.
  const Eigen::MatrixXd& Z = r.reduction.Z;
  EXPECT_EQ(Z, Z.array().round().matrix());
  EXPECT_NEAR(std::abs(Z.determinant()), 1.0, 1e-12);
  EXPECT_LT((Z * r.reduction.Zinv - Eigen::MatrixXd::Identity(3, 3)).cwiseAbs().maxCoeff(), 1e-12);
  const Eigen::MatrixXd Qz = Z.transpose() * Q * Z;
  const auto& f = r.reduction.factor;
  EXPECT_LT((f.L.transpose() * f.d.asDiagonal() * f.L - Qz).cwiseAbs().maxCoeff(), 1e-10);
  std::vector<double> diag{Qz(0, 0), Qz(1, 1), Qz(2, 2)};
  std::sort(diag.begin(), diag.end());
  EXPECT_NEAR(diag[0], 0.626, 5e-4);
  EXPECT_NEAR(diag[1], 1.146, 5e-4);
  EXPECT_NEAR(diag[2], 4.476, 5e-4);
  // The correlation is gone: the largest correlation coefficient of Q_z is far below that of Q
  // (0.95 between the first two ambiguities).
  double maxCorr = 0.0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < i; ++j) maxCorr = std::max(maxCorr, std::abs(Qz(i, j)) / std::sqrt(Qz(i, i) * Qz(j, j)));
  EXPECT_LT(maxCorr, 0.2);
  // Conditional variances are ordered as the reduction promises for the last pair.
  EXPECT_LE(f.d[2], f.d[1] + f.L(2, 1) * f.L(2, 1) * f.d[2] + 1e-12);
  // The same result from enumeration.
  const auto bf = bruteForce(a, Q);
  ASSERT_TRUE(bf);
  EXPECT_EQ(bf->best[0], r.fixed[0]);
  EXPECT_NEAR(bf->norms[0], r.squaredNorms[0], 1e-12);
  EXPECT_NEAR(bf->norms[1], r.squaredNorms[1], 1e-12);
}

TEST(Lambda, MatchesBruteForceOnRandomSmallProblems) {
  std::mt19937 rng(2024);
  std::uniform_real_distribution<double> u(-20.0, 20.0);
  std::uniform_real_distribution<double> scale(0.05, 1.5);
  int checked = 0;
  for (int trial = 0; trial < 400 && checked < 80; ++trial) {
    const int n = 2 + trial % 4;  // 2..5
    const Eigen::MatrixXd Q = randomCorrelatedQ(rng, n, scale(rng));
    Eigen::VectorXd a(n);
    for (int i = 0; i < n; ++i) a[i] = u(rng);
    const auto bf = bruteForce(a, Q);
    if (!bf) continue;
    const LambdaResult r = lambda(a, Q);
    ASSERT_TRUE(r.ok);
    ++checked;
    EXPECT_NEAR(r.squaredNorms[0], bf->norms[0], 1e-9 * (1.0 + bf->norms[0])) << trial;
    EXPECT_NEAR(r.squaredNorms[1], bf->norms[1], 1e-9 * (1.0 + bf->norms[1])) << trial;
    // Ties are practically impossible with continuous random data.
    EXPECT_EQ(r.fixed[0], bf->best[0]) << trial;
    // Every Z is unimodular.
    EXPECT_NEAR(std::abs(r.reduction.Z.determinant()), 1.0, 1e-9) << trial;
  }
  EXPECT_GE(checked, 60);
}

TEST(Lambda, FindsRequestedNumberOfCandidatesInOrder) {
  std::mt19937 rng(99);
  const Eigen::MatrixXd Q = randomCorrelatedQ(rng, 4, 0.3);
  Eigen::VectorXd a(4);
  a << 1.3, -2.7, 10.45, 0.1;
  IlsSearchOptions o;
  o.candidates = 6;
  const LambdaResult r = lambda(a, Q, o);
  ASSERT_TRUE(r.ok);
  ASSERT_EQ(r.fixed.size(), 6u);
  const Eigen::MatrixXd Qi = Q.inverse();
  for (int i = 0; i < 6; ++i) {
    const Eigen::VectorXd e = a - r.fixed[i];
    EXPECT_NEAR(e.dot(Qi * e), r.squaredNorms[i], 1e-9);
    if (i) {
      EXPECT_GE(r.squaredNorms[i], r.squaredNorms[i - 1]);
    }
    for (int j = 0; j < i; ++j) EXPECT_NE(r.fixed[i], r.fixed[j]);
  }
}

TEST(Lambda, OneDimensionRoundsAndNodeLimitIsReported) {
  Eigen::MatrixXd Q(1, 1);
  Q << 0.04;
  Eigen::VectorXd a(1);
  a << -3.3;
  const LambdaResult r = lambda(a, Q);
  ASSERT_TRUE(r.ok);
  EXPECT_EQ(r.fixed[0][0], -3.0);
  EXPECT_EQ(r.fixed[1][0], -4.0);
  EXPECT_NEAR(r.squaredNorms[0], 0.09 / 0.04, 1e-12);
  EXPECT_NEAR(r.squaredNorms[1], 0.49 / 0.04, 1e-12);

  std::mt19937 rng(5);
  const Eigen::MatrixXd Qbig = randomCorrelatedQ(rng, 30, 50.0);
  Eigen::VectorXd abig = Eigen::VectorXd::Constant(30, 0.5);
  IlsSearchOptions tiny;
  tiny.maxNodes = 10;
  const LambdaResult cut = lambda(abig, Qbig, tiny);
  EXPECT_FALSE(cut.ok);
  EXPECT_GT(cut.nodes, 10);
}

/// Single-epoch multi-GNSS dual-frequency problem of 60 DD ambiguities (three systems, many
/// permutations in the reduction): the integers are recovered, the transformation stays exact and
/// its entries small. (The real-data counterpart, nagoya epochs in instantaneous mode, is in
/// test_rtk.)
/// Normal matrix of one epoch of dual-frequency DD phase (4 mm) and code (0.5 m) on three systems
/// with 11, 9 and 13 satellites (60 ambiguities after the position's 3 columns), DDs against each
/// system's first satellite; line-of-sight unit vectors los[system][satellite].
Eigen::MatrixXd multiSystemNormalMatrix(const std::vector<std::vector<Eigen::Vector3d>>& los) {
  const double lam[3][2] = {{0.19029367, 0.24421021}, {0.19029367, 0.25482804}, {0.19203949, 0.24834936}};
  int n = 0;
  for (const auto& s : los) n += 2 * (static_cast<int>(s.size()) - 1);
  Eigen::MatrixXd N = Eigen::MatrixXd::Zero(3 + n, 3 + n);
  int col = 3;
  for (int sys = 0; sys < 3; ++sys) {
    const auto& u = los[static_cast<std::size_t>(sys)];
    const int m = static_cast<int>(u.size()) - 1;
    const Eigen::MatrixXd Ci = (Eigen::MatrixXd::Identity(m, m) + Eigen::MatrixXd::Ones(m, m)).inverse();
    for (int f = 0; f < 2; ++f) {
      Eigen::MatrixXd H = Eigen::MatrixXd::Zero(m, 3 + n), Hc = Eigen::MatrixXd::Zero(m, 3 + n);
      for (int j = 0; j < m; ++j) {
        const Eigen::RowVector3d row = -(u[static_cast<std::size_t>(j) + 1] - u[0]).transpose();
        H.block<1, 3>(j, 0) = row;
        Hc.block<1, 3>(j, 0) = row;
        H(j, col + f * m + j) = lam[sys][f];
      }
      N += H.transpose() * Ci * H / (0.004 * 0.004) + Hc.transpose() * Ci * Hc / (0.5 * 0.5);
    }
    col += 2 * m;
  }
  return N;
}

std::vector<std::vector<Eigen::Vector3d>> randomLinesOfSight(std::mt19937& rng) {
  std::uniform_real_distribution<double> ang(0.0, 6.283), el(0.27, 1.5);
  std::vector<std::vector<Eigen::Vector3d>> los;
  for (int ns : {11, 9, 13}) {
    los.emplace_back();
    for (int i = 0; i < ns; ++i) {
      const double a = ang(rng), e = el(rng);
      los.back().emplace_back(std::cos(e) * std::sin(a), std::cos(e) * std::cos(a), std::sin(e));
    }
  }
  return los;
}

TEST(Lambda, LargeMultiSystemProblemStaysExact) {
  std::mt19937 rng(23);
  std::normal_distribution<double> g(0.0, 1.0);
  const Eigen::MatrixXd N = multiSystemNormalMatrix(randomLinesOfSight(rng));
  const int n = static_cast<int>(N.rows()) - 3;
  ASSERT_EQ(n, 60);
  const Eigen::MatrixXd Q = N.inverse().bottomRightCorner(n, n);
  const Eigen::MatrixXd L = Q.llt().matrixL();
  int correct = 0;
  for (int trial = 0; trial < 20; ++trial) {
    Eigen::VectorXd truth(n), w(n);
    for (int i = 0; i < n; ++i) {
      truth[i] = std::round(50.0 * g(rng));
      w[i] = g(rng);
    }
    const Eigen::VectorXd a = truth + L * w;
    const LambdaResult r = lambda(a, Q);
    ASSERT_TRUE(r.ok) << trial;
    EXPECT_GT(r.reduction.permutations, 100);
    EXPECT_EQ(r.reduction.Z * r.reduction.Zinv, Eigen::MatrixXd::Identity(n, n)) << trial;
    EXPECT_LT(r.reduction.Z.cwiseAbs().maxCoeff(), 100.0) << trial;
    const auto& f = r.reduction.factor;
    const Eigen::MatrixXd Qz = r.reduction.Z.transpose() * Q * r.reduction.Z;
    EXPECT_LT((f.L.transpose() * f.d.asDiagonal() * f.L - Qz).cwiseAbs().maxCoeff(), 1e-9 * Qz.cwiseAbs().maxCoeff());
    // The squared norm of the best candidate is a chi-square with n degrees of freedom at most.
    EXPECT_LT(r.squaredNorms[0], 3.0 * n) << trial;
    if (r.fixed[0] == truth) ++correct;
  }
  EXPECT_GE(correct, 19);
}

/// Warm start (ReductionStart): a filter's float ambiguities one epoch later (the satellites
/// moved by ~0.1°, a second epoch of information) reduced from the previous epoch's basis give
/// the same ILS solution and norms as a cold start, with a basis that meets the reduction
/// conditions and far fewer permutations.
TEST(Lambda, WarmStartFromThePreviousEpochMatchesTheColdStart) {
  std::mt19937 rng(41);
  std::normal_distribution<double> g(0.0, 1.0);
  auto los = randomLinesOfSight(rng);
  const Eigen::MatrixXd N1 = multiSystemNormalMatrix(los);
  for (auto& s : los) {
    for (auto& u : s) u = (u + 2e-4 * Eigen::Vector3d(g(rng), g(rng), g(rng))).normalized();
  }
  const Eigen::MatrixXd N2 = N1 + multiSystemNormalMatrix(los);
  const int n = static_cast<int>(N1.rows()) - 3;
  const Eigen::MatrixXd Q1 = N1.inverse().bottomRightCorner(n, n);
  const Eigen::MatrixXd Q2 = N2.inverse().bottomRightCorner(n, n);
  const Eigen::MatrixXd L2 = Q2.llt().matrixL();
  Eigen::VectorXd truth(n), w(n);
  for (int i = 0; i < n; ++i) {
    truth[i] = std::round(50.0 * g(rng));
    w[i] = g(rng);
  }
  const Eigen::VectorXd a1 = truth + Q1.llt().matrixL().toDenseMatrix() * w;
  const LambdaResult first = lambda(a1, Q1);
  ASSERT_TRUE(first.ok);
  const ReductionStart start{first.reduction.Z, first.reduction.Zinv};
  for (int trial = 0; trial < 10; ++trial) {
    for (int i = 0; i < n; ++i) w[i] = g(rng);
    const Eigen::VectorXd a2 = truth + L2 * w;
    const LambdaResult cold = lambda(a2, Q2);
    const LambdaResult warm = lambda(a2, Q2, {}, &start);
    ASSERT_TRUE(cold.ok && warm.ok) << trial;
    EXPECT_EQ(warm.fixed[0], cold.fixed[0]) << trial;
    EXPECT_EQ(warm.fixed[1], cold.fixed[1]) << trial;
    EXPECT_NEAR(warm.squaredNorms[0], cold.squaredNorms[0], 1e-8 * cold.squaredNorms[0]) << trial;
    EXPECT_NEAR(warm.ratio, cold.ratio, 1e-8 * cold.ratio) << trial;
    EXPECT_EQ(warm.fixed[0], truth) << trial;
    // Cold: hundreds of permutations; warm: a handful.
    EXPECT_GT(cold.reduction.permutations, 100);
    EXPECT_LT(warm.reduction.permutations, cold.reduction.permutations / 10) << trial;
    // The composed basis is unimodular, factors Zᵀ Q₂ Z and is reduced.
    const auto& r = warm.reduction;
    EXPECT_EQ(r.Z * r.Zinv, Eigen::MatrixXd::Identity(n, n)) << trial;
    const Eigen::MatrixXd Qz = r.Z.transpose() * Q2 * r.Z;
    EXPECT_LT((r.factor.L.transpose() * r.factor.d.asDiagonal() * r.factor.L - Qz).cwiseAbs().maxCoeff(),
              1e-9 * Qz.cwiseAbs().maxCoeff());
    for (int k = 0; k + 1 < n; ++k) {
      const double l = r.factor.L(k + 1, k);
      EXPECT_LE(std::abs(l), 0.5 + 1e-12) << k;
      EXPECT_GE(r.factor.d[k] + l * l * r.factor.d[k + 1], (1.0 - 1e-9) * r.factor.d[k + 1]) << k;
    }
  }
  // A start of the wrong size is ignored.
  const ReductionStart small{Eigen::MatrixXd::Identity(3, 3), Eigen::MatrixXd::Identity(3, 3)};
  const LambdaResult ignored = lambda(a1, Q1, {}, &small);
  EXPECT_EQ(ignored.fixed[0], first.fixed[0]);
  EXPECT_EQ(ignored.reduction.permutations, first.reduction.permutations);
}

/// Bootstrapping in the decorrelated domain: success counted by simulation must match
/// Teunissen's (1998) formula, and ILS must succeed at least as often.
TEST(Lambda, BootstrappedSuccessRateMatchesMonteCarlo) {
  std::mt19937 rng(11);
  const int n = 4;
  const Eigen::MatrixXd Q0 = randomCorrelatedQ(rng, n, 1.0);
  // Scale the problem until the bootstrapped success rate is in the informative range.
  Eigen::MatrixXd Q = Q0;
  Reduction red;
  double pBoot = 1.0;
  for (double scale = 0.001; scale < 10.0; scale *= 1.25) {
    Q = scale * Q0;
    const auto f = ltdlFactorize(Q);
    ASSERT_TRUE(f);
    red = reduceLambda(*f);
    pBoot = bootstrapSuccessRate(red.factor.d);
    if (pBoot < 0.85) break;
  }
  ASSERT_GT(pBoot, 0.3);
  ASSERT_LT(pBoot, 0.95);
  const Eigen::MatrixXd C = Q.llt().matrixL();
  std::normal_distribution<double> g(0.0, 1.0);
  const int trials = 4000;
  int bootOk = 0, ilsOk = 0;
  const Eigen::VectorXd truth = Eigen::VectorXd::Zero(n);
  for (int t = 0; t < trials; ++t) {
    Eigen::VectorXd w(n);
    for (int i = 0; i < n; ++i) w[i] = g(rng);
    const Eigen::VectorXd a = truth + C * w;
    // Bootstrapping: sequential conditional rounding of z = Zᵀa from the last component.
    const Eigen::VectorXd zhat = red.Z.transpose() * a;
    Eigen::VectorXd z(n), zc(n);
    for (int k = n - 1; k >= 0; --k) {
      double s = 0.0;
      for (int j = k + 1; j < n; ++j) s += red.factor.L(j, k) * (z[j] - zc[j]);
      zc[k] = zhat[k] + s;
      z[k] = std::round(zc[k]);
    }
    const Eigen::VectorXd aBoot = (red.Zinv.transpose() * z).array().round().matrix();
    if (aBoot == truth) ++bootOk;
    const LambdaResult r = lambda(a, Q);
    if (r.ok && r.fixed[0] == truth) ++ilsOk;
  }
  const double pHat = static_cast<double>(bootOk) / trials;
  const double sigma = std::sqrt(pBoot * (1 - pBoot) / trials);
  EXPECT_NEAR(pHat, pBoot, 4.0 * sigma) << "bootstrapped success rate " << pBoot;
  EXPECT_GE(ilsOk, bootOk - 3.0 * std::sqrt(static_cast<double>(trials)) * sigma);
}

/// A GNSS-like problem: DD ambiguities of 12 satellites on two frequencies after a short static
/// occupation (float values from simulated noise), with the true integers known.
TEST(AmbiguityResolution, FixesSimulatedDualFrequencyProblemAndRejectsWeakOne) {
  std::mt19937 rng(3);
  std::normal_distribution<double> g(0.0, 1.0);
  const int nsat = 12, n = 2 * (nsat - 1);
  // Design: geometry-driven correlation through a 3-D baseline; DD phases (σ 3 mm) and codes
  // (σ 0.3 m) on L1/L2 from 10 epochs with slowly turning line-of-sight vectors.
  const double lam1 = 0.19029367, lam2 = 0.24421021;
  auto solve = [&](double codeSigma, int epochs, int nsatUsed) {
    // Satellites beyond nsatUsed are left out by giving their rows no weight (their ambiguities
    // are then only known from a weak prior).
    Eigen::MatrixXd N = 1e-6 * Eigen::MatrixXd::Identity(3 + n, 3 + n);
    std::vector<Eigen::Vector3d> los(nsat);
    std::uniform_real_distribution<double> ang(0.0, 6.283);
    std::uniform_real_distribution<double> el(0.25, 1.4);
    std::vector<double> az(nsat), e(nsat);
    for (int s = 0; s < nsat; ++s) {
      az[s] = ang(rng);
      e[s] = el(rng);
    }
    for (int ep = 0; ep < epochs; ++ep) {
      for (int s = 0; s < nsat; ++s) {
        const double a = az[s] + 0.002 * ep, el2 = e[s] + 0.001 * ep;
        los[s] = Eigen::Vector3d(std::cos(el2) * std::sin(a), std::cos(el2) * std::cos(a), std::sin(el2));
      }
      for (int f = 0; f < 2; ++f) {
        const double lam = f == 0 ? lam1 : lam2;
        // DD rows with satellite 0 as reference; covariance of DDs: σ²(I + 11ᵀ).
        const int m = nsat - 1;
        Eigen::MatrixXd H = Eigen::MatrixXd::Zero(m, 3 + n), Hc = Eigen::MatrixXd::Zero(m, 3 + n);
        for (int j = 0; j < m; ++j) {
          if (j + 1 >= nsatUsed) continue;
          H.block<1, 3>(j, 0) = -(los[j + 1] - los[0]).transpose();
          H(j, 3 + f * m + j) = lam;
          Hc.block<1, 3>(j, 0) = -(los[j + 1] - los[0]).transpose();
        }
        Eigen::MatrixXd C = Eigen::MatrixXd::Identity(m, m) + Eigen::MatrixXd::Ones(m, m);
        const Eigen::MatrixXd Ci = C.inverse();
        N += H.transpose() * Ci * H / (0.003 * 0.003);
        N += Hc.transpose() * Ci * Hc / (codeSigma * codeSigma);
      }
    }
    return Eigen::MatrixXd(N.inverse().bottomRightCorner(n, n));
  };
  Eigen::VectorXd truth(n);
  std::uniform_int_distribution<int> ui(-1000000, 1000000);
  for (int i = 0; i < n; ++i) truth[i] = ui(rng);

  const Eigen::MatrixXd Qgood = solve(0.3, 10, nsat);
  const Eigen::MatrixXd Lg = Qgood.llt().matrixL();
  Eigen::VectorXd w(n);
  for (int i = 0; i < n; ++i) w[i] = g(rng);
  const Eigen::VectorXd aGood = truth + Lg * w;
  const AmbiguityFix good = resolveAmbiguities(aGood, Qgood);
  ASSERT_TRUE(good.fixed);
  EXPECT_FALSE(good.partial);
  EXPECT_EQ(good.fullSolution, truth);
  EXPECT_GT(good.ratio, 3.0);
  EXPECT_GT(good.successRate, 0.99);

  // Five satellites, code 3 m and a single epoch: the float solution cannot support a reliable
  // fix of the ambiguities of those satellites.
  const Eigen::MatrixXd QweakAll = solve(3.0, 1, 5);
  const int nw = 8;  // DDs of satellites 1..4 on both frequencies
  std::vector<int> keep;
  for (int f = 0; f < 2; ++f)
    for (int j = 0; j < 4; ++j) keep.push_back(f * (nsat - 1) + j);
  Eigen::MatrixXd Qweak(nw, nw);
  for (int i = 0; i < nw; ++i)
    for (int j = 0; j < nw; ++j) Qweak(i, j) = QweakAll(keep[i], keep[j]);
  const Eigen::MatrixXd Lw = Qweak.llt().matrixL();
  Eigen::VectorXd ww(nw), tw(nw);
  for (int i = 0; i < nw; ++i) {
    ww[i] = g(rng);
    tw[i] = truth[keep[i]];
  }
  const Eigen::VectorXd aWeak = tw + Lw * ww;
  AmbiguityResolutionOptions strict;
  strict.partial = false;
  strict.validation = AmbiguityValidation::SuccessRate;
  const AmbiguityFix weak = resolveAmbiguities(aWeak, Qweak, strict);
  EXPECT_FALSE(weak.fixed);
  EXPECT_LT(weak.fullSuccessRate, 0.999);
}

/// Partial fixing: a problem whose full set is unreliable (several ambiguities very weak) but
/// whose well-determined part passes; the fixed combinations must be the true ones.
TEST(AmbiguityResolution, PartialFixRecoversTheWellDeterminedSubset) {
  std::mt19937 rng(17);
  std::normal_distribution<double> g(0.0, 1.0);
  const int n = 10;
  // Seven precise ambiguities (σ ≈ 0.03 cycles, correlated) and three loose ones (σ ≈ 2 cycles).
  Eigen::MatrixXd A(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) A(i, j) = g(rng);
  Eigen::VectorXd s(n);
  s << 0.03, 0.03, 0.03, 0.03, 0.03, 0.03, 0.03, 2.0, 2.0, 2.0;
  const Eigen::MatrixXd Qo = (A * A.transpose() / n + Eigen::MatrixXd::Identity(n, n)) * 0.5;
  const Eigen::VectorXd dn = Qo.diagonal().cwiseSqrt().cwiseInverse();
  const Eigen::VectorXd sc = s.cwiseProduct(dn);
  const Eigen::MatrixXd Q = sc.asDiagonal() * Qo * sc.asDiagonal();
  Eigen::VectorXd truth(n);
  for (int i = 0; i < n; ++i) truth[i] = std::round(100.0 * g(rng));
  const Eigen::MatrixXd L = Q.llt().matrixL();
  int partialOk = 0, fixedCount = 0;
  for (int trial = 0; trial < 30; ++trial) {
    Eigen::VectorXd w(n);
    for (int i = 0; i < n; ++i) w[i] = g(rng);
    const Eigen::VectorXd a = truth + L * w;
    const AmbiguityFix fx = resolveAmbiguities(a, Q);
    if (!fx.fixed) continue;
    ++fixedCount;
    EXPECT_TRUE(fx.partial) << trial;
    EXPECT_GE(fx.numFixed(), 4);
    EXPECT_LT(fx.numFixed(), n);
    // Fixed combinations are integer rows and equal T·truth.
    EXPECT_EQ(fx.T, fx.T.array().round().matrix());
    if ((fx.T * truth - fx.values).cwiseAbs().maxCoeff() < 1e-9) ++partialOk;
  }
  EXPECT_GE(fixedCount, 25);
  EXPECT_EQ(partialOk, fixedCount);
}

/// Fixed-failure-rate ratio test: the simulated critical value bounds the failure rate of a weak
/// model, checked against an independent Monte Carlo run (other seed, other integer vectors),
/// where the fixed ratio threshold 3 fails far more often; a strong model needs no more than 1.
TEST(AmbiguityResolution, FixedFailureRateCriticalRatioBoundsTheFailures) {
  std::mt19937 rng(2024);
  std::normal_distribution<double> g(0.0, 1.0);
  // Five DD ambiguities of a single-epoch, single-frequency model: the three position directions
  // (metre-level code) dominate, the phase-only directions are precise.
  const int n = 5;
  Eigen::MatrixXd G(n, 3);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < 3; ++j) G(i, j) = g(rng);
  const Eigen::MatrixXd Q = (G * (0.6 * 0.6) * G.transpose() + 0.01 * (Eigen::MatrixXd::Identity(n, n) +
                                                                         Eigen::MatrixXd::Ones(n, n))) / (0.19 * 0.19);
  AmbiguityResolutionOptions o;
  o.partial = false;
  o.maxFailureRate = 0.01;
  const LambdaResult probe = lambda(Eigen::VectorXd::Zero(n), Q);
  ASSERT_TRUE(probe.ok);
  ASSERT_LT(probe.successRate, 0.9);  // weak
  const double critical = fixedFailureRateCriticalRatio(probe.reduction.factor, o);
  EXPECT_GT(critical, 3.0);
  EXPECT_EQ(critical, fixedFailureRateCriticalRatio(probe.reduction.factor, o));  // deterministic
  const Eigen::MatrixXd L = Q.llt().matrixL();
  const int trials = 4000;
  int wrongFfrt = 0, wrongRatio = 0, acceptedFfrt = 0;
  for (int t = 0; t < trials; ++t) {
    Eigen::VectorXd truth(n), w(n);
    for (int i = 0; i < n; ++i) {
      truth[i] = std::round(50.0 * g(rng));
      w[i] = g(rng);
    }
    const LambdaResult r = lambda(truth + L * w, Q);
    ASSERT_TRUE(r.ok);
    const bool right = (r.fixed[0] - truth).cwiseAbs().maxCoeff() < 0.5;
    if (r.ratio >= 3.0 && !right) ++wrongRatio;
    if (r.ratio >= std::max(3.0, critical)) {
      ++acceptedFfrt;
      if (!right) ++wrongFfrt;
    }
  }
  // Binomial bound: 1 % of 4000 = 40 expected at most; 3 sigma above.
  EXPECT_LE(wrongFfrt, 40 + 3 * std::sqrt(40.0));
  EXPECT_GT(wrongRatio, 3 * 40);
  EXPECT_GT(acceptedFfrt, 0);
  // resolveAmbiguities applies the same critical value.
  const AmbiguityFix fx = resolveAmbiguities(L * Eigen::VectorXd::Constant(n, 0.1), Q, o);
  EXPECT_DOUBLE_EQ(fx.criticalRatio, std::max(o.ratioThreshold, fx.fullRatio >= 3.0 ? critical : 0.0));
  // A strong model: success rate above 1 - Pf, critical value 1.
  const Eigen::MatrixXd Qs = 1e-3 * (Eigen::MatrixXd::Identity(n, n) + Eigen::MatrixXd::Ones(n, n));
  const LambdaResult strong = lambda(Eigen::VectorXd::Zero(n), Qs);
  ASSERT_GT(strong.successRate, 0.999);
  EXPECT_EQ(fixedFailureRateCriticalRatio(strong.reduction.factor, o), 1.0);
}

}  // namespace
}  // namespace gvins
