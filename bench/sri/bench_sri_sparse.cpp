// Does SuiteSparse pay for the SRI core? Two kinds of problems:
//
// 1. FilterUpdate: the filter's update, [R; W] with R the dense upper-triangular factor of a
//    sliding window (n = 150/300/400, m = 60 VIO rows): SPQR on the stacked sparse matrix vs the
//    structured dense update (SriFilter::update). R of a marginalizing filter is dense, so a
//    sparse factorization has nothing to exploit.
// 2. Batch: the square-root information of a window built from scratch from sparse rows (each of
//    nf features seen by 5 of nc clones, 2 rows per observation, weak priors on everything), as
//    in a batch initialization: the dense structured kernel (rows sorted by lead, features first)
//    vs SuiteSparseQR (SPQR, COLAMD ordering), CHOLMOD supernodal Cholesky of AᵀA, and Eigen's
//    own SparseQR. The window grows until sparse wins.
//
// SuiteSparse 5 has no single precision, so float is dense-only in any case.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <numeric>
#include <random>
#include <vector>

#include <Eigen/CholmodSupport>
#include <Eigen/OrderingMethods>
#include <Eigen/SPQRSupport>
#include <Eigen/SparseCore>
#include <Eigen/SparseQR>

#include "gvins/sri/qr_update.hpp"
#include "vio_window.hpp"

namespace gvins::sri::bench {
namespace {

using SpMat = Eigen::SparseMatrix<double>;

// ---------------------------------------------------------------- 1. filter update

SpMat stackedSparse(const Window<double>& w, const Measurement<double>& z) {
  const Eigen::MatrixXd R = w.filter.squareRootInformation();
  const Eigen::MatrixXd H = denseRows(w.filter, z);
  const int n = static_cast<int>(R.rows());
  const int m = static_cast<int>(H.rows());
  std::vector<Eigen::Triplet<double>> t;
  for (int i = 0; i < n; ++i) {
    for (int j = i; j < n; ++j) {
      if (R(i, j) != 0) t.emplace_back(i, j, R(i, j));
    }
  }
  for (int i = 0; i < m; ++i) {
    for (int j = 0; j < n; ++j) {
      if (H(i, j) != 0) t.emplace_back(n + i, j, H(i, j));
    }
  }
  SpMat A(n + m, n);
  A.setFromTriplets(t.begin(), t.end());
  A.makeCompressed();
  return A;
}

void BM_FilterUpdateDense(benchmark::State& state) {
  Window<double> w;
  buildWindow(w, windowFor(static_cast<int>(state.range(0))), Order::kPaper);
  const Measurement<double> z = vioRows(w, 60);
  UpdateOptions opt;
  opt.scheme = RotationScheme::kBlockedHouseholder;
  for (auto _ : state) benchmark::DoNotOptimize(w.filter.update(z, opt));
}

void BM_FilterUpdateSpqr(benchmark::State& state) {
  Window<double> w;
  buildWindow(w, windowFor(static_cast<int>(state.range(0))), Order::kPaper);
  const SpMat A = stackedSparse(w, vioRows(w, 60));
  state.counters["nnz"] = static_cast<double>(A.nonZeros());
  for (auto _ : state) {
    Eigen::SPQR<SpMat> qr(A);
    benchmark::DoNotOptimize(qr.rank());
  }
}

// ---------------------------------------------------------------- 2. batch problems

struct Batch {
  int n = 0;
  int m = 0;
  std::vector<Eigen::Triplet<double>> t;  // rows in any order
  Eigen::VectorXd b;
};

/// Features first (3 columns each), then clones (6 each).
Batch makeBatch(int nf, int nc, unsigned seed = 3) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  std::uniform_int_distribution<int> clone(0, nc - 1);
  Batch B;
  B.n = 3 * nf + 6 * nc;
  int row = 0;
  for (int f = 0; f < nf; ++f) {
    std::vector<int> seen;
    while (static_cast<int>(seen.size()) < std::min(5, nc)) {
      const int c = clone(rng);
      if (std::find(seen.begin(), seen.end(), c) == seen.end()) seen.push_back(c);
    }
    for (int c : seen) {
      for (int r = 0; r < 2; ++r, ++row) {
        for (int q = 0; q < 3; ++q) B.t.emplace_back(row, 3 * f + q, g(rng));
        for (int q = 0; q < 6; ++q) B.t.emplace_back(row, 3 * nf + 6 * c + q, g(rng));
      }
    }
  }
  for (int j = 0; j < B.n; ++j, ++row) B.t.emplace_back(row, j, 0.1);  // weak priors
  B.m = row;
  B.b = Eigen::VectorXd::Ones(B.m);
  return B;
}

SpMat sparseOf(const Batch& B) {
  SpMat A(B.m, B.n);
  A.setFromTriplets(B.t.begin(), B.t.end());
  A.makeCompressed();
  return A;
}

void BM_BatchDense(benchmark::State& state) {
  const Batch B = makeBatch(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  const Eigen::MatrixXd Ad = Eigen::MatrixXd(sparseOf(B));
  // Rows sorted by their first non-zero column for the structured kernel.
  std::vector<int> lead(static_cast<std::size_t>(B.m));
  for (int i = 0; i < B.m; ++i) {
    int l = 0;
    while (l < B.n && Ad(i, l) == 0) ++l;
    lead[static_cast<std::size_t>(i)] = l;
  }
  std::vector<int> order(static_cast<std::size_t>(B.m));
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return lead[static_cast<std::size_t>(a)] < lead[static_cast<std::size_t>(b)];
  });
  RowMatrix<double> W0(B.m, B.n);
  std::vector<int> sortedLead(static_cast<std::size_t>(B.m));
  for (int s = 0; s < B.m; ++s) {
    W0.row(s) = Ad.row(order[static_cast<std::size_t>(s)]);
    sortedLead[static_cast<std::size_t>(s)] = lead[static_cast<std::size_t>(order[static_cast<std::size_t>(s)])];
  }
  RowMatrix<double> W(B.m, B.n);
  RowMatrix<double> R(B.n, B.n);
  Eigen::VectorXd r(B.n);
  Eigen::VectorXd z(B.m);
  state.counters["n"] = B.n;
  state.counters["m"] = B.m;
  for (auto _ : state) {
    W = W0;
    R.setZero();
    r.setZero();
    z = B.b;
    householderRowUpdate<double>(RowMatrixView<double>(R.data(), B.n, B.n, Eigen::OuterStride<>(B.n)),
                                 VectorView<double>(r.data(), B.n),
                                 RowMatrixView<double>(W.data(), B.m, B.n, Eigen::OuterStride<>(B.n)),
                                 VectorView<double>(z.data(), B.m), sortedLead);
    benchmark::DoNotOptimize(R.data());
  }
}

