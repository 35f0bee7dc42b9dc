// LAMBDA: LᵀDL factorization, decorrelating reduction and integer least-squares search.
// Written from the algorithm descriptions of de Jonge & Tiberius (1996) and Chang, Yang & Zhou
// (2005); see lambda.hpp for the references.
#include "gvins/gnss/lambda.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace gvins {

std::optional<LtdlFactor> ltdlFactorize(const Eigen::MatrixXd& Q) {
  const int n = static_cast<int>(Q.rows());
  if (n == 0 || Q.cols() != n) return std::nullopt;
  // Work on the lower triangle of a copy, eliminating from the last ambiguity backwards:
  // d[k] = A(k,k) is the variance of a_k given a_{k+1..}, L(k, j) = A(k, j) / d[k] the
  // coefficient of a_k in the conditional means of the earlier a_j, and A(0..k-1, 0..k-1) is
  // then replaced by the covariance conditioned on a_k as well.
  Eigen::MatrixXd A = Q.triangularView<Eigen::Lower>();
  LtdlFactor f;
  f.L = Eigen::MatrixXd::Identity(n, n);
  f.d.resize(n);
  const double scale = Q.diagonal().cwiseAbs().maxCoeff();
  for (int k = n - 1; k >= 0; --k) {
    const double dk = A(k, k);
    if (!(dk > 1e-14 * scale) || !std::isfinite(dk)) return std::nullopt;
    f.d[k] = dk;
    for (int j = 0; j < k; ++j) f.L(k, j) = A(k, j) / dk;
    for (int j = 0; j < k; ++j) {
      const double c = f.L(k, j) * dk;
      for (int i = j; i < k; ++i) A(i, j) -= f.L(k, i) * c;
    }
  }
  return f;
}

namespace {

/// Integer Gauss transformation on column j with row i > j: L ← L G, G = I − μ e_i e_jᵀ,
/// μ = round(L(i, j)), so that |L(i, j)| ≤ 1/2 afterwards (de Jonge & Tiberius 1996, 3.5).
/// Z ← Z G and Z⁻¹ ← G⁻¹ Z⁻¹ (kept transposed, so both are column operations).
void gaussTransform(Reduction& r, Eigen::MatrixXd& ZinvT, int i, int j) {
  Eigen::MatrixXd& L = r.factor.L;
  // Most entries are already reduced: test before rounding (nearbyint is a library call).
  if (std::abs(L(i, j)) <= 0.5) return;
  const double mu = std::nearbyint(L(i, j));
  if (mu == 0.0) return;
  const int n = static_cast<int>(L.rows());
  L.block(i, j, n - i, 1) -= mu * L.block(i, i, n - i, 1);
  r.Z.col(j) -= mu * r.Z.col(i);
  ZinvT.col(i) += mu * ZinvT.col(j);
  ++r.gaussTransformations;
}

/// Swaps ambiguities k and k+1 of the factor (de Jonge & Tiberius 1996, 3.6): with l = L(k+1, k)
/// and δ = d_k + l² d_{k+1} the new conditional variances are d'_{k+1} = δ, d'_k = d_k d_{k+1} / δ,
/// the new coupling λ = l d_{k+1} / δ, and rows k, k+1 of the earlier columns are mixed by
/// [[−l, 1], [d_k/δ, λ]].
void permute(Reduction& r, Eigen::MatrixXd& ZinvT, int k, double delta) {
  Eigen::MatrixXd& L = r.factor.L;
  Eigen::VectorXd& d = r.factor.d;
  const int n = static_cast<int>(L.rows());
  const double l = L(k + 1, k);
  const double eta = d[k] / delta;
  const double lam = d[k + 1] * l / delta;
  d[k] = eta * d[k + 1];
  d[k + 1] = delta;
  for (int j = 0; j < k; ++j) {
    const double a0 = L(k, j);
    const double a1 = L(k + 1, j);
    L(k, j) = -l * a0 + a1;
    L(k + 1, j) = eta * a0 + lam * a1;
  }
  L(k + 1, k) = lam;
  for (int i = k + 2; i < n; ++i) std::swap(L(i, k), L(i, k + 1));
  r.Z.col(k).swap(r.Z.col(k + 1));
  ZinvT.col(k).swap(ZinvT.col(k + 1));
  ++r.permutations;
}

}  // namespace

