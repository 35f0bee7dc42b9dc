#include "gvins/sri/measurement.hpp"

#include <stdexcept>
#include <string>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>
#include <vector>

#include "gvins/sri/qr_update.hpp"
#include "gvins/sri/square_root.hpp"

namespace gvins::sri {

namespace {
/// (x, y) ← (c x + s y, c y − s x): one entry pair of a Givens rotation of two rows.
template <typename Scalar>
inline void rotatePair(Scalar& x, Scalar& y, Scalar c, Scalar s) {
  const Scalar xv = x;
  const Scalar yv = y;
  x = c * xv + s * yv;
  y = c * yv - s * xv;
}
}  // namespace

template <typename Scalar>
void Measurement<Scalar>::reset(int rows) {
  if (rows < 0) throw std::invalid_argument("sri::Measurement: negative row count");
  H_.resize(rows, 0);
  nuisance_.resize(rows, 0);
  residual_ = Vector::Zero(rows);
  blocks_.clear();
  whitened_ = false;
  discarded_chi2_ = 0;
  discarded_rows_ = 0;
}

template <typename Scalar>
Eigen::Block<typename Measurement<Scalar>::JacobianMatrix> Measurement<Scalar>::jacobian(BlockId id, int dim) {
  if (!id.valid() || dim <= 0) {
    throw std::invalid_argument("sri::Measurement::jacobian: invalid block id or dimension");
  }
  for (const Entry& e : blocks_) {
    if (e.id == id) {
      if (e.dim != dim) {
        throw std::invalid_argument("sri::Measurement::jacobian: block " +
                                    std::to_string(id.value) + " has dimension " +
                                    std::to_string(e.dim) + ", not " + std::to_string(dim));
      }
      return H_.block(0, e.col, rows(), dim);
    }
  }
  const int col = static_cast<int>(H_.cols());
  H_.conservativeResize(Eigen::NoChange, col + dim);
  H_.rightCols(dim).setZero();
  blocks_.push_back({id, col, dim});
  return H_.block(0, col, rows(), dim);
}

template <typename Scalar>
void Measurement<Scalar>::rotateRows(int a, int b, Scalar c, Scalar s) {
  if (a < 0 || b < 0 || a >= rows() || b >= rows() || a == b) {
    throw std::invalid_argument("sri::Measurement::rotateRows: bad row pair");
  }
  auto rot = [&](auto& M) {
    for (Eigen::Index col = 0; col < M.cols(); ++col) rotatePair(M(a, col), M(b, col), c, s);
  };
  rot(H_);
  rot(nuisance_);
  rotatePair(residual_(a), residual_(b), c, s);
}

template <typename Scalar>
void Measurement<Scalar>::addBlocks(std::span<const BlockId> ids, std::span<const int> dims) {
  if (ids.size() != dims.size()) throw std::invalid_argument("sri::Measurement::addBlocks: ids and dims differ in size");
  int add = 0;
  std::vector<Entry> fresh;
  for (std::size_t k = 0; k < ids.size(); ++k) {
    if (!ids[k].valid() || dims[k] <= 0) {
      throw std::invalid_argument("sri::Measurement::addBlocks: invalid block id or dimension");
    }
    bool found = false;
    auto check = [&](const Entry& e) {
      if (e.id != ids[k]) return;
      if (e.dim != dims[k]) {
        throw std::invalid_argument("sri::Measurement::addBlocks: block " + std::to_string(e.id.value) +
                                    " has dimension " + std::to_string(e.dim) + ", not " + std::to_string(dims[k]));
      }
      found = true;
    };
    for (const Entry& e : blocks_) check(e);
    for (const Entry& e : fresh) check(e);
    if (found) continue;
    fresh.push_back({ids[k], static_cast<int>(H_.cols()) + add, dims[k]});
    add += dims[k];
  }
  if (add == 0) return;
  const Eigen::Index c0 = H_.cols();
  if (c0 == 0) {
    H_.setZero(rows(), add);
  } else {
    H_.conservativeResize(Eigen::NoChange, c0 + add);
    H_.rightCols(add).setZero();
  }
  blocks_.insert(blocks_.end(), fresh.begin(), fresh.end());
}

template <typename Scalar>
Eigen::Block<typename Measurement<Scalar>::Matrix> Measurement<Scalar>::nuisance(int dim) {
  if (dim <= 0) throw std::invalid_argument("sri::Measurement::nuisance: dimension must be > 0");
  if (nuisance_.cols() != dim) {
    if (nuisance_.cols() != 0) {
      throw std::invalid_argument("sri::Measurement::nuisance: dimension changed");
    }
    nuisance_ = Matrix::Zero(rows(), dim);
  }
  return nuisance_.block(0, 0, rows(), dim);
}

template <typename Scalar>
template <typename Op>
void Measurement<Scalar>::transformRows(Op&& op) {
  op(H_);
  op(nuisance_);
  op(residual_);
}

template <typename Scalar>
void Measurement<Scalar>::whitenStdDev(Scalar sigma) {
  if (!(sigma > Scalar(0))) throw std::invalid_argument("sri::Measurement: σ must be > 0");
  const Scalar w = Scalar(1) / sigma;
  transformRows([w](auto& m) { m *= w; });
  whitened_ = true;
}

template <typename Scalar>
void Measurement<Scalar>::whitenStdDevs(const Vector& sigmas) {
  if (sigmas.size() != rows() || !(sigmas.array() > Scalar(0)).all()) {
    throw std::invalid_argument("sri::Measurement: need rows() standard deviations > 0");
  }
  const Vector w = sigmas.cwiseInverse();
  transformRows([&w](auto& m) { m = w.asDiagonal() * m; });
  whitened_ = true;
}

template <typename Scalar>
void Measurement<Scalar>::whitenCovariance(const Matrix& covariance) {
  if (covariance.rows() != rows() || covariance.cols() != rows()) {
    throw std::invalid_argument("sri::Measurement: covariance must be rows() × rows()");
  }
  const auto L = choleskyLower<Scalar>(covariance);
  if (!L) throw std::invalid_argument("sri::Measurement: noise covariance is not positive definite");
  // Rows ← L⁻¹ rows on [H nuisance r] at once.
  const Eigen::Index p = H_.cols();
  const Eigen::Index q = nuisance_.cols();
  Matrix A(rows(), p + q + 1);
  A << H_, nuisance_, residual_;
  solveLowerInPlace<Scalar>(*L, A);
  H_ = A.leftCols(p);
  nuisance_ = A.middleCols(p, q);
  residual_ = A.col(p + q);
  whitened_ = true;
}

template <typename Scalar>
void Measurement<Scalar>::whitenSqrtInformation(const Matrix& S) {
  if (S.rows() != rows() || S.cols() != rows()) {
    throw std::invalid_argument("sri::Measurement: square-root information must be rows() × rows()");
  }
  transformRows([&S](auto& m) { m = S * m; });
  whitened_ = true;
}

template <typename Scalar>
int Measurement<Scalar>::projectNuisance(Measurement* nuisanceRows, NuisanceProjection how) {
  if (!whitened_) throw std::logic_error("sri::Measurement::projectNuisance: whiten first");
  if (nuisanceRows == this) throw std::invalid_argument("sri::Measurement::projectNuisance: output is the input");
  const int q = nuisanceDim();
  const int m = rows();
  if (nuisanceRows) {
    nuisanceRows->reset(0);
    nuisanceRows->blocks_ = blocks_;
    nuisanceRows->whitened_ = true;
  }
  if (q == 0) return 0;
  if (m <= q) {  // no information left about the state
    if (nuisanceRows) {
      nuisanceRows->H_ = H_;
      nuisanceRows->nuisance_ = nuisance_;
      nuisanceRows->residual_ = residual_;
    }
    reset(0);
    whitened_ = true;
    return m;
  }
  const int p = static_cast<int>(H_.cols());
  if (how == NuisanceProjection::kHouseholder) {
    // Column j of the nuisance below row j−1 reflected onto row j (Golub & Van Loan, Matrix
    // Computations, 4th ed., Alg. 5.1.1), applied to the nuisance columns > j, to H (row-major:
    // w = Hᵀv and H −= β v wᵀ run along the rows) and to r.
    Vector v;
    Eigen::Matrix<Scalar, 1, Eigen::Dynamic> w;
    for (int j = 0; j < q; ++j) {
      const int len = m - j;
      auto x = nuisance_.col(j).tail(len);
      const Scalar norm = x.norm();
      if (norm == Scalar(0)) continue;
      const Scalar alpha = x(0) > Scalar(0) ? -norm : norm;
      v = x;
      v(0) -= alpha;
      const Scalar vv = v.squaredNorm();
      if (vv == Scalar(0)) continue;
      const Scalar beta = Scalar(2) / vv;
      for (int k = j + 1; k < q; ++k) {
        auto col = nuisance_.col(k).tail(len);
        col.noalias() -= (beta * v.dot(col)) * v;
      }
      if (p > 0) {
        auto Hj = H_.bottomRows(len);
        w.noalias() = v.transpose() * Hj;
        Hj.noalias() -= (beta * v) * w;
      }
      auto rj = residual_.tail(len);
      rj.noalias() -= (beta * v.dot(rj)) * v;
      x.setZero();
      x(0) = alpha;
    }
  } else {
    // Zero the nuisance column j below row j, from the bottom up, with rotations of adjacent rows;
    // the rows j+1.. of the nuisance columns then span its left null space. H is row-major, so the
    // rotations run on contiguous rows in place; columns < j of the nuisance are already zero in
    // both rows and are skipped.
    // First non-zero column of every row of H (an MSCKF row has its clone's columns and the
    // calibration blocks after them; rows are in observation order): a rotation of rows i − 1 and
    // i only touches the columns from the smaller of their leads on (zeros in both stay zero), and
    // both rows then start there.
    static thread_local std::vector<int> lead;
    lead.resize(static_cast<std::size_t>(m));
    for (int i = 0; i < m; ++i) {
      const Scalar* h = H_.row(i).data();
      int l = 0;
      while (l < p && h[l] == Scalar(0)) ++l;
      lead[static_cast<std::size_t>(i)] = l;
    }
    for (int j = 0; j < q; ++j) {
      for (int i = m - 1; i > j; --i) {
        const Scalar b = nuisance_(i, j);
        if (b == Scalar(0)) continue;
        Scalar c, s;
        makeGivens(nuisance_(i - 1, j), b, c, s);
        for (int k = j; k < q; ++k) rotatePair(nuisance_(i - 1, k), nuisance_(i, k), c, s);
        int& lx = lead[static_cast<std::size_t>(i - 1)];
        int& ly = lead[static_cast<std::size_t>(i)];
        const int l = std::min(lx, ly);
        lx = ly = l;
        Scalar* x = H_.row(i - 1).data();
        Scalar* y = H_.row(i).data();
        for (int col = l; col < p; ++col) rotatePair(x[col], y[col], c, s);
        rotatePair(residual_(i - 1), residual_(i), c, s);
      }
    }
  }
  const int keep = m - q;
  if (nuisanceRows) {
    nuisanceRows->nuisance_ = nuisance_.topRows(q).template triangularView<Eigen::Upper>();
    nuisanceRows->H_ = H_.topRows(q);
    nuisanceRows->residual_ = residual_.head(q);
  }
  // The kept rows to the front (contiguous in row-major storage), then shrink.
  if (p > 0) {
    std::memmove(H_.data(), H_.data() + static_cast<std::ptrdiff_t>(q) * p,
                 sizeof(Scalar) * static_cast<std::size_t>(keep) * static_cast<std::size_t>(p));
  }
  std::memmove(residual_.data(), residual_.data() + q, sizeof(Scalar) * static_cast<std::size_t>(keep));
  H_.conservativeResize(keep, p);
  residual_.conservativeResize(keep);
  nuisance_.resize(keep, 0);
  return q;
}

template <typename Scalar>
int Measurement<Scalar>::compress() {
  if (!whitened_) throw std::logic_error("sri::Measurement::compress: whiten first");
  if (nuisanceDim() != 0) throw std::logic_error("sri::Measurement::compress: project nuisance first");
  const int m = rows();
  const int p = static_cast<int>(H_.cols());
  if (m <= p) return 0;
  // QR of [H r] as a stacked update onto an empty p×p factor (qr_update.hpp).
  std::vector<int> lead(static_cast<std::size_t>(m));
  std::vector<int> order(static_cast<std::size_t>(m));
  for (int i = 0; i < m; ++i) {
    int l = 0;
    while (l < p && H_(i, l) == Scalar(0)) ++l;
    lead[static_cast<std::size_t>(i)] = l;
  }
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return lead[static_cast<std::size_t>(a)] < lead[static_cast<std::size_t>(b)];
  });
  RowMatrix<Scalar> W(m, p);
  Vector z(m);
  std::vector<int> sortedLead(static_cast<std::size_t>(m));
  for (int s = 0; s < m; ++s) {
    const int i = order[static_cast<std::size_t>(s)];
    W.row(s) = H_.row(i);
    z(s) = residual_(i);
    sortedLead[static_cast<std::size_t>(s)] = lead[static_cast<std::size_t>(i)];
  }
  RowMatrix<Scalar> R = RowMatrix<Scalar>::Zero(p, p);
  Vector r = Vector::Zero(p);
  householderRowUpdate<Scalar>(RowMatrixView<Scalar>(R.data(), p, p, Eigen::OuterStride<>(p)),
                               VectorView<Scalar>(r.data(), p),
                               RowMatrixView<Scalar>(W.data(), m, p, Eigen::OuterStride<>(p)),
                               VectorView<Scalar>(z.data(), m), sortedLead);
  discarded_chi2_ += z.squaredNorm();
  discarded_rows_ += m - p;
  H_ = R.template triangularView<Eigen::Upper>();
  residual_ = r;
  nuisance_.resize(p, 0);
  return m - p;
}

