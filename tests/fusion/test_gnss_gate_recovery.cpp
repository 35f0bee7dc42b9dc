// The re-acquisition gate (fusion/gnss_gate_recovery.hpp) on synthetic epochs whose truth is known:
// range rows r_i = -u_iᵀ δp + δc + noise with unit line-of-sight vectors u_i spread over the sky,
// the filter's predicted covariance of [δp, δc] P, and faults added to chosen rows.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>

#include "gvins/fusion/gnss_gate_recovery.hpp"
#include "gvins/sri/chi_square.hpp"

namespace gvins::fusion {
namespace {

constexpr double kRowQuantile = 10.827566;  // χ²₁(0.999), the default row gate
constexpr double kEpochGate = 0.99999;

struct Epoch {
  ReacquisitionRows rows;
  Eigen::Vector4d truth;  // [δp, δc]
};

/// n range rows of satellites at elevations 15-80° and spread azimuths, measurement σ 1 m, the
/// filter's predicted σ of δp and δc `sigmaState`; the true correction `shift` (a position
/// drift of that length and a clock offset of half of it); `faults`: row -> bias (m).
Epoch rangeEpoch(int n, double shift, double sigmaState, const std::map<int, double>& faults, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  Epoch e;
  e.truth << shift * Eigen::Vector3d(0.6, -0.7, 0.39).normalized(), 0.5 * shift;
  ReacquisitionRows& r = e.rows;
  r.residual.resize(n);
  r.G.resize(n, 4);
  r.bandVariance = Eigen::VectorXd::Ones(n);
  for (int i = 0; i < n; ++i) {
    const double az = 2.0 * M_PI * i / n + 0.3 * (i % 3), el = (15.0 + 65.0 * ((i * 7) % n) / n) * M_PI / 180.0;
    const Eigen::Vector3d u(std::cos(el) * std::sin(az), std::cos(el) * std::cos(az), std::sin(el));
    r.G.row(i) << -u.transpose(), 1.0;
    const auto it = faults.find(i);
    r.residual[i] = r.G.row(i).dot(e.truth) + noise(rng) + (it == faults.end() ? 0.0 : it->second);
    r.group.push_back(kReacquireRange);
    r.sats.push_back(SatId{System::Gps, i + 1});
  }
  const Eigen::Matrix4d P = Eigen::Vector4d::Constant(sigmaState * sigmaState).asDiagonal();
  r.S = r.G * P * r.G.transpose() + Eigen::MatrixXd::Identity(n, n);
  return e;
}

int admittedCount(const ReacquisitionSelection& s) {
  int k = 0;
  for (bool a : s.admitted) k += a;
  return k;
}

TEST(GnssGateRecovery, CleanDriftIsReacquiredWithItsShift) {
  // A 20 m drift after a 15 s outage, the filter predicting 2 m: the widened gate (a = 0.3 m/s²:
  // σ 34 m at τ = 15.25 s) admits every row and the consensus finds the drift.
  const Epoch e = rangeEpoch(12, 20.0, 2.0, {}, 1);
  const auto s = selectReacquisitionRows(e.rows, 15.25, 0.3, kRowQuantile, kEpochGate);
  EXPECT_NEAR(s.sigmaP, 0.5 * 0.3 * 15.25 * 15.25, 1e-9);
  ASSERT_TRUE(s.groups[kReacquireRange].admitted);
  EXPECT_EQ(admittedCount(s), 12);
  // Least squares on 12 rows of σ 1 m: the shift to about a metre (geometry dilution ~2).
  EXPECT_LT((s.groups[kReacquireRange].correction - e.truth).head<3>().norm(), 3.0);
  EXPECT_LT(s.groups[kReacquireRange].chi2, s.groups[kReacquireRange].threshold);
  EXPECT_NEAR(s.groups[kReacquireRange].threshold, sri::chiSquareQuantile(kEpochGate, 12), 1e-9);
}

TEST(GnssGateRecovery, FaultedMinorityIsExcluded) {
  // Four of twelve satellites biased by 30-100 m at the re-acquisition: exactly those stay out.
  const std::map<int, double> faults{{1, 40.0}, {4, -60.0}, {7, 100.0}, {10, -30.0}};
  const Epoch e = rangeEpoch(12, 20.0, 2.0, faults, 2);
  const auto s = selectReacquisitionRows(e.rows, 15.25, 0.3, kRowQuantile, kEpochGate);
  ASSERT_TRUE(s.groups[kReacquireRange].admitted);
  for (int i = 0; i < 12; ++i) EXPECT_EQ(s.admitted[static_cast<std::size_t>(i)], faults.count(i) == 0) << "row " << i;
  EXPECT_EQ(s.groups[kReacquireRange].agreeing, 8);
  EXPECT_LT((s.groups[kReacquireRange].correction - e.truth).head<3>().norm(), 3.0);
  const std::string msg = describeReacquisition(e.rows, s);
  EXPECT_NE(msg.find("excluded G02 G05 G08 G11"), std::string::npos) << msg;
}

TEST(GnssGateRecovery, FaultedMajorityAdmitsNothing) {
  // Seven of twelve faulted with different biases: no majority agrees, nothing goes in.
  const std::map<int, double> faults{{0, 35.0}, {2, -50.0}, {3, 70.0}, {5, -90.0}, {6, 45.0}, {8, 100.0}, {9, -65.0}};
  const Epoch e = rangeEpoch(12, 20.0, 2.0, faults, 3);
  const auto s = selectReacquisitionRows(e.rows, 15.25, 0.3, kRowQuantile, kEpochGate);
  EXPECT_FALSE(s.groups[kReacquireRange].admitted);
  EXPECT_EQ(admittedCount(s), 0);
  EXPECT_NE(describeReacquisition(e.rows, s).find("no consensus"), std::string::npos);
}

TEST(GnssGateRecovery, ShiftBeyondTheWidenedCovarianceWaits) {
  // Every satellite agrees on a 50 m shift, but 0.5 s after the last update the widened
  // covariance (filter σ 2 m, growth 0.04 m) cannot explain it: nothing goes in. 30 s later
  // (σ 135 m) the same epoch is admitted.
  const Epoch e = rangeEpoch(12, 50.0, 2.0, {}, 4);
  const auto early = selectReacquisitionRows(e.rows, 0.5, 0.3, kRowQuantile, kEpochGate);
  EXPECT_EQ(admittedCount(early), 0);
  const auto late = selectReacquisitionRows(e.rows, 30.0, 0.3, kRowQuantile, kEpochGate);
  EXPECT_EQ(admittedCount(late), 12);
}

TEST(GnssGateRecovery, OneRowMoreThanTheUnknownsIsTheMinimum) {
  // Five rows for four unknowns: admitted when all agree; one faulted row leaves four (an exact
  // fit proves nothing) and nothing goes in; four rows never.
  EXPECT_EQ(admittedCount(selectReacquisitionRows(rangeEpoch(5, 20.0, 2.0, {}, 5).rows, 15.25, 0.3, kRowQuantile,
                                                  kEpochGate)),
            5);
  EXPECT_EQ(admittedCount(selectReacquisitionRows(rangeEpoch(5, 20.0, 2.0, {{2, 60.0}}, 5).rows, 15.25, 0.3,
                                                  kRowQuantile, kEpochGate)),
            0);
  EXPECT_EQ(admittedCount(selectReacquisitionRows(rangeEpoch(4, 20.0, 2.0, {}, 6).rows, 15.25, 0.3, kRowQuantile,
                                                  kEpochGate)),
            0);
}

TEST(GnssGateRecovery, AnAppliedAdmissionTalliesTheExcludedSatellites) {
  // The four biased satellites of FaultedMinorityIsExcluded, and a row outside the groups (left
  // to the caller's gate, so neither admitted nor excluded by the tests).
  const std::map<int, double> faults{{1, 40.0}, {4, -60.0}, {7, 100.0}, {10, -30.0}};
  Epoch e = rangeEpoch(12, 20.0, 2.0, faults, 2);
  e.rows.group[0] = kReacquireNone;
  const auto s = selectReacquisitionRows(e.rows, 15.25, 0.3, kRowQuantile, kEpochGate);
  const ReacquisitionTally t = tallyReacquisition(e.rows, s);
  EXPECT_EQ(t.admitted, 7);
  EXPECT_EQ(t.excluded, 4);
  ASSERT_EQ(t.excludedSats.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) EXPECT_EQ(t.excludedSats[i], e.rows.sats[3 * i + 1]) << i;
  // Through GnssGateRecovery: counted only when the epoch was applied during a re-acquisition.
  GnssGateRecovery g(2.0, 0.3);
  const GpsTime t0 = GpsTime::fromWeekTow(2381, 408700.0);
  g.outcome(t0, 12, true, true);
  ASSERT_TRUE(g.reacquiring(t0 + 15.0));
  EXPECT_EQ(g.outcome(t0 + 15.0, 12, false, false, &s, &e.rows).excluded, 0);  // not applied
  const ReacquisitionTally applied = g.outcome(t0 + 15.25, 12, true, false, &s, &e.rows);
  EXPECT_EQ(applied.admitted, 7);
  EXPECT_EQ(applied.excluded, 4);
  ASSERT_EQ(applied.excludedSats.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) EXPECT_EQ(applied.excludedSats[i], e.rows.sats[3 * i + 1]) << i;
}

TEST(GnssGateRecovery, RowsOutsideTheGroupsAreLeftToTheCaller) {
  Epoch e = rangeEpoch(8, 10.0, 2.0, {}, 7);
  e.rows.group[3] = kReacquireNone;  // e.g. an SPP velocity row
  const auto s = selectReacquisitionRows(e.rows, 5.0, 0.3, kRowQuantile, kEpochGate);
  EXPECT_FALSE(s.admitted[3]);
  EXPECT_EQ(s.groups[kReacquireRange].offered, 7);
  EXPECT_EQ(admittedCount(s), 7);
}

TEST(GnssGateRecovery, StartsAfterAnOutageOrSustainedRejectionAndEnds) {
  GnssGateRecovery g(2.0, 0.3);
  const GpsTime t0 = GpsTime::fromWeekTow(2381, 408700.0);
  EXPECT_FALSE(g.reacquiring(t0));
  g.outcome(t0, 10, true, true);  // applied through the normal gates
  EXPECT_FALSE(g.reacquiring(t0 + 1.75));
  // An outage: no epoch for 15 s; the next one re-acquires, τ from the last update.
  EXPECT_TRUE(g.reacquiring(t0 + 15.0));
  EXPECT_DOUBLE_EQ(g.sinceUpdate(t0 + 15.0), 15.0);
  EXPECT_EQ(g.recoveries(), 1);
  g.outcome(t0 + 15.0, 10, true, false);  // admitted, the normal gates still fail
  EXPECT_TRUE(g.reacquiring(t0 + 15.25));
  EXPECT_DOUBLE_EQ(g.sinceUpdate(t0 + 15.25), 0.25);
  g.outcome(t0 + 15.25, 10, true, true);  // back within the normal gates
  EXPECT_FALSE(g.reacquiring(t0 + 15.5));
  EXPECT_NE(g.warnings()[0].find("no GNSS update applied for 15.0 s"), std::string::npos) << g.warnings()[0];
  EXPECT_NE(g.warnings().back().find("re-acquired"), std::string::npos) << g.warnings().back();
  // The tight stage starts with every row gated out: re-acquisition 2 s later, not before.
  GnssGateRecovery h(2.0, 0.3);
  for (double t = 0.0; t < 1.9; t += 0.25) {
    EXPECT_FALSE(h.reacquiring(t0 + t)) << t;
    h.outcome(t0 + t, 10, false, false);
  }
  EXPECT_TRUE(h.reacquiring(t0 + 2.0));
  EXPECT_DOUBLE_EQ(h.sinceUpdate(t0 + 2.0), 2.0);
  ASSERT_EQ(h.warnings().size(), 1u);
  EXPECT_NE(h.warnings()[0].find("every row gated out (the state drifted away) for 2.0 s"), std::string::npos)
      << h.warnings()[0];
  GnssGateRecovery never(0.0, 0.3);
  never.outcome(t0, 10, true, true);
  EXPECT_FALSE(never.reacquiring(t0 + 100.0));
}

}  // namespace
}  // namespace gvins::fusion
