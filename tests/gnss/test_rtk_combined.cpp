// Combined (forward + backward) post-processing: the combination rule on hand-made solutions
// (the covariance-weighted mean against the batch least-squares of two independent estimates;
// each branch of the fix rule), and the backward pass and the combination on the real Nagoya
// pair against its reference rover position (tests/data/gnss/nagoya_static_2024).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Dense>

#include "gvins/base/constants.hpp"
#include "gvins/gnss/cycle_slip_detector.hpp"
#include "gvins/gnss/rtk.hpp"
#include "gvins/gnss/rtk_combination.hpp"
#include "gvins/gnss/rtk_pass.hpp"
#include "nagoya_pair.hpp"

using namespace gvins;

namespace {

Eigen::Matrix3d spd(int seed, double scale) {
  std::srand(static_cast<unsigned>(seed));
  const Eigen::Matrix3d a = Eigen::Matrix3d::Random();
  return scale * scale * (a * a.transpose() + 0.1 * Eigen::Matrix3d::Identity());
}

RtkSolution solution(SolutionQuality q, const Eigen::Vector3d& x, double sigma, const Eigen::Vector3d& xFloat,
                     double floatSigma) {
  RtkSolution s;
  s.quality = q;
  s.position = x;
  s.positionCovariance = sigma * sigma * Eigen::Matrix3d::Identity();
  s.floatPosition = xFloat;
  s.floatCovariance = floatSigma * floatSigma * Eigen::Matrix3d::Identity();
  return s;
}

struct Passes {
  std::vector<RtkSolution> forward, backward, combined;
  std::vector<Combination> how;
};

Passes runPasses(const RtkConfig& c, std::size_t first = 0, std::size_t last = 301) {
  const test::RecordedPair& d = test::nagoyaPair();
  const std::vector<ObsEpoch> rover(d.rover.begin() + static_cast<std::ptrdiff_t>(first),
                                    d.rover.begin() + static_cast<std::ptrdiff_t>(std::min(last, d.rover.size())));
  Passes p;
  for (int k = 0; k < 2; ++k) {
    RtkSolver s(d.nav, c);
    s.setRoverGlonassChannels(d.roverHeader.glonassChannels);
    s.setBaseGlonassChannels(d.baseHeader.glonassChannels);
    s.setBasePosition(d.basePosition);
    (k == 0 ? p.forward : p.backward) =
        runRtkPass(s, rover, d.base, k == 0 ? TimeDirection::Forward : TimeDirection::Backward);
  }
  p.combined = combinePasses(p.forward, p.backward, CombinationOptions{}, &p.how);
  return p;
}

int fixedCount(const std::vector<RtkSolution>& v) {
  return static_cast<int>(std::count_if(v.begin(), v.end(), [](const RtkSolution& s) { return s.quality == SolutionQuality::Fix; }));
}

int wrongCount(const std::vector<RtkSolution>& v) {
  const Eigen::Vector3d truth = test::nagoyaPair().truth;
  return static_cast<int>(std::count_if(v.begin(), v.end(), [&](const RtkSolution& s) {
    return s.quality == SolutionQuality::Fix && (s.position - truth).norm() > 0.10;
  }));
}

}  // namespace

// P = (Pa⁻¹ + Pb⁻¹)⁻¹, x = P (Pa⁻¹ xa + Pb⁻¹ xb) is the least-squares solution of the stacked
// observations [I; I] x = [xa; xb] with weight blockdiag(Pa⁻¹, Pb⁻¹), solved here by QR of the
// whitened 6x3 system; its covariance is (Aᵀ W A)⁻¹.
TEST(RtkCombination, WeightedMeanIsTheBatchLeastSquaresOfTwoEstimates) {
  for (int seed = 1; seed <= 5; ++seed) {
    const Eigen::Matrix3d Pa = spd(seed, 0.3), Pb = spd(100 + seed, 0.05 * seed);
    const Eigen::Vector3d xa(-3.9e6 + seed, 3.4e6, 3.6e6), xb = xa + Eigen::Vector3d(0.4, -0.2, 0.1 * seed);
    Eigen::Vector3d x;
    Eigen::Matrix3d P;
    ASSERT_TRUE(combineEstimates(xa, Pa, xb, Pb, x, P));
    // Whitening: L⁻¹ with P = L Lᵀ.
    const Eigen::Matrix3d La = Pa.llt().matrixL(), Lb = Pb.llt().matrixL();
    Eigen::Matrix<double, 6, 3> A;
    Eigen::Matrix<double, 6, 1> y;
    A << La.triangularView<Eigen::Lower>().solve(Eigen::Matrix3d::Identity()),
        Lb.triangularView<Eigen::Lower>().solve(Eigen::Matrix3d::Identity());
    y << La.triangularView<Eigen::Lower>().solve(xa - xa), Lb.triangularView<Eigen::Lower>().solve(xb - xa);
    const Eigen::Vector3d dx = A.colPivHouseholderQr().solve(y);
    const Eigen::Matrix3d Pbatch = (A.transpose() * A).inverse();
    EXPECT_LT((x - (xa + dx)).norm(), 1e-9) << seed;
    EXPECT_LT((P - Pbatch).norm(), 1e-12) << seed;
    // Never less precise than the better input.
    EXPECT_LE(P.trace(), std::min(Pa.trace(), Pb.trace()) + 1e-15);
  }
  Eigen::Vector3d x;
  Eigen::Matrix3d P;
  EXPECT_FALSE(combineEstimates(Eigen::Vector3d::Zero(), Eigen::Matrix3d::Zero(), Eigen::Vector3d::Zero(),
                                Eigen::Matrix3d::Identity(), x, P));
}

