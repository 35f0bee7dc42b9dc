#include "gvins/sri/sri_filter.hpp"

#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "gvins/sri/square_root.hpp"

namespace gvins::sri {

namespace {

template <typename Scalar>
Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic> priorFactor(const Prior<Scalar>& prior,
                                                                  int d) {
  using Matrix = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>;
  switch (prior.type) {
    case Prior<Scalar>::Type::kUninformative:
      return Matrix::Zero(d, d);
    case Prior<Scalar>::Type::kSqrtInformation:
      if (prior.matrix.cols() != d || !prior.matrix.allFinite()) {
        throw std::invalid_argument("sri::SriFilter: prior square-root information must have " +
                                    std::to_string(d) + " finite columns");
      }
      return triangularFactor<Scalar>(prior.matrix);
    case Prior<Scalar>::Type::kCovariance: {
      if (prior.matrix.rows() != d || prior.matrix.cols() != d || !prior.matrix.allFinite()) {
        throw std::invalid_argument("sri::SriFilter: prior covariance must be " + std::to_string(d) +
                                    "×" + std::to_string(d));
      }
      auto U = sqrtInformationFromCovariance<Scalar>(prior.matrix);
      if (!U) throw std::invalid_argument("sri::SriFilter: prior covariance is not positive definite");
      return *U;
    }
  }
  return Matrix::Zero(d, d);
}

}  // namespace

template <typename Scalar>
SriFilter<Scalar>::SriFilter(SriOptions options) : options_(options), layout_(options.first_block_id) {}

template <typename Scalar>
RowMatrixView<Scalar> SriFilter<Scalar>::view(int row, int col, int rows, int cols) {
  return RowMatrixView<Scalar>(rowPtr(row) + col, rows, cols, Eigen::OuterStride<>(ld_));
}

template <typename Scalar>
Eigen::Map<const RowMatrix<Scalar>, Eigen::Unaligned, Eigen::OuterStride<>>
SriFilter<Scalar>::cview(int row, int col, int rows, int cols) const {
  return Eigen::Map<const RowMatrix<Scalar>, Eigen::Unaligned, Eigen::OuterStride<>>(
      rowPtr(row) + col, rows, cols, Eigen::OuterStride<>(ld_));
}

template <typename Scalar>
RowMatrixView<Scalar> SriFilter<Scalar>::rawR() {
  return view(0, 0, n_, n_);
}

template <typename Scalar>
VectorView<Scalar> SriFilter<Scalar>::rawResidual() {
  return rview(0, n_);
}

template <typename Scalar>
void SriFilter<Scalar>::reserve(int dim) {
  if (dim > cap_) relocate(dim);
}

template <typename Scalar>
void SriFilter<Scalar>::relocate(int need) {
  int cap = cap_;
  if (need > cap) cap = std::max({need + need / 2, 2 * cap, 32});
  const int off = (cap - need) / 4;  // headroom in front for blocks inserted there
  if (cap != cap_) {
    constexpr int kLine = 64 / static_cast<int>(sizeof(Scalar));
    int lines = (cap + kLine - 1) / kLine;
    if (lines % 2 == 0) ++lines;
    const int ld = lines * kLine;
    RowMatrix<Scalar> buf(cap, ld);
    Vector rbuf = Vector::Zero(cap);
    for (int i = 0; i < n_; ++i) {
      std::memcpy(buf.data() + static_cast<std::ptrdiff_t>(off + i) * ld + off, rowPtr(i),
                  sizeof(Scalar) * static_cast<std::size_t>(n_));
    }
    if (n_ > 0) rbuf.segment(off, n_) = rbuf_.segment(off_, n_);
    buf_ = std::move(buf);
    rbuf_ = std::move(rbuf);
    cap_ = cap;
    ld_ = ld;
    off_ = off;
    return;
  }
  if (off == off_) return;
  // Same buffer: move rows in an order that never overwrites a row not yet moved.
  auto moveRow = [&](int i) {
    std::memmove(buf_.data() + static_cast<std::ptrdiff_t>(off + i) * ld_ + off, rowPtr(i),
                 sizeof(Scalar) * static_cast<std::size_t>(n_));
  };
  if (off < off_) {
    for (int i = 0; i < n_; ++i) moveRow(i);
  } else {
    for (int i = n_ - 1; i >= 0; --i) moveRow(i);
  }
  if (n_ > 0) {
    std::memmove(rbuf_.data() + off, rbuf_.data() + off_, sizeof(Scalar) * static_cast<std::size_t>(n_));
  }
  off_ = off;
}

template <typename Scalar>
void SriFilter<Scalar>::openColumns(int c, int d) {
  if (d <= 0) return;
  const bool frontFits = off_ >= d;
  const bool backFits = off_ + n_ + d <= cap_;
  if (!frontFits && !backFits) {
    relocate(n_ + d);
    openColumns(c, d);
    return;
  }
  const bool useFront = frontFits && (!backFits || c <= n_ - c);
  const std::size_t sz = sizeof(Scalar);
  if (useFront) {
    // Rows [0, c) move up by d; their columns [0, c) move left by d, columns ≥ c stay in place.
    const int noff = off_ - d;
    for (int i = 0; i < c; ++i) {
      Scalar* src = rowPtr(i);
      Scalar* dst = buf_.data() + static_cast<std::ptrdiff_t>(noff + i) * ld_ + noff;
      std::memmove(dst + i, src + i, sz * static_cast<std::size_t>(c - i));
      std::memmove(dst + c + d, src + c, sz * static_cast<std::size_t>(n_ - c));
      std::fill(dst + c, dst + c + d, Scalar(0));
    }
    for (int q = 0; q < d; ++q) {
      Scalar* dst = buf_.data() + static_cast<std::ptrdiff_t>(noff + c + q) * ld_ + noff;
      std::fill(dst + c, dst + n_ + d, Scalar(0));
    }
    for (int i = 0; i < c; ++i) rbuf_(noff + i) = rbuf_(off_ + i);
    rbuf_.segment(noff + c, d).setZero();
    off_ = noff;
  } else {
    // Rows [c, n) move down and right by d; rows [0, c) shift their columns ≥ c right by d.
    for (int i = n_ - 1; i >= c; --i) {
      Scalar* src = rowPtr(i);
      Scalar* dst = rowPtr(i + d) + d;
      std::memmove(dst + i, src + i, sz * static_cast<std::size_t>(n_ - i));
    }
    for (int i = 0; i < c; ++i) {
      Scalar* row = rowPtr(i);
      std::memmove(row + c + d, row + c, sz * static_cast<std::size_t>(n_ - c));
      std::fill(row + c, row + c + d, Scalar(0));
    }
    for (int q = 0; q < d; ++q) {
      Scalar* row = rowPtr(c + q);
      std::fill(row + c, row + n_ + d, Scalar(0));
    }
    std::memmove(rbuf_.data() + off_ + c + d, rbuf_.data() + off_ + c,
                 sz * static_cast<std::size_t>(n_ - c));
    rbuf_.segment(off_ + c, d).setZero();
  }
  n_ += d;
}

template <typename Scalar>
void SriFilter<Scalar>::dropFrontAfterSweep(int c, int d) {
  // Row d+q (q < c) holds the row of old column q: its part [q, c) moves right by d so that
  // the view can start d rows and d columns later.
  for (int q = 0; q < c; ++q) {
    Scalar* row = rowPtr(d + q);
    std::memmove(row + q + d, row + q, sizeof(Scalar) * static_cast<std::size_t>(c - q));
  }
  off_ += d;
  n_ -= d;
  if (n_ == 0) off_ = cap_ / 4;
}

template <typename Scalar>
BlockId SriFilter<Scalar>::addBlock(const BlockSpec& spec, const BlockEstimate<Scalar>& estimate,
                                    const Prior<Scalar>& prior, Placement where) {
  StateLayout::validate(spec);
  if (!hasShape(estimate, spec.kind, spec.dim)) {
    throw std::invalid_argument("sri::SriFilter::addBlock: estimate does not fit block '" +
                                spec.name + "'");
  }
  const int pos = layout_.resolve(where);
  const auto U = priorFactor<Scalar>(prior, spec.dim);  // validates before changing anything
  const int c = pos < layout_.size() ? layout_.at(pos).offset : n_;
  const int d = spec.dim;
  openColumns(c, d);
  view(c, c, d, d) = U;
  rview(c, d).setZero();
  const BlockId id = layout_.insert(spec, pos);
  estimates_.insert(estimates_.begin() + pos, estimate);
  if constexpr (!std::is_same_v<Scalar, double>) {
    nominal_.insert(nominal_.begin() + pos, castEstimate<double>(estimate));
  }
  return id;
}

template <typename Scalar>
void SriFilter<Scalar>::marginalize(std::span<const BlockId> ids) {
  std::vector<BlockId> todo;
  for (BlockId id : ids) {
    (void)layout_.index(id);  // throws for unknown ids
    if (std::find(todo.begin(), todo.end(), id) == todo.end()) todo.push_back(id);
  }
  while (!todo.empty()) {
    // First remaining block in the order and the run of listed blocks adjacent to it.
    int first = layout_.size();
    for (BlockId id : todo) first = std::min(first, layout_.index(id));
    int last = first;
    auto listed = [&](int idx) {
      const BlockId id = layout_.at(idx).id;
      return std::find(todo.begin(), todo.end(), id) != todo.end();
    };
    while (last + 1 < layout_.size() && listed(last + 1)) ++last;
    const int c = layout_.at(first).offset;
    const int d = layout_.at(last).offset + layout_.at(last).dim - c;
    if (c > 0) sweepColumnsToFront<Scalar>(view(0, 0, n_, n_), rview(0, n_), c, d, 0);
    dropFrontAfterSweep(c, d);
    std::vector<BlockId> run;
    for (int idx = first; idx <= last; ++idx) run.push_back(layout_.at(idx).id);
    layout_.erase(std::span<const BlockId>(run));
    estimates_.erase(estimates_.begin() + first, estimates_.begin() + last + 1);
    if constexpr (!std::is_same_v<Scalar, double>) {
      nominal_.erase(nominal_.begin() + first, nominal_.begin() + last + 1);
    }
    todo.erase(std::remove_if(todo.begin(), todo.end(),
                              [&](BlockId id) { return !layout_.contains(id); }),
               todo.end());
  }
}

template <typename Scalar>
void SriFilter<Scalar>::substitute(BlockId id, const Matrix& A, std::span<const std::pair<BlockId, Matrix>> B,
                                   const BlockEstimate<double>& estimate) {
  const int pos = position(id);
  const BlockInfo& b = layout_.at(pos);
  const int o = b.offset;
  const int d = b.dim;
  if (!hasShape(estimate, b.kind, d)) {
    throw std::invalid_argument("sri::SriFilter::substitute: the new estimate of block '" + b.name +
                                "' does not have its kind and size");
  }
  if (A.rows() != d || A.cols() != d) throw std::invalid_argument("sri::SriFilter::substitute: A must be dim × dim");
  for (const auto& [j, Bj] : B) {
    const BlockInfo& bj = layout_.block(j);
    if (bj.offset < o + d) {
      throw std::invalid_argument("sri::SriFilter::substitute: block '" + bj.name + "' is not after '" + b.name + "'");
    }
    if (Bj.rows() != d || Bj.cols() != bj.dim) {
      throw std::invalid_argument("sri::SriFilter::substitute: B of block '" + bj.name + "' must be dim × its dim");
    }
  }
  const Eigen::FullPivLU<Matrix> lu(A);
  if (!lu.isInvertible()) throw std::invalid_argument("sri::SriFilter::substitute: A is singular");
  const Matrix Ainv = lu.inverse();
  // A⁻¹ B_j with the column offset of block j.
  std::vector<std::pair<int, Matrix>> AB;
  for (const auto& [j, Bj] : B) AB.emplace_back(layout_.block(j).offset, Ainv * Bj);
  // Rows that see the block: all rows up to its own (upper triangular R). In the block's own
  // rows only the entries on and right of the diagonal belong to R (the storage below the
  // diagonal is unspecified and must not be read).
  Eigen::Matrix<Scalar, 1, Eigen::Dynamic> Rx(d);
  for (int i = 0; i < o + d; ++i) {
    Scalar* row = rowPtr(i);
    const int q0 = std::max(0, i - o);
    for (int q = 0; q < d; ++q) Rx(q) = q < q0 ? Scalar(0) : row[o + q];
    if (Rx.isZero(0)) continue;
    for (const auto& [oj, ABj] : AB) {
      Eigen::Map<Eigen::Matrix<Scalar, 1, Eigen::Dynamic>>(row + oj, ABj.cols()).noalias() -= Rx * ABj;
    }
    Eigen::Map<Eigen::Matrix<Scalar, 1, Eigen::Dynamic>>(row + o, d).noalias() = Rx * Ainv;
  }
  // The block's own rows: its diagonal block R_xx A⁻¹ is full; Givens on those d rows (and r)
  // over the columns from o on make it upper triangular again.
  for (int c = 0; c < d; ++c) {
    for (int k = d - 1; k > c; --k) {
      Scalar* top = rowPtr(o + k - 1);
      Scalar* bot = rowPtr(o + k);
      Scalar cs;
      Scalar sn;
      top[o + c] = makeGivens(top[o + c], bot[o + c], cs, sn);
      bot[o + c] = Scalar(0);
      for (int col = o + c + 1; col < n_; ++col) {
        const Scalar x = top[col];
        const Scalar y = bot[col];
        top[col] = cs * x + sn * y;
        bot[col] = cs * y - sn * x;
      }
      Scalar& rx = rbuf_(off_ + o + k - 1);
      Scalar& ry = rbuf_(off_ + o + k);
      const Scalar x = rx;
      const Scalar y = ry;
      rx = cs * x + sn * y;
      ry = cs * y - sn * x;
    }
  }
  storeNominal(pos, estimate);
}

template <typename Scalar>
void SriFilter<Scalar>::reorder(std::span<const BlockId> order) {
  StateLayout next = layout_;
  next.reorder(order);  // validates
  // New column of every old column.
  std::vector<int> newcol(static_cast<std::size_t>(n_));
  for (const BlockInfo& b : layout_.blocks()) {
    const int nb = next.block(b.id).offset;
    for (int q = 0; q < b.dim; ++q) newcol[static_cast<std::size_t>(b.offset + q)] = nb + q;
  }
  int p = 0;
  while (p < n_ && newcol[static_cast<std::size_t>(p)] == p) ++p;
  std::vector<BlockEstimate<Scalar>> est;
  est.reserve(estimates_.size());
  for (BlockId id : order) est.push_back(estimates_[static_cast<std::size_t>(layout_.index(id))]);
  std::vector<BlockEstimate<double>> nom;
  if constexpr (!std::is_same_v<Scalar, double>) {
    nom.reserve(nominal_.size());
    for (BlockId id : order) nom.push_back(nominal_[static_cast<std::size_t>(layout_.index(id))]);
  }
  if (p < n_) {
    const int k = n_ - p;
    // Rows above p keep their position; their columns ≥ p are permuted.
    Vector tmp(k);
    for (int i = 0; i < p; ++i) {
      Scalar* row = rowPtr(i);
      for (int j = p; j < n_; ++j) tmp(newcol[static_cast<std::size_t>(j)] - p) = row[j];
      std::copy(tmp.data(), tmp.data() + k, row + p);
    }
    // Rows ≥ p are re-triangularized in the new column order: they become rows of a stacked
    // update onto an empty factor, sorted by their first column in the new order.
    std::vector<int> lead(static_cast<std::size_t>(k));
    int suffixMin = std::numeric_limits<int>::max();
    for (int i = n_ - 1; i >= p; --i) {
      suffixMin = std::min(suffixMin, newcol[static_cast<std::size_t>(i)] - p);
      lead[static_cast<std::size_t>(i - p)] = suffixMin;
    }
    std::vector<int> rowsOrder(static_cast<std::size_t>(k));
    std::iota(rowsOrder.begin(), rowsOrder.end(), 0);
    std::stable_sort(rowsOrder.begin(), rowsOrder.end(), [&](int a, int b) {
      return lead[static_cast<std::size_t>(a)] < lead[static_cast<std::size_t>(b)];
    });
    RowMatrix<Scalar> W = RowMatrix<Scalar>::Zero(k, k);
    Vector z(k);
    std::vector<int> sortedLead(static_cast<std::size_t>(k));
    for (int s = 0; s < k; ++s) {
      const int i = rowsOrder[static_cast<std::size_t>(s)] + p;
      const Scalar* row = rowPtr(i);
      for (int j = i; j < n_; ++j) W(s, newcol[static_cast<std::size_t>(j)] - p) = row[j];
      z(s) = rbuf_(off_ + i);
      sortedLead[static_cast<std::size_t>(s)] = lead[static_cast<std::size_t>(i - p)];
    }
    auto Rt = view(p, p, k, k);
    for (int i = 0; i < k; ++i) Rt.row(i).tail(k - i).setZero();
    auto rt = rview(p, k);
    rt.setZero();
    householderRowUpdate<Scalar>(Rt, rt,
                                 RowMatrixView<Scalar>(W.data(), k, k, Eigen::OuterStride<>(k)),
                                 VectorView<Scalar>(z.data(), k), sortedLead);
  }
  layout_ = std::move(next);
  estimates_ = std::move(est);
  if constexpr (!std::is_same_v<Scalar, double>) nominal_ = std::move(nom);
}

template <typename Scalar>
const BlockEstimate<Scalar>& SriFilter<Scalar>::estimate(BlockId id) const {
  return estimates_[static_cast<std::size_t>(position(id))];
}

template <typename Scalar>
const BlockEstimate<double>& SriFilter<Scalar>::nominal(BlockId id) const {
  if constexpr (std::is_same_v<Scalar, double>) {
    return estimates_[static_cast<std::size_t>(position(id))];
  } else {
    return nominal_[static_cast<std::size_t>(position(id))];
  }
}

template <typename Scalar>
void SriFilter<Scalar>::setNominal(BlockId id, const BlockEstimate<double>& value, double tolerance) {
  const int pos = position(id);
  const BlockInfo& b = layout_.at(pos);
  if (!hasShape(value, b.kind, b.dim)) {
    throw std::invalid_argument("sri::SriFilter::setNominal: value does not fit block '" + b.name + "'");
  }
  const auto d = boxminus<double>(b, value, nominal(id));
  if (!(d.cwiseAbs().maxCoeff() <= tolerance)) {
    throw std::invalid_argument("sri::SriFilter::setNominal: value of block '" + b.name +
                                "' is not the current estimate up to rounding");
  }
  storeNominal(pos, value);
}

template <typename Scalar>
void SriFilter<Scalar>::storeNominal(int pos, const BlockEstimate<double>& value) {
  if constexpr (std::is_same_v<Scalar, double>) {
    estimates_[static_cast<std::size_t>(pos)] = value;
  } else {
    nominal_[static_cast<std::size_t>(pos)] = value;
    estimates_[static_cast<std::size_t>(pos)] = castEstimate<Scalar>(value);
  }
}

template <typename Scalar>
void SriFilter<Scalar>::setEstimate(BlockId id, const BlockEstimate<Scalar>& value) {
  const int pos = position(id);
  const BlockInfo& b = layout_.at(pos);
  if (!hasShape(value, b.kind, b.dim)) {
    throw std::invalid_argument("sri::SriFilter::setEstimate: value does not fit block '" + b.name +
                                "'");
  }
  Vector delta;
  if constexpr (std::is_same_v<Scalar, double>) {
    delta = boxminus<Scalar>(b, value, estimates_[static_cast<std::size_t>(pos)]);
  } else {
    delta = boxminus<double>(b, castEstimate<double>(value), nominal_[static_cast<std::size_t>(pos)])
                .template cast<Scalar>();
  }
  // Prior mean x̂_old ⊞ R⁻¹r stays put: R(δ' + δ) − r = R δ' − (r − R δ).
  if (b.offset > 0) rview(0, b.offset).noalias() -= cview(0, b.offset, b.offset, b.dim) * delta;
  rview(b.offset, b.dim).noalias() -=
      cview(b.offset, b.offset, b.dim, b.dim).template triangularView<Eigen::Upper>() * delta;
  estimates_[static_cast<std::size_t>(pos)] = value;
  if constexpr (!std::is_same_v<Scalar, double>) {
    nominal_[static_cast<std::size_t>(pos)] = castEstimate<double>(value);
  }
}

template <typename Scalar>
std::vector<BlockId> SriFilter<Scalar>::propagate(const Propagation<Scalar>& step) {
  using MatrixT = Matrix;
  const int d = step.dim();
  if (d <= 0) throw std::invalid_argument("sri::SriFilter::propagate: no new blocks");
  if (step.noise().rows() != d || step.noise().cols() != d || !step.noise().allFinite()) {
    throw std::invalid_argument("sri::SriFilter::propagate: noise must be " + std::to_string(d) +
                                "×" + std::to_string(d));
  }
  if (step.residual().size() != 0 && step.residual().size() != d) {
    throw std::invalid_argument("sri::SriFilter::propagate: residual must have dim() entries");
  }
  for (const auto& [id, phi] : step.transitions()) {
    const BlockInfo& b = layout_.block(id);
    if (phi.rows() != d || phi.cols() != b.dim) {
      throw std::invalid_argument("sri::SriFilter::propagate: transition w.r.t. '" + b.name +
                                  "' must be " + std::to_string(d) + "×" + std::to_string(b.dim));
    }
  }
  for (BlockId id : step.marginalized()) (void)layout_.index(id);
  MatrixT S;
  if (step.noiseIsSqrtInformation()) {
    S = step.noise();
  } else {
    const auto L = choleskyLower<Scalar>(step.noise());
    if (!L) {
      throw std::invalid_argument(
          "sri::SriFilter::propagate: noise covariance is not positive definite");
    }
    S = MatrixT::Identity(d, d);
    solveLowerInPlace<Scalar>(*L, S);  // S = L⁻¹, SᵀS = Q'⁻¹
  }
  // Paper eq. (8) (and (21) for the clocks): rows [S Φ  −S], right-hand side −S e.
  Measurement<Scalar> rows(d);
  for (const auto& [id, phi] : step.transitions()) {
    rows.jacobian(id, layout_.block(id).dim) += S * phi;
  }
  if (step.residual().size() == d) rows.residual() = -(S * step.residual());
  std::vector<BlockId> ids;
  int row = 0;
  for (const auto& nb : step.newBlocks()) {
    ids.push_back(addBlock(nb.spec, nb.estimate, Prior<Scalar>::uninformative(), nb.placement));
    rows.jacobian(ids.back(), nb.spec.dim) = -S.middleCols(row, nb.spec.dim);
    row += nb.spec.dim;
  }
  rows.setWhitened();
  update(rows);
  marginalize(std::span<const BlockId>(step.marginalized()));
  return ids;
}

template <typename Scalar>
UpdateResult<Scalar> SriFilter<Scalar>::update(const Measurement<Scalar>& m,
                                               const UpdateOptions& options) {
  return update(std::span<const Measurement<Scalar>>(&m, 1), options);
}

template <typename Scalar>
UpdateResult<Scalar> SriFilter<Scalar>::update(std::span<const Measurement<Scalar>> parts,
                                               const UpdateOptions& options) {
  UpdateResult<Scalar> result;
  int rows = 0;
  Scalar discardedChi2 = 0;
  // Column offset of every block of every part in the state (parts in turn, blocks in order).
  std::vector<int> boff;
  for (const Measurement<Scalar>& m : parts) {
    if (!m.isWhitened()) throw std::logic_error("sri::SriFilter::update: rows are not whitened");
    if (m.nuisanceDim() != 0) {
      throw std::logic_error("sri::SriFilter::update: project the nuisance columns out first");
    }
    result.dof += m.rows() + m.discardedRows();
    discardedChi2 += m.discardedChiSquare();
    rows += m.rows();
    for (int b = 0; b < m.numBlocks(); ++b) {
      const BlockInfo& info = layout_.block(m.blockId(b));
      if (info.dim != m.blockDim(b)) {
        throw std::invalid_argument("sri::SriFilter::update: Jacobian of block '" + info.name +
                                    "' has the wrong number of columns");
      }
      boff.push_back(info.offset);
    }
  }
  // First non-zero column of every row (rows numbered through the parts in turn).
  std::vector<int> rowLead(static_cast<std::size_t>(rows), n_);
  {
    int r0 = 0;
    std::size_t bo = 0;
    for (const Measurement<Scalar>& m : parts) {
      for (int b = 0; b < m.numBlocks(); ++b) {
        const auto J = m.jacobianAt(b);
        const int o = boff[bo + static_cast<std::size_t>(b)];
        for (int i = 0; i < m.rows(); ++i) {
          int& l = rowLead[static_cast<std::size_t>(r0 + i)];
          if (o >= l) continue;
          for (int q = 0; q < J.cols() && o + q < l; ++q) {
            if (J(i, q) != Scalar(0)) {
              l = o + q;
              break;
            }
          }
        }
      }
      r0 += m.rows();
      bo += static_cast<std::size_t>(m.numBlocks());
    }
  }
  const int c0 = rows > 0 ? *std::min_element(rowLead.begin(), rowLead.end()) : n_;
  const int k = n_ - c0;
  std::vector<int> order(static_cast<std::size_t>(rows));
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return rowLead[static_cast<std::size_t>(a)] < rowLead[static_cast<std::size_t>(b)];
  });
  std::vector<int> slot(static_cast<std::size_t>(rows));  // sorted position of every row
  for (int s = 0; s < rows; ++s) slot[static_cast<std::size_t>(order[static_cast<std::size_t>(s)])] = s;
  // Stack [W z]: rows sorted by lead, columns c0..n−1.
  const std::size_t wsize = static_cast<std::size_t>(rows) * static_cast<std::size_t>(std::max(k, 1));
  if (static_cast<std::size_t>(work_.size()) < wsize) work_.resize(static_cast<Eigen::Index>(wsize), 1);
  if (work_z_.size() < rows) work_z_.resize(rows);
  RowMatrixView<Scalar> W(work_.data(), rows, k, Eigen::OuterStride<>(std::max(k, 1)));
  VectorView<Scalar> z(work_z_.data(), rows);
  lead_.resize(static_cast<std::size_t>(rows));
  if (k > 0) W.setZero();
  {
    int r0 = 0;
    std::size_t bo = 0;
    for (const Measurement<Scalar>& m : parts) {
      for (int i = 0; i < m.rows(); ++i) {
        const int s = slot[static_cast<std::size_t>(r0 + i)];
        z(s) = m.residual()(i);
        lead_[static_cast<std::size_t>(s)] = rowLead[static_cast<std::size_t>(r0 + i)] - c0;
      }
      for (int b = 0; b < m.numBlocks(); ++b) {
        // Columns of the block before c0 are zero in every row by the definition of c0.
        const auto J = m.jacobianAt(b);
        const int o = boff[bo + static_cast<std::size_t>(b)];
        const int skip = std::max(0, c0 - o);
        const int len = static_cast<int>(J.cols()) - skip;
        if (len <= 0) continue;
        for (int i = 0; i < m.rows(); ++i) {
          W.row(slot[static_cast<std::size_t>(r0 + i)]).segment(o + skip - c0, len) = J.row(i).tail(len);
        }
      }
      r0 += m.rows();
      bo += static_cast<std::size_t>(m.numBlocks());
    }
  }
  // Rotation scheme.
  RotationScheme scheme = options.scheme;
  if (scheme == RotationScheme::kAuto) {
    scheme = RotationScheme::kBlockedHouseholder;
    if (k > 0 && rows > 0) {
      const Scalar heavy = W.cwiseAbs().maxCoeff();
      Scalar light = std::numeric_limits<Scalar>::infinity();
      for (int j = c0; j < n_; ++j) {
        const Scalar a = std::abs(rowPtr(j)[j]);
        if (a > Scalar(0)) light = std::min(light, a);
      }
      const double limit = std::is_same_v<Scalar, float> ? options_.auto_givens_ratio_float
                                                         : options_.auto_givens_ratio_double;
      if (std::isfinite(light) && static_cast<double>(heavy) > limit * static_cast<double>(light)) {
        scheme = RotationScheme::kGivens;
      }
    }
  }
  result.scheme = scheme;
  bool gated = std::isfinite(options.max_chi2);
  for (int j = c0; j < n_ && gated; ++j) gated = rowPtr(j)[j] != Scalar(0);
  const bool backup = gated && k > 0 && rows > 0;  // rows touching no column change nothing
  if (backup) {
    gate_backup_.resize(k, k + 1);
    gate_backup_.leftCols(k) = view(c0, c0, k, k);
    gate_backup_.col(k) = rview(c0, k);
  }
  if (k > 0 && rows > 0) {
    if (scheme == RotationScheme::kGivens) {
      givensRowUpdate<Scalar>(view(c0, c0, k, k), rview(c0, k), W, z, lead_);
    } else {
      householderRowUpdate<Scalar>(view(c0, c0, k, k), rview(c0, k), W, z, lead_);
    }
  }
  result.chi2 = z.squaredNorm() + discardedChi2;
  if (gated && static_cast<double>(result.chi2) > options.max_chi2) {
    if (backup) {
      view(c0, c0, k, k) = gate_backup_.leftCols(k);
      rview(c0, k) = gate_backup_.col(k);
    }
    result.applied = false;
  }
  return result;
}

