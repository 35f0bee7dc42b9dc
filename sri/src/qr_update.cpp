#include "gvins/sri/qr_update.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace gvins::sri {

namespace {

/// Householder reflector H = I − τ v vᵀ, v = [1; x̃], with H [α; x] = [β; 0]
/// (the convention of LAPACK's xLARFG). On return alpha = β and x = x̃. Scaled to avoid
/// overflow/underflow of the squared norm.
template <typename Scalar, typename Vec>
Scalar makeReflector(Scalar& alpha, Vec&& x) {
  if (x.size() == 0) return Scalar(0);
  const Scalar xmax = x.cwiseAbs().maxCoeff();
  if (xmax == Scalar(0)) return Scalar(0);
  const Scalar scale = std::max(xmax, std::abs(alpha));
  const Scalar inv = Scalar(1) / scale;
  const Scalar a = alpha * inv;
  const Scalar norm = scale * std::sqrt(a * a + (x * inv).squaredNorm());
  const Scalar beta = alpha >= Scalar(0) ? -norm : norm;
  const Scalar tau = (beta - alpha) / beta;
  x *= Scalar(1) / (alpha - beta);
  alpha = beta;
  return tau;
}

/// Givens rotation [c s; −s c] with −s·a + c·b = 0 and c·a + s·b = ρ = hypot(a, b) ≥ 0 for
/// b ≠ 0 (Golub & Van Loan, Algorithm 5.1.3, scaled against overflow).
template <typename Scalar>
inline Scalar makeGivens(Scalar a, Scalar b, Scalar& c, Scalar& s) {
  if (b == Scalar(0)) {  // identity (ρ = a keeps its sign; the sign of a row of R is free)
    c = Scalar(1);
    s = Scalar(0);
    return a;
  }
  const Scalar aa = std::abs(a);
  const Scalar ab = std::abs(b);
  Scalar rho;
  if (ab > aa) {
    const Scalar t = a / b;
    rho = ab * std::sqrt(Scalar(1) + t * t);
  } else {
    const Scalar t = b / a;
    rho = aa * std::sqrt(Scalar(1) + t * t);
  }
  c = a / rho;
  s = b / rho;
  return rho;
}

/// x ← c·x + s·y, y ← c·y − s·x over n contiguous entries.
template <typename Scalar>
inline void rotateRows(Scalar* __restrict x, Scalar* __restrict y, int n, Scalar c, Scalar s) {
  for (int t = 0; t < n; ++t) {
    const Scalar xv = x[t];
    const Scalar yv = y[t];
    x[t] = c * xv + s * yv;
    y[t] = c * yv - s * xv;
  }
}

}  // namespace