Reduction reduceLambda(const LtdlFactor& f) {
  Reduction r;
  r.factor = f;
  const int n = static_cast<int>(f.d.size());
  r.Z = Eigen::MatrixXd::Identity(n, n);
  Eigen::MatrixXd ZinvT = Eigen::MatrixXd::Identity(n, n);
  if (n >= 2) {
    // Columns are reduced from the back. A permutation at k changes d_k, d_{k+1} and columns k,
    // k+1 of L (and rows k, k+1 of the earlier columns), so the ordering of columns ≥ k+2 still
    // holds and the scan resumes at k+1 (Chang et al. 2005, sec. 3). Only columns ≤ k1 (those the
    // permutations changed) need their Gauss transformations again: column k+1 receives the
    // already reduced entries of column k. Reducing whole columns before each decision keeps
    // every entry of L bounded, and with it Z.
    int k = n - 2;
    int k1 = n - 2;
    const double tol = 1e-12;
    std::int64_t guard = 0;
    const std::int64_t maxSteps = 1000LL * n * n + 1000;  // the loop ends; this only guards NaNs
    while (k >= 0 && guard++ < maxSteps) {
      if (k <= k1) {
        for (int i = k + 1; i < n; ++i) gaussTransform(r, ZinvT, i, k);
      }
      const double l = r.factor.L(k + 1, k);
      const double delta = r.factor.d[k] + l * l * r.factor.d[k + 1];
      if (delta < (1.0 - tol) * r.factor.d[k + 1]) {
        permute(r, ZinvT, k, delta);
        k1 = k;
        k = std::min(k + 1, n - 2);
      } else {
        --k;
      }
    }
  }
  r.Zinv = ZinvT.transpose();
  return r;
}

IlsSearchResult searchIntegerLeastSquares(const LtdlFactor& f, const Eigen::VectorXd& zhat,
                                          const IlsSearchOptions& options) {
  IlsSearchResult res;
  const int n = static_cast<int>(zhat.size());
  const int want = std::max(1, options.candidates);
  if (n == 0) return res;
  const Eigen::MatrixXd& L = f.L;
  const Eigen::VectorXd& d = f.d;

  // Per level k: conditional float value zc[k] given the integers chosen at levels > k, the
  // current integer z[k], the next zig-zag step and the partial norm of the levels above.
  Eigen::VectorXd zc(n), z(n), step(n), dist(n);
  auto sgn = [](double v) { return v < 0.0 ? -1.0 : 1.0; };

  std::vector<Eigen::VectorXd> cand;
  std::vector<double> norms;
  double maxDist = std::numeric_limits<double>::infinity();

  int k = n - 1;
  dist[k] = 0.0;
  zc[k] = zhat[k];
  z[k] = std::nearbyint(zc[k]);
  double y = zc[k] - z[k];
  step[k] = sgn(y);
  for (;;) {
    if (++res.nodes > options.maxNodes) {
      res.complete = false;
      break;
    }
    const double newDist = dist[k] + y * y / d[k];
    if (newDist < maxDist) {
      if (k > 0) {
        // Descend: conditional estimate of level k-1 from the integers of levels ≥ k.
        --k;
        dist[k] = newDist;
        double s = 0.0;
        for (int j = k + 1; j < n; ++j) s += L(j, k) * (z[j] - zc[j]);
        zc[k] = zhat[k] + s;
        z[k] = std::nearbyint(zc[k]);
        y = zc[k] - z[k];
        step[k] = sgn(y);
        continue;
      }
      // A leaf: a full integer vector inside the ellipsoid.
      if (static_cast<int>(cand.size()) < want) {
        cand.push_back(z);
        norms.push_back(newDist);
        if (static_cast<int>(cand.size()) == want) maxDist = *std::max_element(norms.begin(), norms.end());
      } else {
        const auto worst = std::max_element(norms.begin(), norms.end()) - norms.begin();
        cand[worst] = z;
        norms[worst] = newDist;
        maxDist = *std::max_element(norms.begin(), norms.end());
      }
      // Next integer at level 0 (zig-zag around the conditional estimate).
      z[0] += step[0];
      y = zc[0] - z[0];
      step[0] = -step[0] - sgn(step[0]);
    } else {
      // Outside the ellipsoid: every further value at this level is too; go up one level and
      // take its next value.
      if (k == n - 1) break;
      ++k;
      z[k] += step[k];
      y = zc[k] - z[k];
      step[k] = -step[k] - sgn(step[k]);
    }
  }
  std::vector<int> order(cand.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int a, int b) { return norms[a] < norms[b]; });
  for (int i : order) {
    res.candidates.push_back(cand[i]);
    res.squaredNorms.push_back(norms[i]);
  }
  return res;
}

double bootstrapSuccessRate(const Eigen::VectorXd& conditionalVariances) {
  double p = 1.0;
  for (int i = 0; i < conditionalVariances.size(); ++i) {
    const double s = std::sqrt(std::max(conditionalVariances[i], 0.0));
    if (s == 0.0) continue;
    // 2 Φ(1 / (2σ)) − 1 = erf(1 / (2 √2 σ)).
    p *= std::erf(1.0 / (2.0 * std::sqrt(2.0) * s));
  }
  return p;
}

