// Micro-benchmarks of the RTK hot paths: the whole solver per epoch on the Nagoya data held in
// memory (kinematic continuous AR and instantaneous AR, no file I/O), and LAMBDA (factorization,
// reduction, search) on a single-epoch dual-frequency three-system problem of the Nagoya size.
// Whole-process timing against rnx2rtkp is bench_rtk.sh.
#include <benchmark/benchmark.h>

#include <cmath>
#include <fstream>
#include <random>
#include <vector>

#include "gvins/base/geodetic.hpp"
#include "gvins/base/rinex_obs_reader.hpp"
#include "gvins/ephemeris/rinex_nav.hpp"
#include "gvins/gnss/lambda.hpp"
#include "gvins/gnss/rtk.hpp"

namespace {
const std::string kData = GVINS_TEST_DATA;

struct Nagoya {
  std::vector<gvins::ObsEpoch> rover, base;
  gvins::RinexObsHeader roverHeader, baseHeader;
  gvins::EphemerisStore nav;
  Eigen::Vector3d basePosition;
};

const Nagoya& nagoya() {
  static const Nagoya d = [] {
    Nagoya s;
    const std::string dir = kData + "/gnss/nagoya_static_2024/";
    s.rover = gvins::readRinexObs(dir + "rover.obs.gz", &s.roverHeader);
    s.base = gvins::readRinexObs(dir + "base.obs.gz", &s.baseHeader);
    s.nav.add(gvins::readRinexNav(dir + "base.nav.gz"));
    std::ifstream f(dir + "base_position.txt");
    double lat = 0, lon = 0, h = 0;
    f >> lat >> lon >> h;
    s.basePosition = gvins::geodeticToEcef(gvins::geodeticFromDegrees(lat, lon, h));
    return s;
  }();
  return d;
}

/// One pass over the 301 epochs per iteration (base fed up to one epoch past the rover).
void BM_RtkNagoya(benchmark::State& st, gvins::AmbiguityMode mode) {
  const Nagoya& d = nagoya();
  gvins::RtkConfig cfg;
  cfg.ambiguityMode = mode;
  std::int64_t epochs = 0, fixed = 0;
  for (auto _ : st) {
    gvins::RtkSolver s(d.nav, cfg);
    s.setRoverGlonassChannels(d.roverHeader.glonassChannels);
    s.setBaseGlonassChannels(d.baseHeader.glonassChannels);
    s.setBasePosition(d.basePosition);
    std::size_t b = 0;
    for (const gvins::ObsEpoch& e : d.rover) {
      while (b < d.base.size() && (b == 0 || d.base[b - 1].time - e.time <= gvins::BaseStation::kSyncTolerance)) {
        s.addBaseEpoch(d.base[b++]);
      }
      const gvins::RtkSolution sol = s.process(e);
      fixed += sol.quality == gvins::SolutionQuality::Fix;
      ++epochs;
    }
  }
  st.counters["epochs/s"] = benchmark::Counter(static_cast<double>(epochs), benchmark::Counter::kIsRate);
  st.counters["fix_rate"] = static_cast<double>(fixed) / static_cast<double>(std::max<std::int64_t>(epochs, 1));
}
BENCHMARK_CAPTURE(BM_RtkNagoya, kinematic, gvins::AmbiguityMode::Continuous)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_RtkNagoya, instantaneous, gvins::AmbiguityMode::Instantaneous)->Unit(benchmark::kMillisecond);

