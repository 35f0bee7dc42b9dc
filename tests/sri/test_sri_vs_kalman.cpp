// The SRI filter against a textbook covariance Kalman filter on random linear-Gaussian problems
// with block insertion anywhere, propagation (with and without a prediction residual),
// updates, marginalization of blocks anywhere, reordering and corrections. In double the two
// must agree to 1e-9 (relative); the float SRI must agree with the double SRI to ~1e-4.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <map>
#include <random>
#include <span>
#include <vector>

#include "covariance_kf.hpp"
#include "gvins/sri/sri_filter.hpp"

namespace gvins::sri {
namespace {

using Md = Eigen::MatrixXd;
using Vd = Eigen::VectorXd;

template <typename S>
Vd sriMean(const SriFilter<S>& f) {
  Vd x(f.dim());
  const auto dx = f.solve();
  for (const BlockInfo& b : f.layout().blocks()) {
    x.segment(b.offset, b.dim) = (f.estimate(b.id).vector + dx.segment(b.offset, b.dim)).template cast<double>();
  }
  return x;
}

/// r × c matrix of independent uniform entries in [−1, 1].
Md uniformMatrix(std::mt19937& rng, int r, int c) {
  std::uniform_real_distribution<double> u(-1, 1);
  Md m(r, c);
  for (int i = 0; i < r; ++i)
    for (int j = 0; j < c; ++j) m(i, j) = u(rng);
  return m;
}

double relErr(const Md& a, const Md& b) {
  const double nb = std::max(b.norm(), 1e-300);
  return (a - b).norm() / nb;
}

class Lockstep {
 public:
  explicit Lockstep(unsigned seed, RotationScheme scheme) : rng_(seed), scheme_(scheme) {}

  double uni(double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng_); }
  int pick(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng_); }
  Md randm(int r, int c) {
    Md m(r, c);
    for (int i = 0; i < r; ++i) {
      for (int j = 0; j < c; ++j) m(i, j) = uni(-1, 1);
    }
    return m;
  }
  Md spd(int d, double smin, double smax) {
    // Random orthogonal basis with standard deviations in [smin, smax].
    Eigen::HouseholderQR<Md> qr(randm(d, d));
    const Md Q = qr.householderQ();
    Vd s(d);
    for (int i = 0; i < d; ++i) s(i) = uni(smin, smax);
    return Q * s.cwiseAbs2().asDiagonal() * Q.transpose();
  }

  int nblocks() const { return static_cast<int>(keys_.size()); }

  template <typename S>
  Placement placementFor(const std::map<std::uint64_t, BlockId>& ids, int index) const {
    if (index >= nblocks()) return Placement::back();
    return Placement::before(ids.at(keys_[static_cast<std::size_t>(index)]));
  }

  void addBlock() {
    const int d = pick(1, 5);
    const int index = pick(0, nblocks());
    const Vd x0 = 3 * randm(d, 1);
    const Md P0 = spd(d, 0.3, 3.0);
    const std::uint64_t key = next_key_++;
    kf_.addBlock(key, index, x0, P0);
    const int type = pick(0, 2);
    auto prior = [&](auto tag) {
      using S = decltype(tag);
      using Mat = Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic>;
      if (type == 0) return Prior<S>::covariance(P0.cast<S>());
      Eigen::LLT<Md> llt(P0);
      Md Sq = Md::Identity(d, d);
      llt.matrixL().solveInPlace(Sq);  // SᵀS = P0⁻¹ with S lower triangular
      if (type == 1) return Prior<S>::sqrtInformation(Mat(Sq.cast<S>()));
      // A non-square, non-triangular square root: [Q₁ S; 0] rotated.
      Eigen::HouseholderQR<Md> qr(randm(d + 2, d + 2));
      Md big = Md::Zero(d + 2, d);
      big.topRows(d) = Sq;
      return Prior<S>::sqrtInformation(Mat((Md(qr.householderQ()) * big).cast<S>()));
    };
    const Placement pd = placementFor<double>(idd_, index);
    const Placement pf = placementFor<float>(idf_, index);
    idd_[key] = sd_.addBlock(BlockSpec::vector("b", d), BlockEstimate<double>::fromVector(x0),
                             prior(double{}), pd);
    idf_[key] = sf_.addBlock(BlockSpec::vector("b", d),
                             BlockEstimate<float>::fromVector(x0.cast<float>()), prior(float{}), pf);
    keys_.insert(keys_.begin() + index, key);
  }