namespace {

/// A·B for a B with few non-zeros (the integer bases of the reduction: ~10 % on a 60-ambiguity
/// problem), column by column: O(nnz(B)·rows(A)) instead of the dense O(n³).
Eigen::MatrixXd timesSparse(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B) {
  const Eigen::Index rows = A.rows();
  Eigen::MatrixXd C = Eigen::MatrixXd::Zero(rows, B.cols());
  for (Eigen::Index j = 0; j < B.cols(); ++j) {
    double* c = C.col(j).data();
    const double* bj = B.col(j).data();
    for (Eigen::Index i = 0; i < B.rows(); ++i) {
      const double b = bj[i];
      if (b == 0.0) continue;
      const double* a = A.col(i).data();
      for (Eigen::Index k = 0; k < rows; ++k) c[k] += b * a[k];
    }
  }
  return C;
}

}  // namespace

LambdaResult lambda(const Eigen::VectorXd& afloat, const Eigen::MatrixXd& Q, const IlsSearchOptions& options,
                    const ReductionStart* start) {
  LambdaResult out;
  const int n = static_cast<int>(afloat.size());
  if (n == 0 || Q.rows() != n || Q.cols() != n || !afloat.allFinite() || !Q.allFinite()) return out;
  // ILS is invariant to integer shifts: search around the fractional parts.
  Eigen::VectorXd shift(n);
  for (int i = 0; i < n; ++i) shift[i] = std::nearbyint(afloat[i]);
  const Eigen::VectorXd frac = afloat - shift;
  // Warm start: reduce ZᵀQZ and compose the bases, Z = Z_start Z_new, Z⁻¹ = Z_new⁻¹ Z_start⁻¹
  // (Z_new = I when the start was reduced already).
  if (start && start->fits(n)) {
    Eigen::MatrixXd Qs = timesSparse(timesSparse(Q, start->Z).transpose(), start->Z);
    Qs = 0.5 * (Qs + Qs.transpose()).eval();
    if (const auto fs = ltdlFactorize(Qs)) {
      out.reduction = reduceLambda(*fs);
      if (out.reduction.permutations == 0 && out.reduction.gaussTransformations == 0) {
        out.reduction.Z = start->Z;
        out.reduction.Zinv = start->Zinv;
      } else {
        out.reduction.Z = timesSparse(start->Z, out.reduction.Z);
        out.reduction.Zinv = timesSparse(start->Zinv.transpose(), out.reduction.Zinv.transpose()).transpose();
      }
      // A start gone far from this problem (entries growing over many compositions): cold.
      if (!(out.reduction.Z.cwiseAbs().maxCoeff() < 1e6) || !(out.reduction.Zinv.cwiseAbs().maxCoeff() < 1e6)) {
        out.reduction = Reduction{};
      }
    }
  }
  if (out.reduction.factor.d.size() != n) {
    const auto f = ltdlFactorize(Q);
    if (!f) return out;
    out.reduction = reduceLambda(*f);
  }
  // Integer arithmetic in doubles is exact below 2^53; a transformation anywhere near that (never
  // seen with GNSS problems, possible with pathological input) is not trusted.
  if (!(out.reduction.Z.cwiseAbs().maxCoeff() < 1e12) || !(out.reduction.Zinv.cwiseAbs().maxCoeff() < 1e12)) return out;
  out.zhat = out.reduction.Z.transpose() * frac;
  const IlsSearchResult s = searchIntegerLeastSquares(out.reduction.factor, out.zhat, options);
  out.nodes = s.nodes;
  out.successRate = bootstrapSuccessRate(out.reduction.factor.d);
  if (s.candidates.empty() || !s.complete) return out;
  for (std::size_t i = 0; i < s.candidates.size(); ++i) {
    Eigen::VectorXd a = out.reduction.Zinv.transpose() * s.candidates[i];
    for (int j = 0; j < n; ++j) a[j] = std::nearbyint(a[j]) + shift[j];
    out.fixed.push_back(std::move(a));
    out.squaredNorms.push_back(s.squaredNorms[i]);
  }
  // Shift the zhat reported back to the caller's integers (for completeness of the record).
  out.zhat = out.reduction.Z.transpose() * afloat;
  if (out.squaredNorms.size() >= 2) {
    out.ratio = out.squaredNorms[0] > 0.0 ? out.squaredNorms[1] / out.squaredNorms[0]
                                         : std::numeric_limits<double>::infinity();
  }
  out.ok = true;
  return out;
}

}  // namespace gvins
