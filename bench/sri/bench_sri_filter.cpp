// Speed of the SRI core on sliding-window states of n = 150/300/400 with m = 40/60 new rows
// (vio_window.hpp), in float and double:
//   Update          SriFilter::update (blocked Householder, rows scattered and sorted by lead)
//   UpdateGivens    the same with Givens rotations (the row-wise stable path)
//   DenseQR         Eigen::HouseholderQR of the whole stack [R r; W z], (n+m) × (n+1)
//   EkfUpdate       covariance-form EKF update of the same rows (P Hᵀ on the touched columns,
//                   S, Cholesky, P ← P − K (P Hᵀ)ᵀ)
//   MargOldestClone SriFilter::marginalize of the oldest clone, paper order (after the features)
//                   or clones-first order (a free prefix drop); a new clone is appended each
//                   iteration to keep n constant (included in the time)
//   MargDenseQR     the naive alternative: permute the clone first and HouseholderQR all of R
//   EkfMarg         covariance form: delete the clone's rows and columns of P
//   Solve           back-substitution R Δx = r
//   SweepStride     sweepColumnsToFront alone, the IMU propagation's marginalization (9 columns
//                   18 from the end of a dense n = 240 factor moved to the front), with the
//                   factor stored at a row stride of 240 to 1032 elements: a
//                   4 KiB stride (512 doubles, 1024 floats) puts the rotated rows in one L1 set, which
//                   is why SriFilter pads its stride to an odd number of cache lines
//   KernelSlamRows  householderRowUpdate alone on the shape of the VIO bench's SLAM update
//                   (n = 240: 50 features of 3 in front of 90 window columns; 3 rows per
//                   feature from its column on, 50 rows from the window on): kernel speed
//                   in GFLOP/s, with the kernel's flop count 4·Σ_c rows(c)·(n − c)
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <deque>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/QR>

#include "gvins/sri/qr_update.hpp"
#include "vio_window.hpp"