template <typename Scalar>
std::optional<ChiSquare<Scalar>> SriFilter<Scalar>::chiSquare(const Measurement<Scalar>& m) const {
  if (!m.isWhitened()) throw std::logic_error("sri::SriFilter::chiSquare: rows are not whitened");
  if (m.nuisanceDim() != 0) {
    throw std::logic_error("sri::SriFilter::chiSquare: project the nuisance columns out first");
  }
  ChiSquare<Scalar> out;
  out.dof = m.rows() + m.discardedRows();
  const int rows = m.rows();
  const int nb = m.numBlocks();
  int c0 = n_;
  std::vector<int> boff(static_cast<std::size_t>(nb));
  for (int b = 0; b < nb; ++b) {
    const BlockInfo& info = layout_.block(m.blockId(b));
    if (info.dim != m.blockDim(b)) {
      throw std::invalid_argument("sri::SriFilter::chiSquare: Jacobian of block '" + info.name +
                                  "' has the wrong number of columns");
    }
    boff[static_cast<std::size_t>(b)] = info.offset;
    if (!m.jacobianAt(b).isZero(0)) c0 = std::min(c0, info.offset);
  }
  const int k0 = n_ - c0;
  // Y = J R⁻¹ vanishes before c0; Yᵀ = R_ttᵀ⁻¹ J_tᵀ on the trailing block.
  Matrix Jt = Matrix::Zero(k0, rows);
  for (int b = 0; b < nb; ++b) {
    const auto J = m.jacobianAt(b);
    if (boff[static_cast<std::size_t>(b)] < c0) continue;  // all zero
    Jt.middleRows(boff[static_cast<std::size_t>(b)] - c0, J.cols()) += J.transpose();
  }
  Vector zp = m.residual();
  if (k0 > 0 && rows > 0) {
    std::vector<int> keep;
    RowMatrix<Scalar> copy;
    const auto Rt = informedTrailing(c0, keep, copy);
    if (!Rt) return std::nullopt;
    const int k = static_cast<int>(keep.size());
    Matrix Yt(k, rows);
    Vector rt(k);
    std::vector<char> kept(static_cast<std::size_t>(k0), 0);
    for (int i = 0; i < k; ++i) {
      const int j = keep[static_cast<std::size_t>(i)];
      kept[static_cast<std::size_t>(j)] = 1;
      Yt.row(i) = Jt.row(j);
      rt(i) = rbuf_(off_ + c0 + j);
    }
    for (int j = 0; j < k0; ++j) {  // rows touching state without information
      if (!kept[static_cast<std::size_t>(j)] && !Jt.row(j).isZero(0)) return std::nullopt;
    }
    Rt->transpose().template triangularView<Eigen::Lower>().solveInPlace(Yt);
    // Predicted residual z' = z − J R⁻¹ r.
    zp.noalias() -= Yt.transpose() * rt;
    if (rows > k && k > 0) {
      // Many rows on few columns (e.g. a GNSS epoch: 130 rows on 28 columns): the same χ² in
      // the k-dimensional form min_x ‖x‖² + ‖Y x − z'‖² = z'ᵀ (I + YYᵀ)⁻¹ z', i.e. the rows
      // [Y z'] applied to a unit prior and the post-fit ‖e‖², O(rows·k²) instead of O(k·rows²).
      RowMatrix<Scalar> I = RowMatrix<Scalar>::Identity(k, k);
      Vector ri = Vector::Zero(k);
      RowMatrix<Scalar> W = Yt.transpose();
      std::vector<int> lead(static_cast<std::size_t>(rows), 0);
      householderRowUpdate<Scalar>(RowMatrixView<Scalar>(I.data(), k, k, Eigen::OuterStride<>(k)),
                                   VectorView<Scalar>(ri.data(), k),
                                   RowMatrixView<Scalar>(W.data(), rows, k, Eigen::OuterStride<>(k)),
                                   VectorView<Scalar>(zp.data(), rows), lead);
      out.value = zp.squaredNorm() + m.discardedChiSquare();
      return out;
    }
    // χ² = z'ᵀ (I + YYᵀ)⁻¹ z' with UᵀU = I + YYᵀ: QR of the rows of Yᵀ stacked under the
    // identity (qr_update.hpp), then w = U⁻ᵀ z' by forward substitution.
    RowMatrix<Scalar> U = RowMatrix<Scalar>::Identity(rows, rows);
    Vector ru = Vector::Zero(rows);
    RowMatrix<Scalar> W = Yt;
    Vector zw = Vector::Zero(k);
    std::vector<int> lead(static_cast<std::size_t>(k), 0);
    householderRowUpdate<Scalar>(
        RowMatrixView<Scalar>(U.data(), rows, rows, Eigen::OuterStride<>(rows)),
        VectorView<Scalar>(ru.data(), rows),
        RowMatrixView<Scalar>(W.data(), k, rows, Eigen::OuterStride<>(rows)),
        VectorView<Scalar>(zw.data(), k), lead);
    U.transpose().template triangularView<Eigen::Lower>().solveInPlace(zp);
  }
  out.value = zp.squaredNorm() + m.discardedChiSquare();
  return out;
}