template <typename Scalar>
void householderRowUpdate(RowMatrixView<Scalar> R, VectorView<Scalar> r, RowMatrixView<Scalar> W,
                          VectorView<Scalar> z, std::span<const int> lead, int panel) {
  using Matrix = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>;
  using RowMat = RowMatrix<Scalar>;
  using Vector = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>;
  const int k = static_cast<int>(R.rows());
  const int m = static_cast<int>(W.rows());
  if (m == 0 || k == 0 || lead.empty() || lead[0] >= k) return;
  panel = std::max(1, std::min(panel, k));

  Matrix T = Matrix::Zero(panel, panel);
  RowMat Y(panel, k);
  RowMat Y2(panel, k);
  Vector tau(panel);
  Vector tmp(panel);
  Eigen::Matrix<Scalar, 1, Eigen::Dynamic> wv(panel);

  int a = 0;  // active rows: lead < end of panel
  for (int j0 = lead[0]; j0 < k;) {
    const int jb = std::min(panel, k - j0);
    while (a < m && lead[static_cast<std::size_t>(a)] < j0 + jb) ++a;
    if (a == 0) {  // cannot happen (lead[0] < k), kept for safety
      j0 += jb;
      continue;
    }
    // --- Panel factorization (unblocked), columns j0 .. j0+jb−1.
    for (int jj = 0; jj < jb; ++jj) {
      const int j = j0 + jj;
      auto v = W.col(j).head(a);
      tau(jj) = makeReflector<Scalar>(R(j, j), v);
      const int ncols = jb - jj - 1;
      if (tau(jj) != Scalar(0) && ncols > 0) {
        auto Rrow = R.row(j).segment(j + 1, ncols);
        auto Wb = W.block(0, j + 1, a, ncols);
        auto w = wv.head(ncols);
        w.noalias() = v.transpose() * Wb;
        w += Rrow;
        Rrow -= tau(jj) * w;
        Wb.noalias() -= (tau(jj) * v) * w;
      }
    }
    auto V = W.block(0, j0, a, jb);
    // --- T of the compact WY form Q = H_1 ⋯ H_jb = I − V T Vᵀ, V = [I; V_W].
    auto Tb = T.topLeftCorner(jb, jb);
    Tb.setZero();
    for (int jj = 0; jj < jb; ++jj) {
      Tb(jj, jj) = tau(jj);
      if (jj > 0 && tau(jj) != Scalar(0)) {
        auto t = tmp.head(jj);
        t.noalias() = V.leftCols(jj).transpose() * V.col(jj);
        t *= -tau(jj);
        Tb.col(jj).head(jj).noalias() =
            Tb.topLeftCorner(jj, jj).template triangularView<Eigen::Upper>() * t;
      }
    }
    // --- Apply Qᵀ = I − V Tᵀ Vᵀ to the trailing columns and to the right-hand side.
    const int c1 = j0 + jb;
    const int nt = k - c1;
    if (nt > 0) {
      auto CA = R.block(j0, c1, jb, nt);
      auto CB = W.block(0, c1, a, nt);
      auto Yb = Y.topLeftCorner(jb, nt);
      auto Y2b = Y2.topLeftCorner(jb, nt);
      Yb.noalias() = V.transpose() * CB;
      Yb += CA;
      Y2b.noalias() = Tb.transpose().template triangularView<Eigen::Lower>() * Yb;
      CA -= Y2b;
      CB.noalias() -= V * Y2b;
    }
    {
      auto y = tmp.head(jb);
      y.noalias() = V.transpose() * z.head(a);
      y += r.segment(j0, jb);
      Vector y2 = Tb.transpose().template triangularView<Eigen::Lower>() * y;
      r.segment(j0, jb) -= y2;
      z.head(a).noalias() -= V * y2;
    }
    j0 += jb;
  }
}

template <typename Scalar>
void givensRowUpdate(RowMatrixView<Scalar> R, VectorView<Scalar> r, RowMatrixView<Scalar> W,
                     VectorView<Scalar> z, std::span<const int> lead) {
  const int k = static_cast<int>(R.rows());
  const int m = static_cast<int>(W.rows());
  if (m == 0 || k == 0 || lead.empty() || lead[0] >= k) return;
  std::vector<int> rows;
  std::vector<Scalar> cs;
  std::vector<Scalar> sn;
  rows.reserve(static_cast<std::size_t>(m));
  cs.reserve(static_cast<std::size_t>(m));
  sn.reserve(static_cast<std::size_t>(m));
  int a = 0;
  for (int j = lead[0]; j < k; ++j) {
    while (a < m && lead[static_cast<std::size_t>(a)] <= j) ++a;
    rows.clear();
    cs.clear();
    sn.clear();
    Scalar p = R(j, j);
    for (int i = 0; i < a; ++i) {
      const Scalar w = W(i, j);
      if (w == Scalar(0)) continue;
      Scalar c;
      Scalar s;
      p = makeGivens(p, w, c, s);
      W(i, j) = Scalar(0);
      rows.push_back(i);
      cs.push_back(c);
      sn.push_back(s);
    }
    if (rows.empty()) continue;
    R(j, j) = p;
    const int len = k - j - 1;
    Scalar* prow = &R(j, j) + 1;
    Scalar rj = r(j);
    for (std::size_t q = 0; q < rows.size(); ++q) {
      const int i = rows[q];
      if (len > 0) rotateRows(prow, &W(i, j) + 1, len, cs[q], sn[q]);
      const Scalar zi = z(i);
      z(i) = cs[q] * zi - sn[q] * rj;
      rj = cs[q] * rj + sn[q] * zi;
    }
    r(j) = rj;
  }
}