namespace gvins::sri::bench {
namespace {

template <typename S>
void BM_Update(benchmark::State& state) {
  Window<S> w;
  buildWindow(w, windowFor(static_cast<int>(state.range(0))), Order::kPaper);
  const Measurement<S> z = vioRows(w, static_cast<int>(state.range(1)));
  UpdateOptions opt;
  opt.scheme = RotationScheme::kBlockedHouseholder;
  for (auto _ : state) {
    auto res = w.filter.update(z, opt);
    benchmark::DoNotOptimize(res);
  }
}

template <typename S>
void BM_KernelSlamRows(benchmark::State& state) {
  constexpr int kFeatures = 50;
  constexpr int kWindow = 90;
  const int n = 3 * kFeatures + kWindow;
  const int m = 3 * kFeatures + kFeatures;
  RowMatrix<S> R0 = RowMatrix<S>::Random(n, n);
  R0 = R0.template triangularView<Eigen::Upper>();
  R0.diagonal().array() += S(4);
  RowMatrix<S> W0 = RowMatrix<S>::Random(m, n);
  std::vector<int> lead(static_cast<std::size_t>(m));
  for (int i = 0; i < m; ++i) {
    lead[static_cast<std::size_t>(i)] = i < 3 * kFeatures ? 3 * (i / 3) : 3 * kFeatures;
    W0.row(i).head(lead[static_cast<std::size_t>(i)]).setZero();
  }
  Eigen::Matrix<S, Eigen::Dynamic, 1> r0 = Eigen::Matrix<S, Eigen::Dynamic, 1>::Random(n);
  Eigen::Matrix<S, Eigen::Dynamic, 1> z0 = Eigen::Matrix<S, Eigen::Dynamic, 1>::Random(m);
  RowMatrix<S> R = R0, W = W0;
  Eigen::Matrix<S, Eigen::Dynamic, 1> r = r0, z = z0;
  double flops = 0;
  for (int c = 0, a = 0; c < n; ++c) {
    while (a < m && lead[static_cast<std::size_t>(a)] <= c) ++a;
    flops += 4.0 * a * (n - c);
  }
  for (auto _ : state) {
    R = R0;
    W = W0;
    r = r0;
    z = z0;
    const auto t0 = std::chrono::steady_clock::now();
    householderRowUpdate<S>(RowMatrixView<S>(R.data(), n, n, Eigen::OuterStride<>(n)), VectorView<S>(r.data(), n),
                            RowMatrixView<S>(W.data(), m, n, Eigen::OuterStride<>(n)), VectorView<S>(z.data(), m),
                            lead);
    const auto t1 = std::chrono::steady_clock::now();
    state.SetIterationTime(std::chrono::duration<double>(t1 - t0).count());
    benchmark::DoNotOptimize(R.data());
  }
  state.counters["GFLOPs"] = benchmark::Counter(flops * 1e-9 * static_cast<double>(state.iterations()),
                                                benchmark::Counter::kIsRate);
}

template <typename S>
void BM_UpdateGivens(benchmark::State& state) {
  Window<S> w;
  buildWindow(w, windowFor(static_cast<int>(state.range(0))), Order::kPaper);
  const Measurement<S> z = vioRows(w, static_cast<int>(state.range(1)));
  UpdateOptions opt;
  opt.scheme = RotationScheme::kGivens;
  for (auto _ : state) {
    auto res = w.filter.update(z, opt);
    benchmark::DoNotOptimize(res);
  }
}

template <typename S>
void BM_DenseQR(benchmark::State& state) {
  using Mat = Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic>;
  Window<S> w;
  buildWindow(w, windowFor(static_cast<int>(state.range(0))), Order::kPaper);
  const Measurement<S> z = vioRows(w, static_cast<int>(state.range(1)));
  const int n = w.filter.dim();
  const int m = z.rows();
  Mat A = Mat::Zero(n + m, n + 1);
  A.topLeftCorner(n, n) = w.filter.squareRootInformation();
  A.topRightCorner(n, 1) = w.filter.residual();
  A.bottomLeftCorner(m, n) = denseRows(w.filter, z);
  A.bottomRightCorner(m, 1) = z.residual();
  Mat B(n + m, n + 1);
  Eigen::HouseholderQR<Mat> qr(n + m, n + 1);
  for (auto _ : state) {
    B = A;
    qr.compute(B);
    benchmark::DoNotOptimize(qr.matrixQR().data());
  }
}

template <typename S>
void BM_EkfUpdate(benchmark::State& state) {
  using Mat = Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic>;
  using Vec = Eigen::Matrix<S, Eigen::Dynamic, 1>;
  Window<S> w;
  buildWindow(w, windowFor(static_cast<int>(state.range(0))), Order::kPaper);
  const Measurement<S> z = vioRows(w, static_cast<int>(state.range(1)));
  const int n = w.filter.dim();
  const int m = z.rows();
  const Mat P0 = w.filter.fullCovariance();
  const Mat H = denseRows(w.filter, z);
  int c0 = n;
  for (int j = 0; j < n && c0 == n; ++j) {
    if (!H.col(j).isZero(0)) c0 = j;
  }
  const int k = n - c0;
  const Mat Ht = H.rightCols(k);
  Mat P = P0;
  Vec x = Vec::Zero(n);
  Mat PHt(n, m);
  Mat Sm(m, m);
  Mat K(n, m);
  const Vec r = z.residual();
  for (auto _ : state) {
    PHt.noalias() = P.rightCols(k) * Ht.transpose();
    Sm.noalias() = Ht * PHt.bottomRows(k);
    Sm.diagonal().array() += S(1);
    Eigen::LLT<Mat> llt(Sm);
    K = llt.solve(PHt.transpose()).transpose();
    x.noalias() += K * r;
    P.noalias() -= K * PHt.transpose();
    benchmark::DoNotOptimize(P.data());
    state.PauseTiming();
    P = P0;  // keep it positive definite
    state.ResumeTiming();
  }
}

template <typename S>
void BM_MargOldestClone(benchmark::State& state) {
  Window<S> w;
  const Order order = state.range(1) == 0 ? Order::kPaper : Order::kClonesFirst;
  buildWindow(w, windowFor(static_cast<int>(state.range(0))), order);
  std::deque<BlockId> clones(w.clones.begin(), w.clones.end());
  const Prior<S> prior = Prior<S>::stdDev(6, S(1));
  const auto zero = BlockEstimate<S>::zero(BlockKind::kPose, 6);
  for (auto _ : state) {
    w.filter.marginalize(clones.front());
    clones.pop_front();
    // Keep n constant: a new clone after the last one.
    clones.push_back(w.filter.addBlock(BlockSpec::pose("clone"), zero, prior,
                                       Placement::after(clones.back())));
  }
}

template <typename S>
void BM_MargDenseQR(benchmark::State& state) {
  using Mat = Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic>;
  Window<S> w;
  buildWindow(w, windowFor(static_cast<int>(state.range(0))), Order::kPaper);
  const int n = w.filter.dim();
  const BlockInfo& c = w.filter.layout().block(w.clones.front());
  const Mat R = w.filter.squareRootInformation();
  // Columns [clone | everything else | r].
  Mat A(n, n + 1);
  A.leftCols(c.dim) = R.middleCols(c.offset, c.dim);
  A.middleCols(c.dim, c.offset) = R.leftCols(c.offset);
  A.middleCols(c.offset + c.dim, n - c.offset - c.dim) = R.rightCols(n - c.offset - c.dim);
  A.col(n) = w.filter.residual();
  Mat B(n, n + 1);
  Eigen::HouseholderQR<Mat> qr(n, n + 1);
  for (auto _ : state) {
    B = A;
    qr.compute(B);
    benchmark::DoNotOptimize(qr.matrixQR().data());
  }
}

template <typename S>
void BM_EkfMarg(benchmark::State& state) {
  using Mat = Eigen::Matrix<S, Eigen::Dynamic, Eigen::Dynamic>;
  Window<S> w;
  buildWindow(w, windowFor(static_cast<int>(state.range(0))), Order::kPaper);
  const int n = w.filter.dim();
  const BlockInfo& c = w.filter.layout().block(w.clones.front());
  const Mat P = w.filter.fullCovariance();
  Mat Q(n - 6, n - 6);
  const int o = c.offset;
  const int t = n - o - 6;
  for (auto _ : state) {
    Q.topLeftCorner(o, o) = P.topLeftCorner(o, o);
    Q.topRightCorner(o, t) = P.topRightCorner(o, t);
    Q.bottomLeftCorner(t, o) = P.bottomLeftCorner(t, o);
    Q.bottomRightCorner(t, t) = P.bottomRightCorner(t, t);
    benchmark::DoNotOptimize(Q.data());
  }
}

template <typename S>
void BM_Solve(benchmark::State& state) {
  Window<S> w;
  buildWindow(w, windowFor(static_cast<int>(state.range(0))), Order::kPaper);
  w.filter.rawResidual().setOnes();
  for (auto _ : state) {
    auto dx = w.filter.solve();
    benchmark::DoNotOptimize(dx.data());
  }
}

void sizes(benchmark::internal::Benchmark* b) {
  for (int n : {150, 300, 400}) {
    for (int m : {40, 60}) b->Args({n, m});
  }
  b->Unit(benchmark::kMicrosecond);
  // Other engineers share the 2 cores: run with --benchmark_repetitions and read min/median.
  b->ComputeStatistics("min", [](const std::vector<double>& v) {
    return *std::min_element(v.begin(), v.end());
  });
}
// A well-conditioned n × n upper triangle (pseudo-random entries, diagonal + 4) stored with row
// stride ld, for the sweep benchmarks.
template <typename S>
RowMatrix<S> sweepFactor(int n, int ld) {
  RowMatrix<S> buf = RowMatrix<S>::Zero(n, ld);
  std::uint32_t seed = 12345;
  for (int i = 0; i < n; ++i) {
    for (int j = i; j < n; ++j) {
      seed = seed * 1664525u + 1013904223u;
      buf(i, j) = static_cast<S>(static_cast<double>(seed >> 8) / 16777216.0 - 0.5);
    }
    buf(i, i) += S(4);
  }
  return buf;
}

template <typename S>
void BM_SweepStride(benchmark::State& state) {
  const int n = 240;
  const int ld = static_cast<int>(state.range(0));
  constexpr int d = 9;
  const int c = n - 2 * d;
  RowMatrix<S> buf = sweepFactor<S>(n, ld);
  Eigen::Matrix<S, Eigen::Dynamic, 1> r = Eigen::Matrix<S, Eigen::Dynamic, 1>::Ones(n);
  RowMatrixView<S> R(buf.data(), n, n, Eigen::OuterStride<>(ld));
  for (auto _ : state) {
    sweepColumnsToFront<S>(R, VectorView<S>(r.data(), n), c, d, 0);
    benchmark::DoNotOptimize(buf.data());
  }
  state.counters["stride_bytes"] = static_cast<double>(ld) * static_cast<double>(sizeof(S));
}

// The same sweep with d columns (n = 240, the block d columns from the back): what one pass of d
// columns costs against d passes of one, i.e. whether merging marginalizations pays.
template <typename S>
void BM_SweepWidth(benchmark::State& state) {
  const int n = 240;
  const int d = static_cast<int>(state.range(0));
  const int c = n - d;
  RowMatrix<S> buf = sweepFactor<S>(n, n);
  Eigen::Matrix<S, Eigen::Dynamic, 1> r = Eigen::Matrix<S, Eigen::Dynamic, 1>::Ones(n);
  RowMatrixView<S> R(buf.data(), n, n, Eigen::OuterStride<>(n));
  for (auto _ : state) {
    sweepColumnsToFront<S>(R, VectorView<S>(r.data(), n), c, d, 0);
    benchmark::DoNotOptimize(buf.data());
  }
  state.counters["us_per_column"] = benchmark::Counter(static_cast<double>(d), benchmark::Counter::kIsIterationInvariantRate |
                                                                                 benchmark::Counter::kInvert);
}
BENCHMARK(BM_SweepWidth<double>)->Arg(1)->Arg(3)->Arg(6)->Arg(9)->Arg(18)->Arg(24)->Unit(benchmark::kMicrosecond);

void strideSizes(benchmark::internal::Benchmark* b) {
  for (int ld : {240, 256, 264, 512, 520, 1024, 1032}) b->Args({ld});
  b->Unit(benchmark::kMicrosecond);
}

void margSizes(benchmark::internal::Benchmark* b) {
  for (int n : {150, 300, 400}) {
    for (int order : {0, 1}) b->Args({n, order});
  }
  b->Unit(benchmark::kMicrosecond);
  // Other engineers share the 2 cores: run with --benchmark_repetitions and read min/median.
  b->ComputeStatistics("min", [](const std::vector<double>& v) {
    return *std::min_element(v.begin(), v.end());
  });
}
void nSizes(benchmark::internal::Benchmark* b) {
  for (int n : {150, 300, 400}) b->Args({n});
  b->Unit(benchmark::kMicrosecond);
  // Other engineers share the 2 cores: run with --benchmark_repetitions and read min/median.
  b->ComputeStatistics("min", [](const std::vector<double>& v) {
    return *std::min_element(v.begin(), v.end());
  });
}

BENCHMARK(BM_Update<double>)->Apply(sizes);
BENCHMARK(BM_Update<float>)->Apply(sizes);
BENCHMARK(BM_UpdateGivens<double>)->Apply(sizes);
BENCHMARK(BM_UpdateGivens<float>)->Apply(sizes);
BENCHMARK(BM_DenseQR<double>)->Apply(sizes);
BENCHMARK(BM_DenseQR<float>)->Apply(sizes);
BENCHMARK(BM_EkfUpdate<double>)->Apply(sizes);
BENCHMARK(BM_EkfUpdate<float>)->Apply(sizes);
BENCHMARK(BM_MargOldestClone<double>)->Apply(margSizes);
BENCHMARK(BM_MargOldestClone<float>)->Apply(margSizes);
BENCHMARK(BM_MargDenseQR<double>)->Apply(nSizes);
BENCHMARK(BM_MargDenseQR<float>)->Apply(nSizes);
BENCHMARK(BM_EkfMarg<double>)->Apply(nSizes);
BENCHMARK(BM_EkfMarg<float>)->Apply(nSizes);
BENCHMARK(BM_Solve<double>)->Apply(nSizes);
BENCHMARK(BM_Solve<float>)->Apply(nSizes);
BENCHMARK(BM_SweepStride<double>)->Apply(strideSizes);
BENCHMARK(BM_SweepStride<float>)->Apply(strideSizes);
BENCHMARK(BM_KernelSlamRows<double>)->UseManualTime()->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_KernelSlamRows<float>)->UseManualTime()->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace gvins::sri::bench

BENCHMARK_MAIN();