template <typename Scalar>
bool SriFilter<Scalar>::hasZeroPivot(int from) const {
  Scalar maxd = 0;
  for (int j = from; j < n_; ++j) maxd = std::max(maxd, std::abs(rowPtr(j)[j]));
  const Scalar tol = static_cast<Scalar>(options_.zero_pivot) * maxd;
  for (int j = from; j < n_; ++j) {
    if (std::abs(rowPtr(j)[j]) <= tol) return true;
  }
  return false;
}

template <typename Scalar>
typename SriFilter<Scalar>::Vector SriFilter<Scalar>::solve() const {
  Vector dx = rbuf_.segment(off_, n_);
  if (n_ == 0) return dx;
  const auto R = cview(0, 0, n_, n_);
  if (!hasZeroPivot(0)) {
    R.template triangularView<Eigen::Upper>().solveInPlace(dx);
    return dx;
  }
  Scalar maxd = 0;
  for (int j = 0; j < n_; ++j) maxd = std::max(maxd, std::abs(rowPtr(j)[j]));
  const Scalar tol = static_cast<Scalar>(options_.zero_pivot) * maxd;
  for (int j = n_ - 1; j >= 0; --j) {
    const Scalar* row = rowPtr(j);
    const Scalar piv = row[j];
    if (std::abs(piv) <= tol) {
      dx(j) = 0;
      continue;
    }
    Scalar s = dx(j);
    if (j + 1 < n_) s -= R.row(j).tail(n_ - j - 1).dot(dx.tail(n_ - j - 1));
    dx(j) = s / piv;
  }
  return dx;
}