  void propagate() {
    const int si = pick(0, nblocks() - 1);
    const std::uint64_t src = keys_[static_cast<std::size_t>(si)];
    const int ds = kf_.blockDim(src);
    const int d = pick(0, 1) ? ds : pick(1, 5);
    Md PhiS = 0.5 * randm(d, ds);
    if (d == ds) PhiS += Md::Identity(d, d);
    // Sometimes a second source block (e.g. a parameter entering the motion model).
    std::uint64_t other = 0;
    Md PhiO;
    if (nblocks() > 1 && pick(0, 1)) {
      do {
        other = keys_[static_cast<std::size_t>(pick(0, nblocks() - 1))];
      } while (other == src);
      PhiO = 0.3 * randm(d, kf_.blockDim(other));
    }
    const Md Q = spd(d, 0.1, 1.0);
    const bool marg = pick(0, 1) == 1;
    const int where = pick(0, 3);  // 0,1: back, 2: right after src, 3: front
    int index = nblocks();
    if (where == 2) index = si + 1;
    if (where == 3) index = 0;
    const std::uint64_t key = next_key_++;
    // Covariance filter.
    Md Phi = Md::Zero(d, kf_.dim());
    Phi.middleCols(kf_.offset(src), ds) = PhiS;
    if (other) Phi.middleCols(kf_.offset(other), kf_.blockDim(other)) += PhiO;
    const Vd xnew = Phi * kf_.x;
    kf_.propagate(key, index, Phi, xnew, Q);
    if (marg) kf_.marginalize(src);
    // SRI filters: predicted estimate deliberately off by a random offset (tests e).
    const Vd offset = 0.2 * randm(d, 1);
    const bool sqrtNoise = pick(0, 1) == 1;
    auto run = [&](auto& f, auto& ids) {
      using S = typename std::decay_t<decltype(f)>::Vector::Scalar;
      using Vec = Eigen::Matrix<S, Eigen::Dynamic, 1>;
      using Mat = Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic>;
      Vec fx = PhiS.cast<S>() * f.estimate(ids.at(src)).vector;
      if (other) fx += PhiO.cast<S>() * f.estimate(ids.at(other)).vector;
      const Vec predicted = fx + offset.cast<S>();
      Propagation<S> p;
      p.addNewBlock(BlockSpec::vector("p", d), BlockEstimate<S>::fromVector(predicted),
                    index >= nblocks() ? Placement::back()
                                       : Placement::before(ids.at(keys_[static_cast<std::size_t>(index)])));
      p.setTransition(ids.at(src), PhiS.cast<S>());
      if (other) p.setTransition(ids.at(other), PhiO.cast<S>());
      if (sqrtNoise) {
        Eigen::LLT<Md> llt(Q);
        Md Sq = Md::Identity(d, d);
        llt.matrixL().solveInPlace(Sq);
        p.setNoiseSqrtInformation(Mat(Sq.cast<S>()));
      } else {
        p.setNoiseCovariance(Q.cast<S>());
      }
      p.setResidual(fx - predicted);
      if (marg) p.marginalizeAfter(ids.at(src));
      const auto newIds = f.propagate(p);
      EXPECT_EQ(newIds.size(), 1u);
      ids[key] = newIds.at(0);
      if (marg) ids.erase(src);
    };
    run(sd_, idd_);
    run(sf_, idf_);
    keys_.insert(keys_.begin() + index, key);
    if (marg) keys_.erase(std::find(keys_.begin(), keys_.end(), src));
  }

