// Measurement rows: whitening, null-space projection of nuisance columns (against the Schur
// complement and against "feature as a state, then marginalized"), QR compression, stacking,
// the chi-square test, uninformative priors and partially observed states, setEstimate.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/QR>

#include "gvins/sri/sri_filter.hpp"

namespace gvins::sri {
namespace {

using Md = Eigen::MatrixXd;
using Vd = Eigen::VectorXd;

Md randm(std::mt19937& rng, int r, int c) {
  std::normal_distribution<double> g(0.0, 1.0);
  Md m(r, c);
  for (int i = 0; i < r; ++i) {
    for (int j = 0; j < c; ++j) m(i, j) = g(rng);
  }
  return m;
}

// A 3-vector block "x" at zero with the square-root information prior `sqrtInfo` (rows × 3).
template <typename S>
BlockId addVector3(SriFilter<S>& f, const Md& sqrtInfo) {
  return f.addBlock(BlockSpec::vector("x", 3), BlockEstimate<S>::zero(BlockKind::kVector, 3),
                    Prior<S>::sqrtInformation(sqrtInfo.cast<S>()));
}

TEST(Measurement, WhiteningVariants) {
  std::mt19937 rng(1);
  const int m = 4;
  const Md H = randm(rng, m, 3);
  const Vd r = randm(rng, m, 1);
  const Md A = randm(rng, m, m);
  const Md Sigma = A * A.transpose() + 0.5 * Md::Identity(m, m);
  const Md Info = Sigma.inverse();
  const BlockId id{7};
  Measurement<double> z(m);
  EXPECT_FALSE(z.isWhitened());
  z.jacobian(id, 3) = H;
  z.residual() = r;
  z.whitenCovariance(Sigma);
  EXPECT_TRUE(z.isWhitened());
  const Md Hw = z.jacobianAt(0);
  EXPECT_LT((Hw.transpose() * Hw - H.transpose() * Info * H).norm(), 1e-10);
  EXPECT_LT((Hw.transpose() * z.residual() - H.transpose() * Info * r).norm(), 1e-10);
  EXPECT_NEAR(z.residual().squaredNorm(), r.dot(Info * r), 1e-10);
  // Square-root information S with SᵀS = Σ⁻¹.
  Measurement<double> z2(m);
  z2.jacobian(id, 3) = H;
  z2.residual() = r;
  Eigen::LLT<Md> llt(Info);
  z2.whitenSqrtInformation(llt.matrixU());
  EXPECT_LT((Md(z2.jacobianAt(0)).transpose() * z2.jacobianAt(0) - Hw.transpose() * Hw).norm(), 1e-10);
  // Standard deviations.
  Measurement<double> z3(m);
  z3.jacobian(id, 3) = H;
  z3.whitenStdDevs(Vd::Constant(m, 2.0));
  EXPECT_LT((Md(z3.jacobianAt(0)) - H / 2).norm(), 1e-15);
  EXPECT_THROW(z3.whitenStdDevs(Vd::Constant(m, -1.0)), std::invalid_argument);
  EXPECT_THROW(z3.whitenCovariance(-Sigma), std::invalid_argument);
  EXPECT_THROW(z3.jacobian(id, 2), std::invalid_argument);  // dimension changed
}

TEST(Measurement, NullSpaceProjectionEqualsSchurComplement) {
  std::mt19937 rng(2);
  const int m = 10;
  const Md Hc1 = randm(rng, m, 6);
  const Md Hc2 = randm(rng, m, 6);
  const Md Hf = randm(rng, m, 3);
  const Vd r = randm(rng, m, 1);
  Measurement<double> z(m);
  z.jacobian(BlockId{1}, 6) = Hc1;
  z.jacobian(BlockId{2}, 6) = Hc2;
  z.nuisance(3) = Hf;
  z.residual() = r;
  EXPECT_THROW(z.projectNuisance(), std::logic_error);  // not whitened yet
  z.setWhitened();
  EXPECT_EQ(z.projectNuisance(), 3);
  EXPECT_EQ(z.rows(), m - 3);
  EXPECT_EQ(z.nuisanceDim(), 0);
  Md Hx(m, 12);
  Hx << Hc1, Hc2;
  // I − H_f (H_fᵀH_f)⁻¹ H_fᵀ: the orthogonal projector onto the left null space of H_f.
  const Md Pn = Md::Identity(m, m) - Hf * (Hf.transpose() * Hf).inverse() * Hf.transpose();
  const Md Hp = z.stackedJacobian();
  EXPECT_LT((Hp.transpose() * Hp - Hx.transpose() * Pn * Hx).norm(), 1e-10);
  EXPECT_LT((Hp.transpose() * z.residual() - Hx.transpose() * Pn * r).norm(), 1e-10);
  EXPECT_NEAR(z.residual().squaredNorm(), r.dot(Pn * r), 1e-10);
}

// projectNuisance(&top): the removed rows are Q₁ᵀ[N H r] with an upper-triangular nuisance
// factor, and [top; projected] is an orthogonal transform of the original rows (same Gram matrix
// of [N H r]). Rows as in MSCKF: two per observation on its own clone block (a staircase, which
// the rotations skip up to each row's first non-zero column) and a dense calibration block.
TEST(Measurement, NuisanceRowsCompleteTheProjection) {
  std::mt19937 rng(9);
  const int clones = 6, m = 2 * clones;
  Measurement<double> z(m);
  Md A = Md::Zero(m, 3 + 6 * clones + 6 + 1);  // [N | clones | calibration | r], the original
  for (int k = 0; k < clones; ++k) {
    const Md Hk = randm(rng, 2, 6);
    z.jacobian(BlockId{static_cast<std::uint64_t>(k + 1)}, 6).middleRows(2 * k, 2) = Hk;
    A.block(2 * k, 3 + 6 * k, 2, 6) = Hk;
  }
  const Md He = randm(rng, m, 6), Hf = randm(rng, m, 3);
  const Vd r = randm(rng, m, 1);
  z.jacobian(BlockId{100}, 6) = He;
  z.nuisance(3) = Hf;
  z.residual() = r;
  A.middleCols(3 + 6 * clones, 6) = He;
  A.leftCols(3) = Hf;
  A.rightCols(1) = r;
  z.setWhitened();
  Measurement<double> top;
  EXPECT_EQ(z.projectNuisance(&top), 3);
  ASSERT_EQ(top.rows(), 3);
  ASSERT_EQ(top.nuisanceDim(), 3);
  ASSERT_EQ(top.numBlocks(), z.numBlocks());
  const Md Rf = top.nuisanceJacobian();
  EXPECT_EQ(Md(Rf.triangularView<Eigen::StrictlyLower>()).norm(), 0.0);
  Md B = Md::Zero(m, A.cols());  // [top; projected] in the same columns
  B.topLeftCorner(3, 3) = Rf;
  B.block(0, 3, 3, 6 * clones + 6) = top.stackedJacobian();
  B.block(3, 3, m - 3, 6 * clones + 6) = z.stackedJacobian();
  B.block(0, A.cols() - 1, 3, 1) = top.residual();
  B.block(3, A.cols() - 1, m - 3, 1) = z.residual();
  EXPECT_LT((B.transpose() * B - A.transpose() * A).norm(), 1e-10 * (A.transpose() * A).norm());
  // The projected rows carry the Schur complement, as without the output.
  const Md Pn = Md::Identity(m, m) - Hf * (Hf.transpose() * Hf).inverse() * Hf.transpose();
  const Md Hx = A.middleCols(3, 6 * clones + 6);
  EXPECT_LT((z.stackedJacobian().transpose() * z.stackedJacobian() - Hx.transpose() * Pn * Hx).norm(), 1e-10);
  // Fewer rows than nuisance columns: everything goes to `top`.
  Measurement<double> few(2);
  few.jacobian(BlockId{1}, 6) = randm(rng, 2, 6);
  few.nuisance(3) = randm(rng, 2, 3);
  few.setWhitened();
  EXPECT_EQ(few.projectNuisance(&top), 2);
  EXPECT_EQ(few.rows(), 0);
  EXPECT_EQ(top.rows(), 2);
  EXPECT_THROW(few.projectNuisance(&few), std::invalid_argument);
}

// The Householder projection (dense rows, e.g. GNSS rows with the 9-dim IMU integration noise as
// nuisance: [J L_k; I] with prior rows I) keeps the same information as the Givens one: [top;
// projected] has the Gram matrix of the original [N H r], the nuisance factor is upper
// triangular, and the projected rows update a filter exactly as the Givens rows do.
TEST(Measurement, HouseholderProjectionMatchesGivens) {
  std::mt19937 rng(21);
  const int nk = 30, q = 9, m = nk + q, p1 = 15, p2 = 6;
  Md N = Md::Zero(m, q);
  N.topRows(nk) = randm(rng, nk, q);
  N.bottomRows(q).setIdentity();
  Md H1 = Md::Zero(m, p1), H2 = Md::Zero(m, p2);
  H1.topRows(nk) = randm(rng, nk, p1);
  H2.topRows(nk) = randm(rng, nk, p2);
  Vd r = Vd::Zero(m);
  r.head(nk) = randm(rng, nk, 1);
  Md A(m, q + p1 + p2 + 1);
  A << N, H1, H2, r;
  // Two filters with the same prior on blocks a (p1) and b (p2).
  auto filter = [&](SriFilter<double>& f) {
    std::mt19937 r2(5);
    std::vector<BlockId> ids;
    ids.push_back(f.addBlock(BlockSpec::vector("a", p1), BlockEstimate<double>::zero(BlockKind::kVector, p1),
                             Prior<double>::sqrtInformation(randm(r2, p1 + 2, p1))));
    ids.push_back(f.addBlock(BlockSpec::vector("b", p2), BlockEstimate<double>::zero(BlockKind::kVector, p2),
                             Prior<double>::sqrtInformation(randm(r2, p2 + 2, p2))));
    return ids;
  };
  SriFilter<double> fg, fh;
  const std::vector<BlockId> ig = filter(fg), ih = filter(fh);
  auto make = [&](Measurement<double>& z, const std::vector<BlockId>& ids) {
    z.reset(m);
    z.jacobian(ids[0], p1) = H1;
    z.jacobian(ids[1], p2) = H2;
    z.nuisance(q) = N;
    z.residual() = r;
    z.setWhitened();
  };
  Measurement<double> zg, zh, top;
  make(zg, ig);
  make(zh, ih);
  EXPECT_EQ(zg.projectNuisance(), q);
  EXPECT_EQ(zh.projectNuisance(&top, Measurement<double>::NuisanceProjection::kHouseholder), q);
  ASSERT_EQ(zh.rows(), nk);
  ASSERT_EQ(top.rows(), q);
  const Md Rf = top.nuisanceJacobian();
  EXPECT_EQ(Md(Rf.triangularView<Eigen::StrictlyLower>()).norm(), 0.0);
  Md B = Md::Zero(m, A.cols());
  B.topLeftCorner(q, q) = Rf;
  B.block(0, q, q, p1 + p2) = top.stackedJacobian();
  B.block(q, q, nk, p1 + p2) = zh.stackedJacobian();
  B.block(0, A.cols() - 1, q, 1) = top.residual();
  B.block(q, A.cols() - 1, nk, 1) = zh.residual();
  EXPECT_LT((B.transpose() * B - A.transpose() * A).norm(), 1e-12 * (A.transpose() * A).norm());
  // Both projections: [H r] with the same Gram matrix (the Schur complement of N).
  Md Gg(nk, p1 + p2 + 1), Gh(nk, p1 + p2 + 1);
  Gg << zg.stackedJacobian(), zg.residual();
  Gh << zh.stackedJacobian(), zh.residual();
  EXPECT_LT((Gg.transpose() * Gg - Gh.transpose() * Gh).norm(), 1e-12 * (Gg.transpose() * Gg).norm());
  // And the same filter update.
  const auto ug = fg.update(zg);
  const auto uh = fh.update(zh);
  EXPECT_NEAR(ug.chi2, uh.chi2, 1e-10 * ug.chi2);
  EXPECT_LT((fg.solve() - fh.solve()).norm(), 1e-10 * fg.solve().norm());
  EXPECT_LT((fg.fullCovariance() - fh.fullCovariance()).norm(), 1e-10 * fg.fullCovariance().norm());
}

// MSCKF equivalence: updating with the projected rows equals adding the feature as a state with
// no prior information, updating with the full rows and marginalizing the feature.
TEST(Measurement, ProjectionEqualsFeatureStateMarginalized) {
  std::mt19937 rng(3);
  const int m = 8;
  auto makeFilter = [&](SriFilter<double>& f, std::vector<BlockId>& ids) {
    std::mt19937 r2(9);
    for (int i = 0; i < 3; ++i) {
      ids.push_back(f.addBlock(BlockSpec::pose("c"), BlockEstimate<double>::zero(BlockKind::kPose, 6),
                               Prior<double>::sqrtInformation(randm(r2, 9, 6))));
    }
  };
  SriFilter<double> a;
  SriFilter<double> b;
  std::vector<BlockId> ia;
  std::vector<BlockId> ib;
  makeFilter(a, ia);
  makeFilter(b, ib);
  std::vector<Md> Hc;
  for (int i = 0; i < 3; ++i) Hc.push_back(randm(rng, m, 6));
  const Md Hf = randm(rng, m, 3);
  const Vd r = randm(rng, m, 1);
  Measurement<double> za(m);
  for (int i = 0; i < 3; ++i) za.jacobian(ia[static_cast<std::size_t>(i)], 6) = Hc[static_cast<std::size_t>(i)];
  za.nuisance(3) = Hf;
  za.residual() = r;
  za.whitenStdDev(0.7);
  EXPECT_THROW(a.update(za), std::logic_error);  // nuisance still there
  za.projectNuisance();
  const auto ra = a.update(za);
  const BlockId feat = b.addBlock(BlockSpec::vector("f", 3), BlockEstimate<double>::zero(BlockKind::kVector, 3),
                                  Prior<double>::uninformative(), Placement::front());
  Measurement<double> zb(m);
  for (int i = 0; i < 3; ++i) zb.jacobian(ib[static_cast<std::size_t>(i)], 6) = Hc[static_cast<std::size_t>(i)];
  zb.jacobian(feat, 3) = Hf;
  zb.residual() = r;
  zb.whitenStdDev(0.7);
  const auto rb = b.update(zb);
  b.marginalize(feat);
  EXPECT_NEAR(ra.chi2, rb.chi2, 1e-10);
  EXPECT_LT((a.fullCovariance() - b.fullCovariance()).norm(), 1e-10 * b.fullCovariance().norm());
  EXPECT_LT((a.solve() - b.solve()).norm(), 1e-10);
}

TEST(Measurement, CompressionKeepsInformationAndChiSquare) {
  std::mt19937 rng(4);
  const int m = 40;
  SriFilter<double> f1;
  SriFilter<double> f2;
  std::vector<BlockId> ids1;
  std::vector<BlockId> ids2;
  for (int i = 0; i < 3; ++i) {
    ids1.push_back(f1.addBlock(BlockSpec::vector("x", 4), BlockEstimate<double>::zero(BlockKind::kVector, 4),
                               Prior<double>::stdDev(4, 2.0)));
    ids2.push_back(f2.addBlock(BlockSpec::vector("x", 4), BlockEstimate<double>::zero(BlockKind::kVector, 4),
                               Prior<double>::stdDev(4, 2.0)));
  }
  // A tall stack built from two measurements (stack matches blocks by id), on 2 of 3 blocks.
  const Md H0 = randm(rng, m / 2, 4), H1 = randm(rng, m / 2, 4), H2 = randm(rng, m / 2, 4);
  const Vd r0 = randm(rng, m / 2, 1), r1 = randm(rng, m / 2, 1);
  auto build = [&](const std::vector<BlockId>& ids) {
    Measurement<double> a(m / 2);
    a.jacobian(ids[1], 4) = H0;
    a.jacobian(ids[2], 4) = H1;
    a.residual() = r0;
    a.whitenStdDev(0.5);
    Measurement<double> b(m / 2);
    b.jacobian(ids[2], 4) = H2;  // other order, one block only
    b.residual() = r1;
    b.whitenStdDev(0.5);
    a.stack(b);
    return a;
  };
  Measurement<double> full = build(ids1);
  Measurement<double> small = build(ids2);
  EXPECT_EQ(full.rows(), m);
  EXPECT_EQ(small.compress(), m - 8);
  EXPECT_EQ(small.rows(), 8);
  EXPECT_EQ(small.discardedRows(), m - 8);
  const Md Hf = full.stackedJacobian();
  const Md Hs = small.stackedJacobian();
  EXPECT_LT((Hs.transpose() * Hs - Hf.transpose() * Hf).norm(), 1e-10);
  EXPECT_LT((Hs.transpose() * small.residual() - Hf.transpose() * full.residual()).norm(), 1e-10);
  EXPECT_NEAR(small.residual().squaredNorm() + small.discardedChiSquare(), full.residual().squaredNorm(), 1e-10);
  const auto pre = f2.chiSquare(small);
  ASSERT_TRUE(pre.has_value());
  const auto c1 = f1.update(full);
  const auto c2 = f2.update(small);
  EXPECT_NEAR(c1.chi2, c2.chi2, 1e-9);
  EXPECT_NEAR(pre->value, c1.chi2, 1e-9);
  EXPECT_EQ(c1.dof, m);
  EXPECT_EQ(c2.dof, m);
  EXPECT_EQ(pre->dof, m);
  EXPECT_LT((f1.fullCovariance() - f2.fullCovariance()).norm(), 1e-12);
  EXPECT_LT((f1.solve() - f2.solve()).norm(), 1e-12);
}

TEST(Measurement, ChiSquareAgainstCovarianceFormula) {
  std::mt19937 rng(5);
  SriFilter<double> f;
  std::vector<BlockId> ids;
  for (int i = 0; i < 4; ++i) {
    ids.push_back(addVector3(f, randm(rng, 5, 3)));
  }
  // A prior offset (r ≠ 0): the predicted residual must account for it.
  f.rawResidual() = randm(rng, 12, 1);
  const Md P = f.fullCovariance();
  const Vd mean = f.solve();
  Measurement<double> z(5);
  const Md H1 = randm(rng, 5, 3), H3 = randm(rng, 5, 3);
  z.jacobian(ids[1], 3) = H1;
  z.jacobian(ids[3], 3) = H3;
  z.residual() = randm(rng, 5, 1);
  z.whitenStdDev(0.3);
  Md H = Md::Zero(5, 12);
  H.middleCols(3, 3) = H1 / 0.3;
  H.middleCols(9, 3) = H3 / 0.3;
  const Vd nu = z.residual() - H * mean;
  const Md S = H * P * H.transpose() + Md::Identity(5, 5);
  const double expect = nu.dot(S.ldlt().solve(nu));
  const auto c = f.chiSquare(z);
  ASSERT_TRUE(c.has_value());
  EXPECT_NEAR(c->value, expect, 1e-10 * expect);
  EXPECT_EQ(c->dof, 5);
  const auto u = f.update(z);
  EXPECT_NEAR(u.chi2, expect, 1e-10 * expect);
  // Rows that touch nothing: χ² is ‖r‖² and R does not change.
  const Md R0 = f.squareRootInformation();
  Measurement<double> none(2);
  none.jacobian(ids[0], 3).setZero();
  none.residual() = Vd::Constant(2, 3.0);
  none.setWhitened();
  EXPECT_NEAR(f.chiSquare(none)->value, 18.0, 1e-12);
  EXPECT_NEAR(f.update(none).chi2, 18.0, 1e-12);
  EXPECT_EQ(f.squareRootInformation(), R0);
}

// More rows than touched columns (a GNSS epoch: many satellites on a few trailing blocks) takes
// the k-dimensional form of the χ²; same value as the covariance formula, double and float.
TEST(Measurement, ChiSquareManyRowsOnFewColumns) {
  std::mt19937 rng(11);
  SriFilter<double> fd;
  SriFilter<float> ff;
  std::vector<BlockId> idd, idf;
  for (int i = 0; i < 4; ++i) {
    const Md L = randm(rng, 5, 3);
    idd.push_back(addVector3(fd, L));
    idf.push_back(addVector3(ff, L));
  }
  const Vd r0 = randm(rng, 12, 1);
  fd.rawResidual() = r0;
  ff.rawResidual() = r0.cast<float>();
  const Md P = fd.fullCovariance();
  const Vd mean = fd.solve();
  constexpr int m = 40;  // rows on the 6 columns of the last two blocks
  const Md H2 = randm(rng, m, 3), H3 = randm(rng, m, 3);
  const Vd res = randm(rng, m, 1);
  Md H = Md::Zero(m, 12);
  H.middleCols(6, 3) = H2 / 0.3;
  H.middleCols(9, 3) = H3 / 0.3;
  const Vd nu = res / 0.3 - H * mean;
  const Md S = H * P * H.transpose() + Md::Identity(m, m);
  const double expect = nu.dot(S.ldlt().solve(nu));
  Measurement<double> zd(m);
  zd.jacobian(idd[2], 3) = H2;
  zd.jacobian(idd[3], 3) = H3;
  zd.residual() = res;
  zd.whitenStdDev(0.3);
  const auto cd = fd.chiSquare(zd);
  ASSERT_TRUE(cd.has_value());
  EXPECT_NEAR(cd->value, expect, 1e-10 * expect);
  EXPECT_EQ(cd->dof, m);
  Measurement<float> zf(m);
  zf.jacobian(idf[2], 3) = H2.cast<float>();
  zf.jacobian(idf[3], 3) = H3.cast<float>();
  zf.residual() = res.cast<float>();
  zf.whitenStdDev(0.3f);
  const auto cf = ff.chiSquare(zf);
  ASSERT_TRUE(cf.has_value());
  EXPECT_NEAR(cf->value, expect, 1e-4 * expect);
  // The update's post-fit ‖e‖² is the same χ².
  EXPECT_NEAR(fd.update(zd).chi2, expect, 1e-10 * expect);
}

// UpdateOptions::max_chi2: rows whose χ² exceeds it leave [R r] exactly as it was; below it the
// update is the ungated one.
TEST(Measurement, GatedUpdateRestoresOnReject) {
  std::mt19937 rng(12);
  SriFilter<double> f, g;
  std::vector<BlockId> ids, idg;
  for (int i = 0; i < 3; ++i) {
    const Md L = randm(rng, 4, 3);
    ids.push_back(addVector3(f, L));
    idg.push_back(addVector3(g, L));
  }
  auto rowsOn = [&](const std::vector<BlockId>& b, double scale) {
    Measurement<double> z(10);
    std::mt19937 r2(3);
    z.jacobian(b[1], 3) = randm(r2, 10, 3);
    z.jacobian(b[2], 3) = randm(r2, 10, 3);
    z.residual() = scale * randm(r2, 10, 1);
    z.whitenStdDev(0.5);
    return z;
  };
  const Md R0 = f.squareRootInformation();
  const Vd r0 = f.rawResidual();
  const Measurement<double> big = rowsOn(ids, 100.0);
  const double chi2 = f.chiSquare(big)->value;
  UpdateOptions opt;
  opt.max_chi2 = 0.5 * chi2;
  const auto rej = f.update(big, opt);
  EXPECT_FALSE(rej.applied);
  EXPECT_NEAR(rej.chi2, chi2, 1e-9 * chi2);
  EXPECT_EQ(f.squareRootInformation(), R0);
  EXPECT_EQ(f.rawResidual(), r0);
  opt.max_chi2 = 2.0 * chi2;
  const auto acc = f.update(big, opt);
  EXPECT_TRUE(acc.applied);
  g.update(rowsOn(idg, 100.0));
  EXPECT_EQ(f.squareRootInformation(), g.squareRootInformation());
  EXPECT_EQ(f.rawResidual(), g.rawResidual());
}

TEST(Measurement, ErrorsAreReported) {
  SriFilter<double> f;
  const BlockId x = f.addBlock(BlockSpec::vector("x", 2), BlockEstimate<double>::zero(BlockKind::kVector, 2),
                               Prior<double>::stdDev(2, 1.0));
  Measurement<double> z(1);
  z.jacobian(x, 2).setOnes();
  EXPECT_THROW(f.update(z), std::logic_error);  // not whitened
  z.setWhitened();
  Measurement<double> unknown(1);
  unknown.jacobian(BlockId{12345}, 2).setOnes();
  unknown.setWhitened();
  EXPECT_THROW(f.update(unknown), std::out_of_range);
  Measurement<double> wrongDim(1);
  wrongDim.jacobian(x, 3).setOnes();
  wrongDim.setWhitened();
  EXPECT_THROW(f.update(wrongDim), std::invalid_argument);
  EXPECT_THROW(f.addBlock(BlockSpec::vector("y", 2), BlockEstimate<double>::zero(BlockKind::kVector, 3),
                          Prior<double>::stdDev(2, 1.0)),
               std::invalid_argument);
  EXPECT_THROW(f.addBlock(BlockSpec::vector("y", 2), BlockEstimate<double>::zero(BlockKind::kVector, 2),
                          Prior<double>::covariance(-Md::Identity(2, 2))),
               std::invalid_argument);
  EXPECT_THROW(f.addBlock(BlockSpec::vector("y", 2), BlockEstimate<double>::zero(BlockKind::kVector, 2),
                          Prior<double>::stdDev(2, 1.0), Placement::after(BlockId{999})),
               std::out_of_range);
  EXPECT_EQ(f.dim(), 2);  // failed additions left nothing behind
}

// addBlocks declares columns at once: later jacobian() calls find them, existing blocks are kept,
// and a dimension that differs is an error; the stacked Jacobian equals the one built block by block.
TEST(Measurement, AddBlocksDeclaresColumnsOnce) {
  const BlockId a{1}, b{2}, c{3};
  Measurement<double> z(3);
  z.jacobian(a, 2).setConstant(1.0);
  const BlockId ids[] = {b, a, c};
  const int dims[] = {3, 2, 1};
  z.addBlocks(ids, dims);
  ASSERT_EQ(z.numBlocks(), 3);
  EXPECT_EQ(z.blockId(0), a);
  EXPECT_EQ(z.blockId(1), b);
  EXPECT_EQ(z.blockId(2), c);
  EXPECT_EQ(z.stackedJacobian().cols(), 6);
  EXPECT_EQ(z.jacobianAt(0).sum(), 6.0);  // kept
  EXPECT_EQ(z.jacobianAt(1).norm(), 0.0);  // new columns are zero
  z.jacobian(b, 3)(1, 2) = 5.0;
  z.jacobian(c, 1)(2, 0) = 7.0;
  Measurement<double> w(3);
  w.jacobian(a, 2).setConstant(1.0);
  w.jacobian(b, 3)(1, 2) = 5.0;
  w.jacobian(c, 1)(2, 0) = 7.0;
  EXPECT_EQ((z.stackedJacobian() - w.stackedJacobian()).norm(), 0.0);
  const int bad[] = {3, 3, 1};  // a has 2 columns
  EXPECT_THROW(z.addBlocks(ids, bad), std::invalid_argument);
  const int shortDims[] = {3, 2};
  EXPECT_THROW(z.addBlocks(ids, shortDims), std::invalid_argument);
}

// rotateRows: the Givens rotation of two rows of [H nuisance r], against the explicit product.
TEST(Measurement, RotateRowsAppliesTheGivensRotation) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  Measurement<double> z(4);
  const BlockId a{1}, b{2};
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 3; ++j) z.jacobian(a, 3)(i, j) = u(rng);
    z.jacobian(b, 1)(i, 0) = u(rng);
    z.nuisance(2)(i, 0) = u(rng);
    z.nuisance(2)(i, 1) = u(rng);
    z.residual()(i) = u(rng);
  }
  Md M(4, 7);
  M << z.stackedJacobian(), Md(z.nuisance(2)), z.residual();
  const double th = 0.7, c = std::cos(th), s = std::sin(th);
  Md G = Md::Identity(4, 4);
  G(1, 1) = c, G(1, 3) = s, G(3, 1) = -s, G(3, 3) = c;
  const Md expect = G * M;
  z.rotateRows(1, 3, c, s);
  Md got(4, 7);
  got << z.stackedJacobian(), Md(z.nuisance(2)), z.residual();
  EXPECT_LT((got - expect).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_NEAR(z.jacobianAt(0)(1, 0), expect(1, 0), 1e-15);  // mutable and const views agree
  EXPECT_THROW(z.rotateRows(1, 1, c, s), std::invalid_argument);
  EXPECT_THROW(z.rotateRows(0, 4, c, s), std::invalid_argument);
}