void BM_BatchSpqr(benchmark::State& state) {
  const Batch B = makeBatch(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  const SpMat A = sparseOf(B);
  state.counters["n"] = B.n;
  state.counters["m"] = B.m;
  for (auto _ : state) {
    Eigen::SPQR<SpMat> qr(A);
    benchmark::DoNotOptimize(qr.rank());
  }
}

void BM_BatchCholmod(benchmark::State& state) {
  const Batch B = makeBatch(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  const SpMat A = sparseOf(B);
  state.counters["n"] = B.n;
  for (auto _ : state) {
    const SpMat AtA = A.transpose() * A;
    Eigen::CholmodSupernodalLLT<SpMat> llt(AtA);
    benchmark::DoNotOptimize(llt.info());
  }
}

void BM_BatchEigenSparseQR(benchmark::State& state) {
  const Batch B = makeBatch(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  const SpMat A = sparseOf(B);
  state.counters["n"] = B.n;
  for (auto _ : state) {
    Eigen::SparseQR<SpMat, Eigen::COLAMDOrdering<int>> qr(A);
    benchmark::DoNotOptimize(qr.rank());
  }
}

void filterSizes(benchmark::internal::Benchmark* b) {
  for (int n : {150, 300, 400}) b->Args({n});
  b->Unit(benchmark::kMicrosecond);
  // Other engineers share the 2 cores: run with --benchmark_repetitions and read min/median.
  b->ComputeStatistics("min", [](const std::vector<double>& v) {
    return *std::min_element(v.begin(), v.end());
  });
}
void batchSizes(benchmark::internal::Benchmark* b) {
  for (int nc : {10, 20}) {
    for (int nf : {10, 25, 50, 100, 200}) b->Args({nf, nc});
  }
  b->Unit(benchmark::kMicrosecond);
  // Other engineers share the 2 cores: run with --benchmark_repetitions and read min/median.
  b->ComputeStatistics("min", [](const std::vector<double>& v) {
    return *std::min_element(v.begin(), v.end());
  });
}

BENCHMARK(BM_FilterUpdateDense)->Apply(filterSizes);
BENCHMARK(BM_FilterUpdateSpqr)->Apply(filterSizes);
BENCHMARK(BM_BatchDense)->Apply(batchSizes);
BENCHMARK(BM_BatchSpqr)->Apply(batchSizes);
BENCHMARK(BM_BatchCholmod)->Apply(batchSizes);
BENCHMARK(BM_BatchEigenSparseQR)->Apply(batchSizes);

}  // namespace
}  // namespace gvins::sri::bench

BENCHMARK_MAIN();