  void update() {
    const int m = pick(1, 8);
    // Touch 1–3 blocks, with a bias towards the back.
    std::vector<std::uint64_t> touched;
    const int nt = std::min(nblocks(), pick(1, 3));
    while (static_cast<int>(touched.size()) < nt) {
      const int i = pick(0, 1) ? pick(std::max(0, nblocks() - 3), nblocks() - 1) : pick(0, nblocks() - 1);
      const std::uint64_t k = keys_[static_cast<std::size_t>(i)];
      if (std::find(touched.begin(), touched.end(), k) == touched.end()) touched.push_back(k);
    }
    Md H = Md::Zero(m, kf_.dim());
    std::vector<Md> Hb;
    for (std::uint64_t k : touched) {
      Hb.push_back(randm(m, kf_.blockDim(k)));
      H.middleCols(kf_.offset(k), kf_.blockDim(k)) = Hb.back();
    }
    const bool full = pick(0, 1) == 1;
    Md Rn = full ? spd(m, 0.2, 1.0) : Md(Vd::NullaryExpr(m, [&](Eigen::Index) {
                                              return std::pow(uni(0.2, 1.0), 2);
                                            }).asDiagonal());
    const Vd z = H * kf_.x + 0.5 * randm(m, 1);
    const double kfChi2 = kf_.update(H, z, Rn);
    auto run = [&](auto& f, auto& ids, double tol) {
      using S = typename std::decay_t<decltype(f)>::Vector::Scalar;
      using Vec = Eigen::Matrix<S, Eigen::Dynamic, 1>;
      Measurement<S> meas(m);
      Vec pred = Vec::Zero(m);
      for (std::size_t b = 0; b < touched.size(); ++b) {
        const BlockId id = ids.at(touched[b]);
        meas.jacobian(id, static_cast<int>(Hb[b].cols())) = Hb[b].cast<S>();
        pred += Hb[b].cast<S>() * f.estimate(id).vector;
      }
      meas.residual() = z.cast<S>() - pred;
      if (full) {
        meas.whitenCovariance(Rn.cast<S>());
      } else {
        meas.whitenStdDevs(Rn.diagonal().cwiseSqrt().cast<S>());
      }
      const auto pre = f.chiSquare(meas);
      EXPECT_TRUE(pre.has_value());
      if (pre) {
        EXPECT_NEAR(pre->value, kfChi2, tol * std::max(1.0, kfChi2));
        EXPECT_EQ(pre->dof, m);
      }
      UpdateOptions opt;
      opt.scheme = scheme_;
      const auto res = f.update(meas, opt);
      EXPECT_NEAR(res.chi2, kfChi2, tol * std::max(1.0, kfChi2));
    };
    run(sd_, idd_, 1e-9);
    run(sf_, idf_, 1e-3);
  }

  void marginalize() {
    if (nblocks() < 3) return;
    std::vector<std::uint64_t> ks;
    const int count = pick(1, 2);
    while (static_cast<int>(ks.size()) < count) {
      const std::uint64_t k = keys_[static_cast<std::size_t>(pick(0, nblocks() - 1))];
      if (std::find(ks.begin(), ks.end(), k) == ks.end()) ks.push_back(k);
    }
    std::vector<BlockId> d;
    std::vector<BlockId> f;
    for (std::uint64_t k : ks) {
      kf_.marginalize(k);
      d.push_back(idd_.at(k));
      f.push_back(idf_.at(k));
      idd_.erase(k);
      idf_.erase(k);
      keys_.erase(std::find(keys_.begin(), keys_.end(), k));
    }
    sd_.marginalize(d);
    sf_.marginalize(f);
  }

  void reorder() {
    std::vector<std::uint64_t> ks = keys_;
    if (pick(0, 1)) {
      std::shuffle(ks.begin(), ks.end(), rng_);
    } else {  // move one block to another place
      const int from = pick(0, nblocks() - 1);
      const std::uint64_t k = ks[static_cast<std::size_t>(from)];
      ks.erase(ks.begin() + from);
      ks.insert(ks.begin() + pick(0, static_cast<int>(ks.size())), k);
    }
    kf_.reorder(ks);
    std::vector<BlockId> d;
    std::vector<BlockId> f;
    for (std::uint64_t k : ks) {
      d.push_back(idd_.at(k));
      f.push_back(idf_.at(k));
    }
    sd_.reorder(d);
    sf_.reorder(f);
    keys_ = ks;
  }

  void correct() {
    sd_.correct();
    sf_.correct();
  }