template <typename Scalar>
void SriFilter<Scalar>::correct() {
  if (n_ == 0) return;
  const Vector dx = solve();
  if constexpr (std::is_same_v<Scalar, double>) {
    for (int i = 0; i < layout_.size(); ++i) {
      const BlockInfo& b = layout_.at(i);
      boxplus<Scalar>(b, estimates_[static_cast<std::size_t>(i)], dx.segment(b.offset, b.dim));
    }
  } else {
    // Mixed precision: the correction is applied to the double value (sri_filter.hpp).
    const Eigen::VectorXd dxd = dx.template cast<double>();
    for (int i = 0; i < layout_.size(); ++i) {
      const BlockInfo& b = layout_.at(i);
      auto& nom = nominal_[static_cast<std::size_t>(i)];
      boxplus<double>(b, nom, dxd.segment(b.offset, b.dim));
      estimates_[static_cast<std::size_t>(i)] = castEstimate<Scalar>(nom);
    }
  }
  if (!hasZeroPivot(0)) {
    rview(0, n_).setZero();
  } else {
    rview(0, n_).noalias() -= cview(0, 0, n_, n_).template triangularView<Eigen::Upper>() * dx;
  }
}

template <typename Scalar>
std::optional<typename SriFilter<Scalar>::ConstView> SriFilter<Scalar>::informedTrailing(
    int c, std::vector<int>& keep, RowMatrix<Scalar>& copy) const {
  const int k = n_ - c;
  keep.clear();
  bool all = true;
  for (int j = c; j < n_; ++j) {
    if (rowPtr(j)[j] != Scalar(0)) {
      keep.push_back(j - c);
      continue;
    }
    // No information on this column: harmless only if it is decoupled from the others.
    bool coupled = false;
    for (int i = c; i < j && !coupled; ++i) coupled = rowPtr(i)[j] != Scalar(0);
    for (int q = j + 1; q < n_ && !coupled; ++q) coupled = rowPtr(j)[q] != Scalar(0);
    if (coupled) return std::nullopt;
    all = false;
  }
  if (all) return cview(c, c, k, k);
  const int kk = static_cast<int>(keep.size());
  copy.setZero(kk, kk);
  for (int a = 0; a < kk; ++a) {
    const Scalar* row = rowPtr(c + keep[static_cast<std::size_t>(a)]);
    for (int b = a; b < kk; ++b) copy(a, b) = row[c + keep[static_cast<std::size_t>(b)]];
  }
  return ConstView(copy.data(), kk, kk, Eigen::OuterStride<>(std::max(kk, 1)));
}