template <typename Scalar>
void Measurement<Scalar>::stack(const Measurement& other) {
  if (nuisanceDim() != 0 || other.nuisanceDim() != 0) {
    throw std::logic_error("sri::Measurement::stack: project nuisance first");
  }
  if (rows() > 0 && other.rows() > 0 && whitened_ != other.whitened_) {
    throw std::logic_error("sri::Measurement::stack: whitening state differs");
  }
  const int m0 = rows();
  const int m1 = other.rows();
  // The joint block list first (other's new blocks after mine), then one allocation.
  std::vector<Entry> blocks = blocks_;
  std::vector<int> colOf;  // column of each of other's blocks in the joint list
  colOf.reserve(other.blocks_.size());
  int cols = static_cast<int>(H_.cols());
  for (const Entry& e : other.blocks_) {
    int col = -1;
    for (const Entry& mine : blocks) {
      if (mine.id == e.id) {
        if (mine.dim != e.dim) throw std::invalid_argument("sri::Measurement::stack: dim mismatch");
        col = mine.col;
      }
    }
    if (col < 0) {
      col = cols;
      cols += e.dim;
      blocks.push_back({e.id, col, e.dim});
    }
    colOf.push_back(col);
  }
  JacobianMatrix H = JacobianMatrix::Zero(m0 + m1, cols);
  H.topLeftCorner(m0, H_.cols()) = H_;
  for (std::size_t k = 0; k < other.blocks_.size(); ++k) {
    const Entry& e = other.blocks_[k];
    H.block(m0, colOf[k], m1, e.dim) = other.H_.block(0, e.col, m1, e.dim);
  }
  Vector r(m0 + m1);
  r << residual_, other.residual_;
  const bool white = m0 > 0 ? whitened_ : other.whitened_;
  H_ = std::move(H);
  residual_ = std::move(r);
  blocks_ = std::move(blocks);
  nuisance_.resize(m0 + m1, 0);
  whitened_ = white;
  discarded_chi2_ += other.discarded_chi2_;
  discarded_rows_ += other.discarded_rows_;
}

template class Measurement<float>;
template class Measurement<double>;

}  // namespace gvins::sri