// Uninformative priors: the update is then ordinary weighted least squares; unobserved
// components are reported, not invented.
TEST(Measurement, UninformativePriorGivesLeastSquares) {
  std::mt19937 rng(6);
  SriFilter<double> f;
  const BlockId a = f.addBlock(BlockSpec::vector("a", 3), BlockEstimate<double>::fromVector(Eigen::Vector3d(1, 1, 1)),
                               Prior<double>::uninformative());
  const BlockId b = f.addBlock(BlockSpec::vector("b", 2), BlockEstimate<double>::zero(BlockKind::kVector, 2),
                               Prior<double>::uninformative());
  // Before any measurement: nothing is known.
  Measurement<double> probe(1);
  probe.jacobian(a, 3).setOnes();
  probe.setWhitened();
  EXPECT_FALSE(f.chiSquare(probe).has_value());
  EXPECT_FALSE(f.informed(std::vector<BlockId>{a}));
  EXPECT_THROW(f.covariance(std::vector<BlockId>{a}), std::domain_error);
  // Observe only a (6 rows): b stays unobserved.
  const Md H = randm(rng, 6, 3);
  const Vd y = randm(rng, 6, 1);
  Measurement<double> z(6);
  z.jacobian(a, 3) = H;
  z.residual() = y - H * Eigen::Vector3d(1, 1, 1);
  z.whitenStdDev(0.2);
  f.update(z);
  // informed() answers exactly where covariance() would throw.
  EXPECT_FALSE(f.informed(std::vector<BlockId>{b}));
  EXPECT_FALSE(f.informed(std::vector<BlockId>{a, b}));
  EXPECT_TRUE(f.informed(std::vector<BlockId>{a}));
  EXPECT_THROW(f.covariance(std::vector<BlockId>{b}), std::domain_error);
  f.correct();
  const Vd ls = H.colPivHouseholderQr().solve(y);
  EXPECT_LT((f.estimate(a).vector - ls).norm(), 1e-12);
  EXPECT_EQ(f.estimate(b).vector, Eigen::Vector2d::Zero());  // left alone
  // Marginal covariance of a: (HᵀH/σ²)⁻¹, although b (behind it) has no information at all.
  const Md Pa = (H.transpose() * H / 0.04).inverse();
  EXPECT_LT((f.covariance(std::vector<BlockId>{a}) - Pa).norm(), 1e-12);
  const Md Fa = f.covarianceFactor(std::vector<BlockId>{a});
  EXPECT_EQ(Fa.cols(), 3);  // b's uninformed columns are left out
  EXPECT_LT((Fa * Fa.transpose() - Pa).norm(), 1e-12);
  EXPECT_THROW(f.covarianceFactor(std::vector<BlockId>{b}), std::domain_error);
  // Gating a new measurement of a works; one that involves b cannot be gated yet.
  Measurement<double> za(1);
  za.jacobian(a, 3) = Eigen::RowVector3d(1, -1, 0.5);
  za.residual()(0) = 0.3;
  za.setWhitened();
  const auto ca = f.chiSquare(za);
  ASSERT_TRUE(ca.has_value());
  const Eigen::RowVector3d h(1, -1, 0.5);
  EXPECT_NEAR(ca->value, 0.09 / (1 + h * Pa * h.transpose()), 1e-12);
  Measurement<double> zb(1);
  zb.jacobian(b, 2) = Eigen::RowVector2d(1, 0);
  zb.setWhitened();
  EXPECT_FALSE(f.chiSquare(zb).has_value());
  // Once b is tied to a by a row that leaves part of b undetermined, R has a coupled zero pivot
  // and the covariance is refused rather than computed wrongly.
  Measurement<double> tie(1);
  tie.jacobian(a, 3) = Eigen::RowVector3d(1, 0, 0);
  tie.jacobian(b, 2) = Eigen::RowVector2d(1, 1);
  tie.setWhitened();
  f.update(tie);
  EXPECT_FALSE(f.informed(std::vector<BlockId>{a}));
  EXPECT_THROW(f.covariance(std::vector<BlockId>{a}), std::domain_error);
}