template <typename Scalar>
std::optional<typename SriFilter<Scalar>::ConstView> SriFilter<Scalar>::listedTrailing(
    std::span<const BlockId> ids, const char* who, std::vector<int>& columns, RowMatrix<Scalar>& copy) const {
  columns.clear();
  int c = n_;
  for (BlockId id : ids) c = std::min(c, layout_.block(id).offset);
  if (c == n_) return std::nullopt;
  std::vector<int> keep;
  const auto Rt = informedTrailing(c, keep, copy);
  if (!Rt) {
    throw std::domain_error(std::string("sri::SriFilter::") + who +
                            ": a later block without information is coupled to the others");
  }
  // Position of every trailing column in the reduced factor (−1: dropped).
  std::vector<int> pos(static_cast<std::size_t>(n_ - c), -1);
  for (std::size_t a = 0; a < keep.size(); ++a) pos[static_cast<std::size_t>(keep[a])] = static_cast<int>(a);
  for (BlockId id : ids) {
    const BlockInfo& b = layout_.block(id);
    for (int q = 0; q < b.dim; ++q) {
      const int p = pos[static_cast<std::size_t>(b.offset - c + q)];
      if (p < 0) throw std::domain_error(std::string("sri::SriFilter::") + who + ": block '" + b.name + "' has no information");
      columns.push_back(p);
    }
  }
  return Rt;
}

