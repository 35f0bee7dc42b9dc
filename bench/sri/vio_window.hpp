// A synthetic SRI-SWF state of realistic structure for the benchmarks: SLAM features
// (3 each), IMU pose clones (6 each), parameters (camera–IMU extrinsics 6, GNSS lever arm 3,
// receiver clocks 4, clock drift 1) and the IMU extra state (9), filled with a dense random
// upper-triangular square-root information; and measurement rows like those of a VIO update
// (MSCKF rows on the recent clones and the extrinsics, SLAM rows on one feature, the newest
// clone and the extrinsics).
#pragma once

#include <algorithm>
#include <random>
#include <vector>

#include <Eigen/Core>

#include "gvins/sri/sri_filter.hpp"

namespace gvins::sri::bench {

enum class Order {
  kPaper,       ///< [features | clones (oldest first) | parameters | extra]  (paper, eq. (1))
  kClonesFirst  ///< [clones (oldest first) | features | parameters | extra]
};

struct WindowSpec {
  int n = 300;
  int clones = 20;
};

inline WindowSpec windowFor(int n) {
  if (n <= 150) return {n, 10};
  if (n <= 300) return {n, 20};
  return {n, 25};
}

template <typename S>
struct Window {
  SriFilter<S> filter;
  std::vector<BlockId> features, clones;
  BlockId extrinsic, lever, clocks, extra;
  int paramsDim = 0;
};

template <typename S>
void fillRandomFactor(SriFilter<S>& f, std::mt19937& rng) {
  std::normal_distribution<double> g(0.0, 0.1);
  std::uniform_real_distribution<double> u(1.0, 3.0);
  auto R = f.rawR();
  const int n = static_cast<int>(R.rows());
  for (int i = 0; i < n; ++i) {
    R(i, i) = static_cast<S>(u(rng));
    for (int j = i + 1; j < n; ++j) R(i, j) = static_cast<S>(g(rng));
  }
  f.rawResidual().setZero();
}

/// Builds a window of total dimension spec.n (clock block absorbs the remainder).
template <typename S>
void buildWindow(Window<S>& w, const WindowSpec& spec, Order order, unsigned seed = 7) {
  const int fixed = 6 * spec.clones + 6 + 3 + 9;
  const int nfeat = (spec.n - fixed - 5) / 3;
  const int clockDim = spec.n - fixed - 3 * nfeat - 1;  // ≥ 4 with the sizes used here
  w.filter.reserve(spec.n + 64);
  auto add = [&](const BlockSpec& s) {
    return w.filter.addBlock(s, BlockEstimate<S>::zero(s.kind, s.dim), Prior<S>::stdDev(s.dim, S(1)));
  };
  auto addFeatures = [&] {
    for (int i = 0; i < nfeat; ++i) w.features.push_back(add(BlockSpec::vector("feature", 3)));
  };
  auto addClones = [&] {
    for (int i = 0; i < spec.clones; ++i) w.clones.push_back(add(BlockSpec::pose("clone")));
  };
  if (order == Order::kPaper) {
    addFeatures();
    addClones();
  } else {
    addClones();
    addFeatures();
  }
  w.extrinsic = add(BlockSpec::pose("T_CI"));
  w.lever = add(BlockSpec::vector("lever", 3));
  w.clocks = add(BlockSpec::vector("clocks", clockDim));
  add(BlockSpec::vector("drift", 1));
  w.extra = add(BlockSpec::vector("extra", 9));
  std::mt19937 rng(seed);
  fillRandomFactor(w.filter, rng);
}

/// m whitened rows: ~80 % MSCKF rows (last 8 clones + extrinsics), the rest SLAM re-observations
/// (2 rows per feature: one feature, the newest clone, the extrinsics).
template <typename S>
Measurement<S> vioRows(const Window<S>& w, int m, unsigned seed = 11) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  auto randm = [&](int r, int c) {
    Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic> a(r, c);
    for (int i = 0; i < r; ++i) {
      for (int j = 0; j < c; ++j) a(i, j) = static_cast<S>(g(rng));
    }
    return a;
  };
  auto randv = [&](Eigen::Matrix<S, Eigen::Dynamic, 1>& v) {
    for (Eigen::Index i = 0; i < v.size(); ++i) v(i) = static_cast<S>(g(rng));
  };
  const int slamRows = 2 * std::max(1, m / 10);
  const int msckfRows = m - slamRows;
  Measurement<S> all(0);
  all.setWhitened();
  {
    Measurement<S> z(msckfRows);
    const int nc = static_cast<int>(w.clones.size());
    for (int c = std::max(0, nc - 8); c < nc; ++c) z.jacobian(w.clones[static_cast<std::size_t>(c)], 6) = randm(msckfRows, 6);
    z.jacobian(w.extrinsic, 6) = randm(msckfRows, 6);
    randv(z.residual());
    z.setWhitened();
    all.stack(z);
  }
  std::uniform_int_distribution<int> pickFeature(0, static_cast<int>(w.features.size()) - 1);
  for (int f = 0; f < slamRows / 2; ++f) {
    Measurement<S> z(2);
    z.jacobian(w.features[static_cast<std::size_t>(pickFeature(rng))], 3) = randm(2, 3);
    z.jacobian(w.clones.back(), 6) = randm(2, 6);
    z.jacobian(w.extrinsic, 6) = randm(2, 6);
    randv(z.residual());
    z.setWhitened();
    all.stack(z);
  }
  return all;
}

/// The same rows as a dense m × n matrix over the whole state (for the dense competitors).
template <typename S>
Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic> denseRows(const SriFilter<S>& f, const Measurement<S>& z) {
  Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic> H =
      Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic>::Zero(z.rows(), f.dim());
  for (int b = 0; b < z.numBlocks(); ++b) {
    const BlockInfo& info = f.layout().block(z.blockId(b));
    H.middleCols(info.offset, info.dim) = z.jacobianAt(b);
  }
  return H;
}

}  // namespace gvins::sri::bench