  /// Compares state, covariance and a random marginal covariance.
  void check() {
    ASSERT_EQ(sd_.dim(), kf_.dim());
    ASSERT_EQ(sf_.dim(), kf_.dim());
    for (int i = 0; i < nblocks(); ++i) {
      ASSERT_EQ(sd_.layout().at(i).id, idd_.at(keys_[static_cast<std::size_t>(i)]));
    }
    const Vd xd = sriMean(sd_);
    const Vd xf = sriMean(sf_);
    const Md Pd = sd_.fullCovariance();
    const Md Pf = sf_.fullCovariance().cast<double>();
    max_double_x_ = std::max(max_double_x_, (xd - kf_.x).norm() / std::max(1.0, kf_.x.norm()));
    max_double_p_ = std::max(max_double_p_, relErr(Pd, kf_.P));
    max_float_x_ = std::max(max_float_x_, (xf - xd).norm() / std::max(1.0, xd.norm()));
    max_float_p_ = std::max(max_float_p_, relErr(Pf, Pd));
    // Marginal covariance of a random subset (order as listed).
    if (nblocks() > 0) {
      std::vector<std::uint64_t> ks;
      const int count = std::min(nblocks(), pick(1, 3));
      while (static_cast<int>(ks.size()) < count) {
        const std::uint64_t k = keys_[static_cast<std::size_t>(pick(0, nblocks() - 1))];
        if (std::find(ks.begin(), ks.end(), k) == ks.end()) ks.push_back(k);
      }
      std::vector<BlockId> ids;
      std::vector<int> idx;
      for (std::uint64_t k : ks) {
        ids.push_back(idd_.at(k));
        for (int q = 0; q < kf_.blockDim(k); ++q) idx.push_back(kf_.offset(k) + q);
      }
      const Md Pm = sd_.covariance(ids);
      Md expect(idx.size(), idx.size());
      for (std::size_t a = 0; a < idx.size(); ++a) {
        for (std::size_t b = 0; b < idx.size(); ++b) expect(a, b) = kf_.P(idx[a], idx[b]);
      }
      max_double_p_ = std::max(max_double_p_, relErr(Pm, expect));
      // The factor form (F Fᵀ, no covariance formed) gives the same marginal.
      const Md Fm = sd_.covarianceFactor(ids);
      max_double_p_ = std::max(max_double_p_, relErr(Md(Fm * Fm.transpose()), expect));
    }
  }

  void run(int steps) {
    for (int i = 0; i < 4; ++i) addBlock();
    check();
    for (int s = 0; s < steps && !::testing::Test::HasFatalFailure(); ++s) {
      const int op = pick(0, 99);
      if (kf_.dim() > 45) {
        marginalize();
      } else if (op < 15) {
        addBlock();
      } else if (op < 40) {
        propagate();
      } else if (op < 75) {
        update();
      } else if (op < 85) {
        marginalize();
      } else if (op < 92) {
        reorder();
      } else {
        correct();
      }
      check();
    }
  }

  double max_double_x_ = 0, max_double_p_ = 0, max_float_x_ = 0, max_float_p_ = 0;

 private:
  std::mt19937 rng_;
  RotationScheme scheme_;
  test::CovarianceKf<double> kf_;
  SriFilter<double> sd_;
  SriFilter<float> sf_;
  std::vector<std::uint64_t> keys_;
  std::map<std::uint64_t, BlockId> idd_, idf_;
  std::uint64_t next_key_ = 1;
};

class SriVsKalman : public ::testing::TestWithParam<RotationScheme> {};

TEST_P(SriVsKalman, RandomLinearGaussianProblems) {
  double dx = 0, dp = 0, fx = 0, fp = 0;
  for (unsigned seed = 1; seed <= 12; ++seed) {
    Lockstep s(seed, GetParam());
    s.run(80);
    dx = std::max(dx, s.max_double_x_);
    dp = std::max(dp, s.max_double_p_);
    fx = std::max(fx, s.max_float_x_);
    fp = std::max(fp, s.max_float_p_);
  }
  RecordProperty("max_rel_err_double_state", std::to_string(dx));
  RecordProperty("max_rel_err_double_cov", std::to_string(dp));
  RecordProperty("max_rel_err_float_state", std::to_string(fx));
  RecordProperty("max_rel_err_float_cov", std::to_string(fp));
  std::printf("double vs KF: state %.2e cov %.2e | float vs double: state %.2e cov %.2e\n", dx, dp,
              fx, fp);
  EXPECT_LT(dx, 1e-9);
  EXPECT_LT(dp, 1e-9);
  EXPECT_LT(fx, 1e-4);
  EXPECT_LT(fp, 1e-4);
}