template <typename Scalar>
bool SriFilter<Scalar>::informed(std::span<const BlockId> ids) const {
  // The conditions under which listedTrailing() throws, without throwing.
  int c = n_;
  for (BlockId id : ids) c = std::min(c, layout_.block(id).offset);
  if (c == n_) return true;  // no columns listed: an empty covariance
  std::vector<int> keep;
  RowMatrix<Scalar> copy;
  if (!informedTrailing(c, keep, copy)) return false;
  for (BlockId id : ids) {
    const BlockInfo& b = layout_.block(id);
    for (int q = b.offset; q < b.offset + b.dim; ++q) {
      if (rowPtr(q)[q] == Scalar(0)) return false;  // a column informedTrailing() drops
    }
  }
  return true;
}

template <typename Scalar>
typename SriFilter<Scalar>::Matrix SriFilter<Scalar>::covariance(
    std::span<const BlockId> ids) const {
  std::vector<int> cols;
  RowMatrix<Scalar> copy;
  const auto Rt = listedTrailing(ids, "covariance", cols, copy);
  if (!Rt) return Matrix();
  const int s = static_cast<int>(cols.size());
  Matrix Y = Matrix::Zero(Rt->rows(), s);
  for (int col = 0; col < s; ++col) Y(cols[static_cast<std::size_t>(col)], col) = Scalar(1);
  Rt->transpose().template triangularView<Eigen::Lower>().solveInPlace(Y);
  return Y.transpose() * Y;
}

