// gvins-eval library: alignment recovers known transforms, errors equal their analytic values on
// hand-constructed trajectories, covariance file parsing and malformed inputs, SVG output.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <sstream>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "gvins/base/parse_error.hpp"
#include "gvins/vio/pose_covariance_csv.hpp"
#include "gvins/vio/so3.hpp"
#include "gvins/vio/svg_plot.hpp"
#include "gvins/vio/trajectory_alignment.hpp"
#include "gvins/vio/trajectory_metrics.hpp"

using namespace gvins::vio;

namespace {

Eigen::Matrix3d rotZ(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).toRotationMatrix(); }

/// A 3-D Lissajous-like path (non-planar, so SE(3) alignment is well posed), 200 Hz for `seconds`,
/// orientation turning with the path; velocity from the analytic derivative.
std::vector<TrajectorySample> curve(double seconds, double rateHz = 200.0) {
  std::vector<TrajectorySample> out;
  const int n = static_cast<int>(seconds * rateHz) + 1;
  for (int k = 0; k < n; ++k) {
    const double t = k / rateHz;
    TrajectorySample s;
    s.t_ns = 1'000'000'000LL + static_cast<std::int64_t>(std::llround(t * 1e9));
    s.p = {10.0 * std::sin(0.3 * t), 6.0 * std::sin(0.2 * t) + 0.5 * t, 2.0 * std::cos(0.25 * t)};
    s.v = Eigen::Vector3d(3.0 * std::cos(0.3 * t), 1.2 * std::cos(0.2 * t) + 0.5, -0.5 * std::sin(0.25 * t));
    s.R = rotZ(0.1 * t) * Eigen::AngleAxisd(0.2 * std::sin(t), Eigen::Vector3d::UnitX()).toRotationMatrix();
    out.push_back(s);
  }
  return out;
}

/// est = T⁻¹ applied to ref (so that aligning est gives back T): p_e = R^T (p − t)/s, R_e = R^T R_ref.
std::vector<TrajectorySample> transformed(const std::vector<TrajectorySample>& ref, const SimilarityTransform& T,
                                          std::size_t stride = 1) {
  std::vector<TrajectorySample> out;
  for (std::size_t i = 0; i < ref.size(); i += stride) {
    TrajectorySample s = ref[i];
    s.p = T.R.transpose() * (ref[i].p - T.t) / T.scale;
    s.R = T.R.transpose() * ref[i].R;
    s.v.reset();
    out.push_back(s);
  }
  return out;
}

}  // namespace

TEST(TrajectoryAlignment, UmeyamaRecoversKnownSim3AndSE3) {
  const auto ref = curve(60.0);
  SimilarityTransform T;
  T.R = (Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized())).toRotationMatrix();
  T.t = {12.0, -4.0, 3.5};
  T.scale = 1.3;
  const auto est = transformed(ref, T);
  std::vector<Eigen::Vector3d> pe, pr;
  for (std::size_t i = 0; i < ref.size(); ++i) pe.push_back(est[i].p), pr.push_back(ref[i].p);
  const SimilarityTransform A = alignTrajectory(AlignmentKind::Sim3, pe, pr);
  EXPECT_LT((A.R - T.R).norm(), 1e-9);
  EXPECT_LT((A.t - T.t).norm(), 1e-8);
  EXPECT_NEAR(A.scale, 1.3, 1e-10);

  T.scale = 1.0;
  const auto est2 = transformed(ref, T);
  for (std::size_t i = 0; i < ref.size(); ++i) pe[i] = est2[i].p;
  const SimilarityTransform B = alignTrajectory(AlignmentKind::SE3, pe, pr);
  EXPECT_LT((B.R - T.R).norm(), 1e-9);
  EXPECT_LT((B.t - T.t).norm(), 1e-8);
  EXPECT_EQ(B.scale, 1.0);
}