/// substitute(): the exact change of variables δx'_k = A δx_k + Σ B_j δx_j. With T the map from
/// the old error state to the new one, the covariance must become T P Tᵀ and the mean T δ̂
/// (δ̂ = R⁻¹ r, solve()), on a random factor with an update applied (r ≠ 0); the factor stays
/// upper triangular; blocks before the substituted one, or a singular A, are refused.
/// A filter of vector blocks of the given dimensions with random priors and one random 20-row
/// update applied (r ≠ 0); the ids in order.
std::vector<BlockId> randomFilter(SriFilter<double>& f, std::mt19937& rng, std::span<const int> dims) {
  auto rnd = [&](int r, int c) { return uniformMatrix(rng, r, c); };
  std::vector<BlockId> ids;
  for (int d : dims) {
    const Md L = rnd(d, d) + 3.0 * Md::Identity(d, d);
    ids.push_back(f.addBlock(BlockSpec::vector("b", d), BlockEstimate<double>::fromVector(rnd(d, 1)),
                             Prior<double>::covariance(L * L.transpose())));
  }
  Measurement<double> m(20);
  for (std::size_t k = 0; k < ids.size(); ++k) m.jacobian(ids[k], dims[k]) = rnd(20, dims[k]);
  m.residual() = rnd(20, 1);
  m.setWhitened();
  f.update(m);
  return ids;
}

TEST(SriFilterSubstitute, IsTheLinearChangeOfVariables) {
  std::mt19937 rng(11);
  auto rnd = [&](int r, int c) { return uniformMatrix(rng, r, c); };
  SriFilter<double> f;
  const int dims[] = {3, 3, 3, 6, 6, 9};
  const std::vector<BlockId> ids = randomFilter(f, rng, dims);
  const Md P0 = f.fullCovariance();
  const Vd d0 = f.solve();
  // Substitute block 1 (columns 3..5) with blocks 3 and 5 after it.
  const Md A = rnd(3, 3) + 2.0 * Md::Identity(3, 3);
  const Md B3 = rnd(3, 6), B5 = rnd(3, 9);
  const int n = f.dim();
  Md T = Md::Identity(n, n);
  T.block(3, 3, 3, 3) = A;
  T.block(3, f.layout().block(ids[3]).offset, 3, 6) = B3;
  T.block(3, f.layout().block(ids[5]).offset, 3, 9) = B5;
  const Vd x1 = rnd(3, 1);
  const std::vector<std::pair<BlockId, Md>> B = {{ids[3], B3}, {ids[5], B5}};
  f.substitute(ids[1], A, B, BlockEstimate<double>::fromVector(x1));
  EXPECT_LT(relErr(f.fullCovariance(), T * P0 * T.transpose()), 1e-10);
  EXPECT_LT((f.solve() - T * d0).norm(), 1e-10 * (1.0 + d0.norm()));
  const Md R = f.squareRootInformation();
  EXPECT_EQ(R.triangularView<Eigen::StrictlyLower>().toDenseMatrix().norm(), 0.0);
  EXPECT_EQ(f.estimate(ids[1]).vector, x1);
  // Refused: a B on an earlier block, a singular A.
  const std::vector<std::pair<BlockId, Md>> before = {{ids[0], rnd(3, 3)}};
  EXPECT_THROW(f.substitute(ids[1], A, before, BlockEstimate<double>::fromVector(x1)), std::invalid_argument);
  EXPECT_THROW(f.substitute(ids[1], Md::Zero(3, 3), B, BlockEstimate<double>::fromVector(x1)), std::invalid_argument);
}