/// Float DD ambiguities of one epoch: per system `sats` satellites (one reference), two
/// frequencies, phase 3 mm and code 30 cm (DD-correlated), random sky; returns the ambiguity
/// block of the inverse normal matrix of [position; ambiguities].
Eigen::MatrixXd singleEpochQ(std::mt19937& rng, const std::vector<int>& sats) {
  std::uniform_real_distribution<double> az(0.0, 6.283), el(0.27, 1.5);
  const double lambda[2] = {0.1903, 0.2442};
  int n = 0;
  for (int s : sats) n += 2 * (s - 1);
  Eigen::MatrixXd N = Eigen::MatrixXd::Zero(3 + n, 3 + n);
  int col = 3;
  for (int s : sats) {
    const int m = s - 1;
    std::vector<Eigen::Vector3d> u(static_cast<std::size_t>(s));
    for (auto& v : u) {
      const double a = az(rng), e = el(rng);
      v = Eigen::Vector3d(std::cos(e) * std::sin(a), std::cos(e) * std::cos(a), std::sin(e));
    }
    // DD covariance (unit): I + 11ᵀ for equal SD variances.
    const Eigen::MatrixXd W = (Eigen::MatrixXd::Identity(m, m) + Eigen::MatrixXd::Ones(m, m)).inverse();
    for (int f = 0; f < 2; ++f) {
      Eigen::MatrixXd Hp = Eigen::MatrixXd::Zero(m, 3 + n), Hc = Eigen::MatrixXd::Zero(m, 3 + n);
      for (int j = 0; j < m; ++j) {
        const Eigen::RowVector3d g = -(u[static_cast<std::size_t>(j) + 1] - u[0]).transpose();
        Hp.block<1, 3>(j, 0) = g;
        Hc.block<1, 3>(j, 0) = g;
        Hp(j, col + f * m + j) = lambda[f];
      }
      N += Hp.transpose() * W * Hp / (0.003 * 0.003) + Hc.transpose() * W * Hc / (0.3 * 0.3);
    }
    col += 2 * m;
  }
  return N.inverse().bottomRightCorner(n, n);
}

void BM_LambdaSingleEpoch(benchmark::State& st) {
  std::mt19937 rng(7);
  const Eigen::MatrixXd Q = singleEpochQ(rng, {12, 9, 12});  // 62 ambiguities
  const Eigen::MatrixXd L = Q.llt().matrixL();
  std::normal_distribution<double> g(0.0, 1.0);
  Eigen::VectorXd w(Q.rows());
  for (int i = 0; i < w.size(); ++i) w[i] = g(rng);
  const Eigen::VectorXd a = L * w;
  double perms = 0;
  for (auto _ : st) {
    const gvins::LambdaResult r = gvins::lambda(a, Q);
    perms = r.reduction.permutations;
    benchmark::DoNotOptimize(r.fixed);
  }
  st.counters["n"] = static_cast<double>(Q.rows());
  st.counters["permutations"] = perms;
}
BENCHMARK(BM_LambdaSingleEpoch)->Unit(benchmark::kMicrosecond);

/// The same problem started from the basis of an earlier reduction of it (ReductionStart), as
/// the RTK filter does from one epoch to the next: what the warm start costs when the basis still
/// fits (the filter's covariance changes a little between epochs, so a few permutations remain).
void BM_LambdaWarmStart(benchmark::State& st) {
  std::mt19937 rng(7);
  const Eigen::MatrixXd Q = singleEpochQ(rng, {12, 9, 12});
  const Eigen::MatrixXd L = Q.llt().matrixL();
  std::normal_distribution<double> g(0.0, 1.0);
  Eigen::VectorXd w(Q.rows());
  for (int i = 0; i < w.size(); ++i) w[i] = g(rng);
  const Eigen::VectorXd a = L * w;
  const gvins::LambdaResult cold = gvins::lambda(a, Q);
  const gvins::ReductionStart start{cold.reduction.Z, cold.reduction.Zinv};
  double perms = 0;
  for (auto _ : st) {
    const gvins::LambdaResult r = gvins::lambda(a, Q, {}, &start);
    perms = r.reduction.permutations;
    benchmark::DoNotOptimize(r.fixed);
  }
  st.counters["n"] = static_cast<double>(Q.rows());
  st.counters["permutations"] = perms;
}
BENCHMARK(BM_LambdaWarmStart)->Unit(benchmark::kMicrosecond);

void BM_LambdaReduction(benchmark::State& st) {
  std::mt19937 rng(7);
  const Eigen::MatrixXd Q = singleEpochQ(rng, {12, 9, 12});
  const auto f = gvins::ltdlFactorize(Q);
  for (auto _ : st) benchmark::DoNotOptimize(gvins::reduceLambda(*f).Z);
}
BENCHMARK(BM_LambdaReduction)->Unit(benchmark::kMicrosecond);
}  // namespace

BENCHMARK_MAIN();