TEST(Measurement, SetEstimateKeepsTheDistribution) {
  std::mt19937 rng(7);
  SriFilter<double> f;
  const BlockId p = f.addBlock(BlockSpec::pose("T"), BlockEstimate<double>::zero(BlockKind::kPose, 6),
                               Prior<double>::sqrtInformation(randm(rng, 8, 6)));
  const BlockId v = f.addBlock(BlockSpec::vector("v", 3), BlockEstimate<double>::fromVector(Eigen::Vector3d(1, 2, 3)),
                               Prior<double>::sqrtInformation(randm(rng, 4, 3)));
  Measurement<double> z(4);
  z.jacobian(p, 6) = randm(rng, 4, 6);
  z.jacobian(v, 3) = randm(rng, 4, 3);
  z.residual() = randm(rng, 4, 1);
  z.setWhitened();
  f.update(z);
  const Vd mean = f.solve();
  const Vd vMean = f.estimate(v).vector + mean.tail(3);
  const Md P = f.fullCovariance();
  f.setEstimate(v, BlockEstimate<double>::fromVector(Eigen::Vector3d(-4, 0.5, 9)));
  EXPECT_LT((f.estimate(v).vector + f.solve().tail(3) - vMean).norm(), 1e-12);
  EXPECT_LT((f.solve().head(6) - mean.head(6)).norm(), 1e-12);
  EXPECT_LT((f.fullCovariance() - P).norm(), 1e-12);
}

}  // namespace
}  // namespace gvins::sri