/// substitute() on a pose block (the VIO's world re-anchoring re-expresses every pose and the
/// velocity in a new world frame whose offset is a later block): the same linear algebra on the
/// error columns, the caller's pose becomes the estimate; an estimate of another kind is refused.
TEST(SriFilterSubstitute, PoseBlockIsTheLinearChangeOfVariables) {
  std::mt19937 rng(13);
  auto rnd = [&](int r, int c) { return uniformMatrix(rng, r, c); };
  SriFilter<double> f;
  const BlockId v0 = f.addBlock(BlockSpec::vector("feature", 3), BlockEstimate<double>::fromVector(rnd(3, 1)),
                                Prior<double>::stdDev(3, 2.0));
  const Eigen::Quaterniond q0(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()));
  const BlockId pose = f.addBlock(BlockSpec::pose("clone"), BlockEstimate<double>::fromPose(q0, Eigen::Vector3d(1, 2, 3)),
                                  Prior<double>::stdDev(6, 0.5));
  const BlockId frame = f.addBlock(BlockSpec::vector("frame", 4), BlockEstimate<double>::fromVector(rnd(4, 1)),
                                   Prior<double>::stdDev(4, 3.0));
  Measurement<double> m(12);
  m.jacobian(v0, 3) = rnd(12, 3);
  m.jacobian(pose, 6) = rnd(12, 6);
  m.jacobian(frame, 4) = rnd(12, 4);
  m.residual() = rnd(12, 1);
  m.setWhitened();
  f.update(m);
  const Md P0 = f.fullCovariance();
  const Vd d0 = f.solve();
  Md A = Md::Identity(6, 6);
  A.block(3, 3, 3, 3) = Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Md Bf = rnd(6, 4);
  const int n = f.dim();
  const int o = f.layout().block(pose).offset;
  Md T = Md::Identity(n, n);
  T.block(o, o, 6, 6) = A;
  T.block(o, f.layout().block(frame).offset, 6, 4) = Bf;
  const Eigen::Quaterniond q1(Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()) * q0);
  const std::vector<std::pair<BlockId, Md>> B = {{frame, Bf}};
  f.substitute(pose, A, B, BlockEstimate<double>::fromPose(q1, Eigen::Vector3d(-2, 1, 3)));
  EXPECT_LT(relErr(f.fullCovariance(), T * P0 * T.transpose()), 1e-10);
  EXPECT_LT((f.solve() - T * d0).norm(), 1e-10 * (1.0 + d0.norm()));
  EXPECT_LT(f.estimate(pose).rotation.angularDistance(q1), 1e-12);
  EXPECT_EQ(f.estimate(pose).vector, Eigen::Vector3d(-2, 1, 3));
  EXPECT_THROW(f.substitute(pose, A, B, BlockEstimate<double>::fromVector(rnd(6, 1))), std::invalid_argument);
}

/// substitute() reads only R: the storage below the diagonal is unspecified (sri_filter.hpp) and
/// holds leftovers of earlier rotations in a running filter. Filled with garbage here, the result
/// must be the same change of variables. (Before the fix the block's own rows read it: in the VIO,
/// re-anchoring then changed the other blocks' covariance, e.g. the velocity's by 2e-6 relative.)
TEST(SriFilterSubstitute, IgnoresTheStorageBelowTheDiagonal) {
  std::mt19937 rng(12);
  auto rnd = [&](int r, int c) { return uniformMatrix(rng, r, c); };
  SriFilter<double> f;
  const int dims[] = {9, 3, 3, 6, 6};
  const std::vector<BlockId> ids = randomFilter(f, rng, dims);
  const Md P0 = f.fullCovariance();
  const Vd d0 = f.solve();
  const int n = f.dim();
  auto raw = f.rawR();
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < i; ++j) raw(i, j) = 1e3 * rnd(1, 1)(0, 0);
  }
  const int o = f.layout().block(ids[2]).offset;  // a block with rows of other blocks above it
  const Md A = rnd(3, 3) + 2.0 * Md::Identity(3, 3);
  const Md B4 = rnd(3, 6);
  Md T = Md::Identity(n, n);
  T.block(o, o, 3, 3) = A;
  T.block(o, f.layout().block(ids[4]).offset, 3, 6) = B4;
  const std::vector<std::pair<BlockId, Md>> B = {{ids[4], B4}};
  f.substitute(ids[2], A, B, BlockEstimate<double>::fromVector(rnd(3, 1)));
  EXPECT_LT(relErr(f.fullCovariance(), T * P0 * T.transpose()), 1e-10);
  EXPECT_LT((f.solve() - T * d0).norm(), 1e-10 * (1.0 + d0.norm()));
}