TEST(TrajectoryAlignment, UmeyamaReflectionCaseGivesProperRotation) {
  // A planar point set whose mirror image fits as well: the determinant fix must keep det R = +1.
  std::vector<Eigen::Vector3d> pe = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}}, pr;
  const Eigen::Matrix3d R = rotZ(0.4);
  for (const auto& p : pe) pr.push_back(R * p + Eigen::Vector3d(1, 2, 3));
  const SimilarityTransform A = alignTrajectory(AlignmentKind::SE3, pe, pr);
  EXPECT_NEAR(A.R.determinant(), 1.0, 1e-12);
  EXPECT_LT((A.R - R).norm(), 1e-9);
}

TEST(TrajectoryAlignment, FourDofRecoversYawAndTranslationOnly) {
  const auto ref = curve(60.0);
  SimilarityTransform T;
  T.R = rotZ(-2.1);
  T.t = {-30.0, 7.0, 1.25};
  const auto est = transformed(ref, T);
  std::vector<Eigen::Vector3d> pe, pr;
  for (std::size_t i = 0; i < ref.size(); ++i) pe.push_back(est[i].p), pr.push_back(ref[i].p);
  const SimilarityTransform A = alignTrajectory(AlignmentKind::Yaw4Dof, pe, pr);
  EXPECT_LT((A.R - T.R).norm(), 1e-12);
  EXPECT_LT((A.t - T.t).norm(), 1e-9);
  // A roll the 4-DoF model cannot represent stays as error: R must remain a pure z rotation.
  const Eigen::Matrix3d tilt = Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitX()).toRotationMatrix();
  for (auto& p : pe) p = tilt * p;
  const SimilarityTransform B = alignTrajectory(AlignmentKind::Yaw4Dof, pe, pr);
  EXPECT_NEAR(B.R(2, 2), 1.0, 1e-15);
  EXPECT_NEAR(B.R(0, 2), 0.0, 1e-15);
}

TEST(TrajectoryAlignment, NamesAndBadInput) {
  EXPECT_EQ(parseAlignmentKind("4dof"), AlignmentKind::Yaw4Dof);
  EXPECT_EQ(parseAlignmentKind("sim3"), AlignmentKind::Sim3);
  EXPECT_FALSE(parseAlignmentKind("se4"));
  std::vector<Eigen::Vector3d> a(3), b(2);
  EXPECT_THROW(alignTrajectory(AlignmentKind::SE3, a, b), std::invalid_argument);
}

TEST(TrajectoryMetrics, ExactTransformGivesZeroErrorAfterAlignment) {
  const auto ref = curve(120.0);
  SimilarityTransform T;
  T.R = rotZ(1.0);
  T.t = {5, 6, 7};
  EvaluationOptions opt;
  opt.alignment = AlignmentKind::Yaw4Dof;
  // Estimate at 20 Hz on reference stamps: zero error, yaw and translation of T recovered.
  auto est0 = transformed(ref, T, 10);
  const EvaluationResult r0 = evaluateTrajectory(est0, ref, {}, opt);
  EXPECT_LT(r0.translation.rmse, 1e-9);
  EXPECT_LT(r0.rotation.rmse, 1e-6);
  EXPECT_LT((r0.alignment.R - T.R).norm(), 1e-12);
  // The estimate's velocity (central differences at 20 Hz) vs the analytic one: the error of a
  // central difference of a·sin(ωt) over ±h is at most a ω³ h²/6 per axis; and it is not zero.
  const double h2 = 0.05 * 0.05;
  const double bound = (10.0 * std::pow(0.3, 3) + 6.0 * std::pow(0.2, 3) + 2.0 * std::pow(0.25, 3)) * h2 / 6.0;
  EXPECT_LT(r0.velocity.max, bound * 1.001);
  EXPECT_GT(r0.velocity.max, 0.1 * bound);
  for (const auto& s : r0.segments) {
    EXPECT_GT(s.count, 0u);
    EXPECT_LT(s.meanTranslation, 1e-9);
  }
}