template <typename Scalar>
void sweepColumnsToFront(RowMatrixView<Scalar> R, VectorView<Scalar> r, int c, int d, int t) {
  const int n = static_cast<int>(R.cols());
  if (d <= 0 || c <= t) return;
  std::vector<Scalar> cs(static_cast<std::size_t>(d));
  std::vector<Scalar> sn(static_cast<std::size_t>(d));
  std::vector<Scalar> carry(static_cast<std::size_t>(std::max(n, 1)));
  const int cend = c + d;
  for (int i = c - 1; i >= t; --i) {
    // Rotation k acts on rows (i+k, i+k+1) and zeroes R(i+k+1, c+k); computed sequentially on
    // the moved block's columns, where the previous rotations have to be applied first.
    for (int k = 0; k < d; ++k) {
      const int top = i + k;
      const int bot = top + 1;
      Scalar ck;
      Scalar sk;
      R(top, c + k) = makeGivens(R(top, c + k), R(bot, c + k), ck, sk);
      R(bot, c + k) = Scalar(0);
      for (int q = k + 1; q < d; ++q) {
        const Scalar x = R(top, c + q);
        const Scalar y = R(bot, c + q);
        R(top, c + q) = ck * x + sk * y;
        R(bot, c + q) = ck * y - sk * x;
      }
      cs[static_cast<std::size_t>(k)] = ck;
      sn[static_cast<std::size_t>(k)] = sk;
    }
    // The same chain on the other columns ≥ i and on r: one pass per row, the "bottom" result
    // of rotation k is carried into rotation k+1.
    auto chain = [&](int col0, int len) {
      if (len <= 0) return;
      Scalar* __restrict cr = carry.data();
      const Scalar* src = &R(i, col0);
      for (int q = 0; q < len; ++q) cr[q] = src[q];
      for (int k = 0; k < d; ++k) {
        Scalar* __restrict top = &R(i + k, col0);
        const Scalar* __restrict bot = &R(i + k + 1, col0);
        const Scalar ck = cs[static_cast<std::size_t>(k)];
        const Scalar sk = sn[static_cast<std::size_t>(k)];
        for (int q = 0; q < len; ++q) {
          const Scalar x = cr[q];
          const Scalar y = bot[q];
          top[q] = ck * x + sk * y;
          cr[q] = ck * y - sk * x;
        }
      }
      Scalar* dst = &R(i + d, col0);
      for (int q = 0; q < len; ++q) dst[q] = cr[q];
    };
    // Column i: only row i is non-zero there (the rows below are below their diagonals, whose
    // storage is not read), so the chain reduces to scalars.
    {
      Scalar x = R(i, i);
      for (int k = 0; k < d; ++k) {
        R(i + k, i) = cs[static_cast<std::size_t>(k)] * x;
        x = -sn[static_cast<std::size_t>(k)] * x;
      }
      R(i + d, i) = x;
    }
    chain(i + 1, c - i - 1);
    chain(cend, n - cend);
    Scalar x = r(i);
    for (int k = 0; k < d; ++k) {
      const Scalar y = r(i + k + 1);
      r(i + k) = cs[static_cast<std::size_t>(k)] * x + sn[static_cast<std::size_t>(k)] * y;
      x = cs[static_cast<std::size_t>(k)] * y - sn[static_cast<std::size_t>(k)] * x;
    }
    r(i + d) = x;
  }
}

#define GVINS_SRI_INSTANTIATE(S)                                                              \
  template void householderRowUpdate<S>(RowMatrixView<S>, VectorView<S>, RowMatrixView<S>,    \
                                        VectorView<S>, std::span<const int>, int);            \
  template void givensRowUpdate<S>(RowMatrixView<S>, VectorView<S>, RowMatrixView<S>,         \
                                   VectorView<S>, std::span<const int>);                      \
  template void sweepColumnsToFront<S>(RowMatrixView<S>, VectorView<S>, int, int, int);
GVINS_SRI_INSTANTIATE(float)
GVINS_SRI_INSTANTIATE(double)
#undef GVINS_SRI_INSTANTIATE

}  // namespace gvins::sri