// update(parts): the rows of several measurements at once (SLAM re-observations of one frame),
// against the information form (Λ += Σ HᵀH, η += Σ Hᵀz, computed densely) and against update()
// of the stacked measurement (same rows, same order: the same numbers).
TEST(SriFilterUpdate, PartsEqualTheInformationSumAndTheirStack) {
  std::mt19937 rng(5);
  auto rnd = [&](int r, int c) { return uniformMatrix(rng, r, c); };
  SriFilter<double> a, b;
  std::vector<BlockId> ids;
  const int dims[] = {3, 3, 6, 6, 9};
  for (int d : dims) {
    const Vd x0 = rnd(d, 1);
    const Md L = rnd(d, d) + 3.0 * Md::Identity(d, d);
    const auto prior = Prior<double>::covariance(L * L.transpose());
    const auto est = BlockEstimate<double>::fromVector(x0);
    ids.push_back(a.addBlock(BlockSpec::vector("b", d), est, prior));
    b.addBlock(BlockSpec::vector("b", d), est, prior);
  }
  // Three parts: one on blocks 0 and 2, one on 1, 2 and 4 (compressed: discarded rows), one on 3.
  std::vector<Measurement<double>> parts(3);
  const std::vector<std::vector<int>> uses = {{0, 2}, {1, 2, 4}, {3}};
  const int rowsOf[] = {4, 30, 2};
  for (int p = 0; p < 3; ++p) {
    parts[p].reset(rowsOf[p]);
    for (int k : uses[p]) parts[p].jacobian(ids[k], dims[k]) = rnd(rowsOf[p], dims[k]);
    parts[p].residual() = rnd(rowsOf[p], 1);
    parts[p].setWhitened();
  }
  parts[1].compress();
  EXPECT_GT(parts[1].discardedRows(), 0);
  const Md Rb = a.squareRootInformation();
  const Vd rb = a.residual();
  Md Lam = Rb.transpose() * Rb;
  Vd eta = Rb.transpose() * rb;
  int rows = 0;
  for (const auto& m : parts) {
    Md H = Md::Zero(m.rows(), a.dim());
    for (int q = 0; q < m.numBlocks(); ++q) H.middleCols(a.layout().block(m.blockId(q)).offset, m.blockDim(q)) = m.jacobianAt(q);
    Lam += H.transpose() * H;
    eta += H.transpose() * m.residual();
    rows += m.rows();
  }
  const UpdateResult<double> ua = a.update(std::span<const Measurement<double>>(parts));
  const Md Ra = a.squareRootInformation();
  const Vd ra = a.residual();
  EXPECT_LT(relErr(Ra.transpose() * Ra, Lam), 1e-12);
  EXPECT_LT(relErr(Ra.transpose() * ra, eta), 1e-12);
  EXPECT_EQ(ua.dof, 4 + 30 + 2);
  // The stacked measurement, block by block.
  Measurement<double> stack(rows);
  int r0 = 0;
  for (const auto& m : parts) {
    for (int q = 0; q < m.numBlocks(); ++q) stack.jacobian(m.blockId(q), m.blockDim(q)).middleRows(r0, m.rows()) = m.jacobianAt(q);
    stack.residual().segment(r0, m.rows()) = m.residual();
    r0 += m.rows();
  }
  stack.setWhitened();
  const UpdateResult<double> us = b.update(stack);
  EXPECT_EQ((Ra - b.squareRootInformation()).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ((ra - b.residual()).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_NEAR(ua.chi2, us.chi2 + parts[1].discardedChiSquare(), 1e-12 * ua.chi2);
  EXPECT_EQ(us.dof + parts[1].discardedRows(), ua.dof);
}

INSTANTIATE_TEST_SUITE_P(Schemes, SriVsKalman,
                         ::testing::Values(RotationScheme::kAuto, RotationScheme::kBlockedHouseholder,
                                           RotationScheme::kGivens));

}  // namespace
}  // namespace gvins::sri