TEST(TrajectoryMetrics, EstimatedVelocityIsRotatedByTheAlignment) {
  // An estimate in another frame (yaw 1 rad, shifted) that carries its own velocity: the
  // velocity error uses it (rotated into the reference frame) instead of differencing
  // positions, so it is exact where the differences are not; an error of 0.1 m/s added along
  // the estimate's x axis appears as exactly 0.1 m/s after the rotation.
  const auto ref = curve(60.0);
  SimilarityTransform T;
  T.R = rotZ(1.0);
  T.t = {5, 6, 7};
  auto est = transformed(ref, T, 10);
  for (std::size_t i = 0; i < est.size(); ++i) est[i].v = T.R.transpose() * *ref[i * 10].v;
  EvaluationOptions opt;
  opt.alignment = AlignmentKind::Yaw4Dof;
  const EvaluationResult r0 = evaluateTrajectory(est, ref, {}, opt);
  EXPECT_EQ(r0.velocity.count, est.size());
  EXPECT_LT(r0.velocity.max, 1e-9);
  for (auto& s : est) *s.v += Eigen::Vector3d(0.1, 0.0, 0.0);
  const EvaluationResult r1 = evaluateTrajectory(est, ref, {}, opt);
  EXPECT_NEAR(r1.velocity.rmse, 0.1, 1e-9);
  EXPECT_NEAR(r1.velocity.mean, 0.1, 1e-9);
  // The body-frame velocity error needs no alignment: R_estᵀ (0.1 e_x) has length 0.1.
  EXPECT_EQ(r0.bodyVelocity.count, est.size());
  EXPECT_LT(r0.bodyVelocity.max, 1e-9);
  EXPECT_NEAR(r1.bodyVelocity.rmse, 0.1, 1e-9);
  EXPECT_NEAR(r1.bodyVelocity.max, 0.1, 1e-9);
}

TEST(TrajectoryMetrics, FirstPoseAlignmentKeepsTheDrift) {
  // An estimate in another frame (yaw 1 rad, shifted, tilted start) that drifts by 0.01 m per s
  // along its own x axis: the first-pose alignment recovers the frame from the first pose alone
  // and leaves the drift in the errors (a whole-trajectory 4-DoF fit would spread it).
  const auto ref = curve(60.0);
  SimilarityTransform T;
  T.R = rotZ(1.0);
  T.t = {5, 6, 7};
  auto est = transformed(ref, T, 10);
  for (auto& s : est) s.p += Eigen::Vector3d(0.01 * static_cast<double>(s.t_ns - est.front().t_ns) * 1e-9, 0.0, 0.0);
  EvaluationOptions opt;
  opt.alignment = AlignmentKind::FirstPose4Dof;
  const EvaluationResult r = evaluateTrajectory(est, ref, {}, opt);
  EXPECT_LT((r.alignment.R - T.R).norm(), 1e-12);
  EXPECT_LT((r.alignment.t - T.t).norm(), 1e-9);
  ASSERT_EQ(r.translationError.size(), est.size());
  for (std::size_t i = 0; i < est.size(); ++i) EXPECT_NEAR(r.translationError[i], 0.01 * r.time[i], 1e-9) << i;
  EXPECT_LT(r.rotation.max, 1e-6);
  opt.alignment = AlignmentKind::Yaw4Dof;
  EXPECT_LT(evaluateTrajectory(est, ref, {}, opt).translation.max, r.translation.max);
  EXPECT_EQ(parseAlignmentKind("first"), AlignmentKind::FirstPose4Dof);
  EXPECT_EQ(toString(AlignmentKind::FirstPose4Dof), "first");
  const std::vector<Eigen::Vector3d> pts{Eigen::Vector3d::Zero()};
  EXPECT_THROW(alignTrajectory(AlignmentKind::FirstPose4Dof, pts, pts), std::invalid_argument);
}

