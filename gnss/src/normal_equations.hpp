// Weighted least-squares normal equations N x = b for a handful of unknowns (SPP: position,
// one clock per system, a zenith ionosphere term: at most 11), accumulated row by row and solved
// by an unpivoted LDL^T factorisation, all in fixed-size arrays.
//
// Why not Eigen's dynamic-size GEMM + LDLT: for 3-11 unknowns and 10-40 rows the blocked
// product kernels spend most of their time packing, and each design row has only 4-5 non-zero
// entries (three line-of-sight components, one clock, the ionosphere mapping), which a rank-1
// update can skip. Measured on the Kamakura file (900 epochs, 20 satellites): the least-squares
// step (GEMM, GEMV, LDLT, the covariance by triangular solves) went from 116 M to 89 M
// instructions (callgrind), the whole run from 335 M to 308 M.
//
// N is symmetric positive (semi-)definite; the factorisation declares it singular when a pivot
// is not above max(relTol x the largest diagonal entry of N, absTol) (the tests the SPP and the
// DOPs used with Eigen's pivoted LDLT before).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>

namespace gvins::detail {

template <int MaxN>
class NormalEquations {
 public:
  explicit NormalEquations(int n = 0) { reset(n); }

  void reset(int n) {
    n_ = n;
    for (int i = 0; i < n_; ++i) {
      b_[i] = 0.0;
      for (int j = i; j < n_; ++j) a_[i][j] = 0.0;
    }
  }

  /// A design row with at most 5 non-zero entries, column indices strictly ascending.
  struct SparseRow {
    std::array<int, 5> col{};
    std::array<double, 5> val{};
    int nnz = 0;
    void push(int c, double v) {
      col[nnz] = c;
      val[nnz] = v;
      ++nnz;
    }
    double dot(const double* x) const {
      double s = 0.0;
      for (int k = 0; k < nnz; ++k) s += val[k] * x[col[k]];
      return s;
    }
  };

  /// Adds the row h with observation v and weight w: N += w h h^T, b += w h v, over the
  /// non-zeros of h only.
  void addRow(const SparseRow& h, double v, double w) {
    for (int k = 0; k < h.nnz; ++k) {
      const double whk = w * h.val[k];
      const int i = h.col[k];
      b_[i] += whk * v;
      for (int l = k; l < h.nnz; ++l) a_[i][h.col[l]] += whk * h.val[l];  // i < col[l]: upper
    }
  }

  /// h^T S h for a symmetric matrix S stored column-major with stride ld (e.g. inverse()).
  static double quadraticForm(const SparseRow& h, const double* s, int ld) {
    double diag = 0.0, off = 0.0;
    for (int k = 0; k < h.nnz; ++k) {
      const double* sk = s + h.col[k] * ld;
      diag += h.val[k] * h.val[k] * sk[h.col[k]];
      for (int l = k + 1; l < h.nnz; ++l) off += h.val[k] * h.val[l] * sk[h.col[l]];
    }
    return diag + 2.0 * off;
  }

  /// Factorises N = L D L^T in place of the upper triangle (L^T stored above the diagonal).
  /// Returns false when a pivot is not above max(relTol * max diag N, absTol).
  bool factor(double relTol, double absTol = 0.0) {
    double maxDiag = 0.0;
    for (int i = 0; i < n_; ++i) maxDiag = std::max(maxDiag, a_[i][i]);
    const double tol = std::max(relTol * maxDiag, absTol);
    // Column-wise LDL^T: for j, d_j = a_jj - sum_k<j l_jk^2 d_k, l_ij = (a_ji - sum l_ik l_jk d_k)/d_j.
    for (int j = 0; j < n_; ++j) {
      double d = a_[j][j];
      for (int k = 0; k < j; ++k) d -= a_[k][j] * a_[k][j] * d_[k];
      if (!(d > tol)) return false;
      d_[j] = d;
      const double inv = 1.0 / d;
      for (int i = j + 1; i < n_; ++i) {
        double s = a_[j][i];
        for (int k = 0; k < j; ++k) s -= a_[k][i] * a_[k][j] * d_[k];
        a_[j][i] = s * inv;  // l_ij stored at (j, i)
      }
    }
    return true;
  }

  /// Solves N x = y for one right-hand side after factor() (x may alias y).
  void solve(const double* y, double* x) const {
    std::array<double, MaxN> z{};
    for (int i = 0; i < n_; ++i) {  // L z = y
      double s = y[i];
      for (int k = 0; k < i; ++k) s -= a_[k][i] * z[k];
      z[i] = s;
    }
    for (int i = 0; i < n_; ++i) z[i] /= d_[i];
    for (int i = n_ - 1; i >= 0; --i) {  // L^T x = z
      double s = z[i];
      for (int k = i + 1; k < n_; ++k) s -= a_[i][k] * x[k];
      x[i] = s;
    }
  }

  /// x = N^-1 b after factor().
  void solve(double* x) const { solve(b_.data(), x); }

  /// N^-1 after factor(), written with stride `ld` (column-major, element (i, j) at inv[i + j ld]).
  void inverse(double* inv, int ld) const {
    std::array<double, MaxN> e{}, col{};
    for (int j = 0; j < n_; ++j) {
      e.fill(0.0);
      e[j] = 1.0;
      solve(e.data(), col.data());
      for (int i = 0; i < n_; ++i) inv[i + j * ld] = col[i];
    }
  }

 private:
  int n_ = 0;
  std::array<std::array<double, MaxN>, MaxN> a_{};
  std::array<double, MaxN> b_{};
  std::array<double, MaxN> d_{};
};

}  // namespace gvins::detail