template <typename Scalar>
typename SriFilter<Scalar>::Matrix SriFilter<Scalar>::covarianceFactor(
    std::span<const BlockId> ids) const {
  std::vector<int> cols;
  RowMatrix<Scalar> copy;
  const auto Rt = listedTrailing(ids, "covarianceFactor", cols, copy);
  if (!Rt) return Matrix();
  const int k = static_cast<int>(Rt->rows());
  const Matrix X = upperTriangularInverse<Scalar>(*Rt);
  Matrix F(static_cast<Eigen::Index>(cols.size()), k);
  for (std::size_t r = 0; r < cols.size(); ++r) F.row(static_cast<Eigen::Index>(r)) = X.row(cols[r]);
  return F;
}

template <typename Scalar>
typename SriFilter<Scalar>::Matrix SriFilter<Scalar>::fullCovariance() const {
  Matrix Rinv = Matrix::Identity(n_, n_);
  if (n_ == 0) return Rinv;
  cview(0, 0, n_, n_).template triangularView<Eigen::Upper>().solveInPlace(Rinv);
  return Rinv * Rinv.transpose();
}

template <typename Scalar>
typename SriFilter<Scalar>::Matrix SriFilter<Scalar>::squareRootInformation() const {
  Matrix R = Matrix::Zero(n_, n_);
  if (n_ > 0) R = cview(0, 0, n_, n_).template triangularView<Eigen::Upper>();
  return R;
}

template <typename Scalar>
typename SriFilter<Scalar>::Vector SriFilter<Scalar>::residual() const {
  return rbuf_.segment(off_, n_);
}

template class SriFilter<float>;
template class SriFilter<double>;

}  // namespace gvins::sri