TEST(TrajectoryMetrics, InterpolatedReferenceAtOffsetStamps) {
  // Straight line at constant velocity: linear interpolation of the 200 Hz reference is exact,
  // so an estimate equal to the analytic pose at shifted stamps has zero error.
  std::vector<TrajectorySample> ref, est;
  const Eigen::Vector3d v(2.0, -1.0, 0.5);
  for (int k = 0; k <= 2000; ++k) {
    TrajectorySample s;
    s.t_ns = 5'000'000'000LL + k * 5'000'000LL;
    s.p = v * (k * 0.005);
    s.v = v;
    ref.push_back(s);
  }
  for (int k = 0; k < 190; ++k) {
    TrajectorySample s;
    s.t_ns = 5'000'000'000LL + k * 50'000'000LL + 1'234'567;
    s.p = v * (static_cast<double>(s.t_ns - 5'000'000'000LL) * 1e-9);
    est.push_back(s);
  }
  EvaluationOptions opt;
  opt.alignment = AlignmentKind::None;
  opt.tolerance_ns = 4'000'000;
  const EvaluationResult r = evaluateTrajectory(est, ref, {}, opt);
  EXPECT_EQ(r.matched, 190u);
  EXPECT_LT(r.translation.max, 1e-9);
  EXPECT_LT(r.velocity.max, 1e-6);
  // With a 1 ms tolerance and 5 ms reference spacing, stamps 1.23 ms from the nearest sample
  // match only if within 1 ms of a sample: none here (1.23 and 3.77 ms away).
  opt.tolerance_ns = 1'000'000;
  EXPECT_THROW(evaluateTrajectory(est, ref, {}, opt), std::invalid_argument);
}

TEST(TrajectoryMetrics, RmseEqualsAnalyticValueForKnownNoise) {
  // Estimate = reference + alternating ±a along z (zero mean) → after 4-DoF alignment the yaw and
  // x-y translation are exact, z translation is the mean (0), and every error is exactly a.
  const auto ref = curve(100.0, 20.0);
  const double a = 0.037;
  std::vector<TrajectorySample> est = ref;
  for (std::size_t i = 0; i < est.size(); ++i) {
    est[i].p.z() += (i % 2 == 0 ? a : -a);
    est[i].v.reset();
  }
  if (est.size() % 2 == 1) est.pop_back();
  EvaluationOptions opt;
  opt.alignment = AlignmentKind::Yaw4Dof;
  const EvaluationResult r = evaluateTrajectory(est, ref, {}, opt);
  EXPECT_NEAR(r.translation.rmse, a, 1e-12);
  EXPECT_NEAR(r.translation.mean, a, 1e-12);
  EXPECT_NEAR(r.translation.max, a, 1e-12);

  // Constant rotation error θ about a fixed body axis, no alignment: every rotation error is θ.
  std::vector<TrajectorySample> est2 = ref;
  const double theta = 0.02;
  for (auto& e : est2) e.R = e.R * so3::exp(Eigen::Vector3d(0.6, 0.0, 0.8) * theta);
  opt.alignment = AlignmentKind::None;
  const EvaluationResult r2 = evaluateTrajectory(est2, ref, {}, opt);
  EXPECT_NEAR(r2.rotation.rmse, theta * 180.0 / std::numbers::pi, 1e-9);
  EXPECT_LT(r2.translation.rmse, 1e-12);

  // Random Gaussian position noise σ per axis: the RMSE estimates sqrt(3)σ (n ≈ 2000, ±5 %).
  std::mt19937_64 rng(7);
  std::normal_distribution<double> nd(0.0, 0.1);
  std::vector<TrajectorySample> est3 = ref;
  for (auto& e : est3) e.p += Eigen::Vector3d(nd(rng), nd(rng), nd(rng));
  const EvaluationResult r3 = evaluateTrajectory(est3, ref, {}, opt);
  EXPECT_NEAR(r3.translation.rmse, std::sqrt(3.0) * 0.1, 0.05 * std::sqrt(3.0) * 0.1);
}

TEST(TrajectoryMetrics, DriftPercentOfScaledStraightLine) {
  // Straight 375 m line sampled every 0.125 m (exact in binary, so path lengths add up exactly);
  // the estimate is 1 % too long from the start: every segment of length L
  // has translation error 0.01·L → drift 1 % whatever L; with Sim(3) alignment the scale
  // correction removes it.
  std::vector<TrajectorySample> ref, est;
  for (int k = 0; k <= 3000; ++k) {
    TrajectorySample s;
    s.t_ns = k * 100'000'000LL;
    s.p = Eigen::Vector3d(0.125 * k, 0.0, 0.0);
    s.R = rotZ(0.3);
    ref.push_back(s);
    s.p *= 1.01;
    est.push_back(s);
  }
  EvaluationOptions opt;
  opt.alignment = AlignmentKind::None;
  const EvaluationResult r = evaluateTrajectory(est, ref, {}, opt);
  ASSERT_EQ(r.segments.size(), 3u);
  for (const auto& s : r.segments) {
    EXPECT_NEAR(s.driftPercent, 1.0, 1e-6) << s.length;
    EXPECT_NEAR(s.rotationDegPerM, 0.0, 1e-12);
  }
  // Starts 0..2920 have a pose 10 m (80 samples) further; 0..2200 one 100 m further.
  EXPECT_EQ(r.segments[0].count, 2921u);
  EXPECT_EQ(r.segments[2].count, 2201u);
  opt.alignment = AlignmentKind::Sim3;
  const EvaluationResult rs = evaluateTrajectory(est, ref, {}, opt);
  EXPECT_NEAR(rs.alignment.scale, 1.0 / 1.01, 1e-12);
  EXPECT_LT(rs.segments[2].driftPercent, 1e-8);
  EXPECT_LT(rs.translation.rmse, 1e-8);
}

TEST(TrajectoryMetrics, NeesMatchesHandComputation) {
  const auto ref = curve(20.0, 10.0);
  std::vector<TrajectorySample> est = ref;
  std::vector<PoseCovariance> cov;
  const Eigen::Vector3d dp(0.3, -0.2, 0.1), dth(0.01, 0.02, -0.03);
  Matrix6d P = Matrix6d::Zero();
  P.diagonal() << 1e-4, 4e-4, 9e-4, 0.04, 0.01, 0.09;
  for (auto& e : est) {
    e.p -= dp;                    // p_ref − p_est = dp
    e.R = e.R * so3::exp(-dth);   // R_ref = R_est·Exp(dth)
    cov.push_back({e.t_ns, P});
  }
  EvaluationOptions opt;
  opt.alignment = AlignmentKind::None;
  const EvaluationResult r = evaluateTrajectory(est, ref, cov, opt);
  EXPECT_EQ(r.neesCount, ref.size());
  const double np = 0.09 / 0.04 + 0.04 / 0.01 + 0.01 / 0.09;
  const double no = 1e-4 / 1e-4 + 4e-4 / 4e-4 + 9e-4 / 9e-4;
  EXPECT_NEAR(r.positionNees, np, 1e-9);
  EXPECT_NEAR(r.orientationNees, no, 1e-6);
}

TEST(PoseCovarianceCsv, WriteReadRoundTrip) {
  const auto dir = std::filesystem::temp_directory_path() / "gvins_test_cov";
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "est.cov.csv").string();
  Matrix6d A = Matrix6d::Random();
  const Matrix6d P = A * A.transpose();
  {
    PoseCovarianceWriter w(path);
    w.write(1'403'715'274'312'143'104LL, P);
    w.write(1'403'715'274'362'142'976LL, 2.0 * P);
    w.close();
  }
  const auto c = readPoseCovarianceCsv(path);
  ASSERT_EQ(c.size(), 2u);
  EXPECT_EQ(c[0].t_ns, 1'403'715'274'312'143'104LL);
  EXPECT_EQ(c[1].t_ns, 1'403'715'274'362'142'976LL);
  EXPECT_LT((c[1].P - 2.0 * P).norm(), 1e-7 * P.norm());
}

TEST(PoseCovarianceCsv, MalformedInputNamesLineAndField) {
  std::string row = "1.0";
  for (int i = 0; i < 36; ++i) row += (i % 7 == 0) ? ",1" : ",0";
  auto expectError = [](const std::string& text, int line, const std::string& field) {
    try {
      parsePoseCovarianceCsv(text, "x.cov.csv");
      ADD_FAILURE() << "no error for: " << text.substr(0, 60);
    } catch (const gvins::ParseError& e) {
      EXPECT_EQ(e.file(), "x.cov.csv");
      EXPECT_EQ(e.line(), line) << e.what();
      EXPECT_EQ(e.field(), field) << e.what();
    }
  };
  EXPECT_EQ(parsePoseCovarianceCsv("# c\n" + row + "\n", "x").size(), 1u);
  expectError("# c\n1.0,1,0,0\n", 2, "c03");  // t, c00..c02 present: c03 missing
  std::string bad = row;
  bad.replace(bad.find(",0"), 2, ",zz");  // c01
  expectError(row + "\n" + bad + "\n", 2, "c01");
  std::string asym = "2.0,1,0.5";
  for (int i = 2; i < 36; ++i) asym += (i % 7 == 0) ? ",1" : ",0";
  expectError(asym + "\n", 1, "c10");
  std::string neg = "2.0,-1";
  for (int i = 1; i < 36; ++i) neg += (i % 7 == 0) ? ",1" : ",0";
  expectError(neg + "\n", 1, "c00");
  expectError(row + "\n" + row + "\n", 2, "timestamp");
  expectError("abc" + row.substr(3) + "\n", 1, "timestamp");
  std::string nan = "1.0,nan";
  for (int i = 1; i < 36; ++i) nan += ",0";
  expectError(nan + "\n", 1, "c00");
  EXPECT_THROW(readPoseCovarianceCsv("/nonexistent/est.cov.csv"), gvins::ParseError);
}

TEST(SvgPlot, TicksAndDocument) {
  const auto t = niceTicks(0.0, 9.7, 5);
  ASSERT_EQ(t.size(), 5u);
  EXPECT_DOUBLE_EQ(t[1] - t[0], 2.0);
  EXPECT_DOUBLE_EQ(t.back(), 8.0);
  const auto u = niceTicks(-0.013, 0.021, 6);
  // raw step 0.034/6 = 0.0057 → next of 1, 2, 5, 10 × 1e-3 is 0.01: −0.01, 0, 0.01, 0.02.
  ASSERT_EQ(u.size(), 4u);
  EXPECT_NEAR(u[1] - u[0], 0.01, 1e-15);
  EXPECT_NEAR(u.front(), -0.01, 1e-15);
  SvgPlot p("A <title>", "x", "y");
  p.addLine("s&1", {0, 1, std::nan(""), 3}, {0, 1, 2, 3});
  const std::string svg = p.render();
  EXPECT_NE(svg.find("A &lt;title&gt;"), std::string::npos);
  EXPECT_NE(svg.find("s&amp;1"), std::string::npos);
  // NaN breaks the line: two "M" moves in the path.
  const auto path = svg.substr(svg.find("<path d=\""));
  EXPECT_EQ(std::count(path.begin(), path.begin() + static_cast<std::ptrdiff_t>(path.find("\"", 9)), 'M'), 2);
  EXPECT_THROW(p.addLine("bad", {1}, {1, 2}), std::invalid_argument);
}