TEST(RtkCombination, FixRule) {
  const Eigen::Vector3d truth(-3.9e6, 3.4e6, 3.6e6);
  const Eigen::Vector3d off(0.3, 0.0, 0.0);
  const CombinationOptions o;
  Combination how;
  using Q = SolutionQuality;
  // Both fixed at the same position: the combined fix, their weighted mean.
  RtkSolution s = combineSolutions(solution(Q::Fix, truth, 0.004, truth, 0.2),
                                   solution(Q::Fix, truth + Eigen::Vector3d(0.003, 0, 0), 0.004, truth, 0.2), o, &how);
  EXPECT_EQ(how, Combination::BothFixed);
  EXPECT_EQ(s.quality, Q::Fix);
  EXPECT_NEAR(s.position.x() - truth.x(), 0.0015, 1e-9);
  EXPECT_NEAR(s.positionCovariance(0, 0), 0.5 * 0.004 * 0.004, 1e-12);
  // Both fixed, 0.3 m apart with 4 mm sigmas: float (the combined floats), counted.
  s = combineSolutions(solution(Q::Fix, truth, 0.004, truth, 0.2), solution(Q::Fix, truth + off, 0.004, truth + off, 0.2), o,
                       &how);
  EXPECT_EQ(how, Combination::Disagreement);
  EXPECT_EQ(s.quality, Q::Float);
  EXPECT_NEAR(s.position.x() - truth.x(), 0.15, 1e-9);
  // One pass fixed, consistent with the other's float: that fix.
  s = combineSolutions(solution(Q::Float, truth + off, 0.2, truth + off, 0.2), solution(Q::Fix, truth, 0.004, truth, 0.3), o,
                       &how);
  EXPECT_EQ(how, Combination::BackwardFixed);
  EXPECT_EQ(s.quality, Q::Fix);
  EXPECT_EQ(s.position, truth);
  // ... inconsistent with it (1.5 m off, 0.1 m float sigma): float.
  const Eigen::Vector3d far(1.5, 0.0, 0.0);
  s = combineSolutions(solution(Q::Fix, truth, 0.004, truth, 0.3), solution(Q::Float, truth + far, 0.1, truth + far, 0.1), o,
                       &how);
  EXPECT_EQ(how, Combination::FixRejected);
  EXPECT_EQ(s.quality, Q::Float);
  // ... the other pass without a float: the fix stands.
  RtkSolution single = solution(Q::Single, truth + far, 2.0, Eigen::Vector3d::Zero(), 0.0);
  s = combineSolutions(solution(Q::Fix, truth, 0.004, truth, 0.3), single, o, &how);
  EXPECT_EQ(how, Combination::ForwardFixed);
  EXPECT_EQ(s.quality, Q::Fix);
  // A pass's rejected fix (float with ArStatus::Rejected) never becomes a fix.
  RtkSolution rejected = solution(Q::Float, truth, 0.2, truth, 0.2);
  rejected.ar = ArStatus::Rejected;
  s = combineSolutions(rejected, solution(Q::Float, truth, 0.2, truth, 0.2), o, &how);
  EXPECT_EQ(how, Combination::Float);
  EXPECT_EQ(s.quality, Q::Float);
  EXPECT_NEAR(s.positionCovariance(0, 0), 0.02, 1e-12);
  // Neither pass with an RTK solution: the single-point fallback; none at all: none.
  s = combineSolutions(RtkSolution{}, single, o, &how);
  EXPECT_EQ(how, Combination::Single);
  EXPECT_EQ(s.quality, Q::Single);
  s = combineSolutions(RtkSolution{}, RtkSolution{}, o, &how);
  EXPECT_EQ(how, Combination::None);
  EXPECT_FALSE(s.valid());
}

// The backward pass alone on the static Nagoya pair (kinematic processing, continuous AR): it
// fixes as the forward pass does, and where both are fixed they agree within their sigmas and
// with the reference position.
TEST(RtkCombined, BackwardPassAgreesWithForward) {
  const Passes p = runPasses(RtkConfig{});
  const Eigen::Vector3d truth = test::nagoyaPair().truth;
  const int ff = fixedCount(p.forward), bf = fixedCount(p.backward);
  EXPECT_GE(bf, 290);
  EXPECT_EQ(wrongCount(p.backward), 0);
  int both = 0;
  for (std::size_t i = 0; i < p.forward.size(); ++i) {
    const RtkSolution &f = p.forward[i], &b = p.backward[i];
    ASSERT_LT(std::abs(f.time - b.time), 1e-6) << i;
    if (f.quality != SolutionQuality::Fix || b.quality != SolutionQuality::Fix) continue;
    ++both;
    const double sigma = std::sqrt((f.positionCovariance + b.positionCovariance).trace());
    EXPECT_LT((f.position - b.position).norm(), 3.0 * sigma + 1e-3) << i;
    EXPECT_LT((b.position - truth).norm(), 0.02) << i;
  }
  EXPECT_GE(both, std::min(ff, bf) - 5);
  EXPECT_EQ(fixedCount(p.combined), static_cast<int>(p.combined.size()));
  // The counts of combinePasses against the solutions themselves.
  CombinationCounts counts;
  const std::vector<RtkSolution> again = combinePasses(p.forward, p.backward, CombinationOptions{}, nullptr, &counts);
  ASSERT_EQ(again.size(), p.combined.size());
  EXPECT_EQ(counts.forwardFixed, ff);
  EXPECT_EQ(counts.backwardFixed, bf);
  EXPECT_EQ(counts.bothFixed + counts.disagreements, both);
  EXPECT_EQ(counts.combinedFixed, fixedCount(again));
  EXPECT_THROW(combinePasses(p.forward, std::vector<RtkSolution>(p.forward.size() - 1), CombinationOptions{}),
               std::invalid_argument);
}

// The weak single-epoch case of the integrity table (Galileo E1 only, 25 deg mask, instantaneous
// AR) and a 40-epoch cut of the pair with continuous AR: no wrong fix, and at least the forward
// pass's fixes (the cut: more, the backward pass has converged where the forward one starts).
TEST(RtkCombined, WeakCasesNoWrongFixAndAtLeastTheForwardFixRate) {
  RtkConfig c;
  c.systems = parseSystemLetters("E");
  c.frequencies = 1;
  c.elevationMask = c.arElevationMask = 25.0 * constants::kDegToRad;
  c.ambiguityMode = AmbiguityMode::Instantaneous;
  const Passes weak = runPasses(c);
  EXPECT_EQ(wrongCount(weak.forward), 0);
  EXPECT_EQ(wrongCount(weak.backward), 0);
  EXPECT_EQ(wrongCount(weak.combined), 0);
  EXPECT_GE(fixedCount(weak.combined), fixedCount(weak.forward));

  RtkConfig e1;
  e1.systems = parseSystemLetters("E");
  e1.frequencies = 1;
  const Passes cut = runPasses(e1, 100, 140);
  EXPECT_EQ(wrongCount(cut.combined), 0);
  EXPECT_GT(fixedCount(cut.combined), fixedCount(cut.forward));
  EXPECT_GE(fixedCount(cut.combined), fixedCount(cut.backward));
}

// Backward slip detection on real rover phases: a loss-of-lock flag at epoch 10 marks a slip
// between epochs 9 and 10. Forward, epoch 10 starts the new arc; backward (20 down to 0), epoch 9
// does, and the arcs on either side are whole (no other flag, no gap) in both directions.
TEST(RtkCombined, BackwardSlipDetectionFlagsTheEpochBeforeTheLossOfLock) {
  const test::RecordedPair& d = test::nagoyaPair();
  std::vector<ObsEpoch> rover(d.rover.begin(), d.rover.begin() + 21);
  const SatId sat = rover[10].sats.front().sat;
  SignalObs* sig = nullptr;
  for (SignalObs& s : rover[10].sats.front().signals) {
    if (s.hasPhase() && !sig) sig = &s;
  }
  ASSERT_NE(sig, nullptr);
  sig->lli |= 1;
  const ObsCode code = sig->code;
  for (const TimeDirection dir : {TimeDirection::Forward, TimeDirection::Backward}) {
    CycleSlipDetector det;
    det.setDirection(dir);
    std::vector<int> flagged;
    for (int k = 0; k < 21; ++k) {
      const int i = dir == TimeDirection::Forward ? k : 20 - k;
      det.process(rover[static_cast<std::size_t>(i)], d.roverHeader.glonassChannels);
      const std::uint8_t f = det.flags(sat, code);
      if (f & kSlipLli) flagged.push_back(i);
      if (k > 0) {
        EXPECT_EQ(f & (kSlipGap | kSlipDoppler | kSlipGeometryFree), 0) << toString(dir) << " " << i;
      }
    }
    ASSERT_EQ(flagged.size(), 1u) << toString(dir);
    EXPECT_EQ(flagged[0], dir == TimeDirection::Forward ? 10 : 9);
    EXPECT_EQ(*det.arcStart(sat, code), rover[dir == TimeDirection::Forward ? 10u : 9u].time);
  }
}
