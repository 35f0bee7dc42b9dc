// Mono in-motion visual-inertial alignment of the SRI-SWF estimator's initialisation
// (visual_inertial_initializer.hpp, docs/vio_estimator.md "Initialisation", "In motion (mono)").
#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>
#include <utility>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "gvins/vio/imu_integration.hpp"
#include "gvins/vio/so3.hpp"
#include "gvins/vio/visual_inertial_initializer.hpp"

namespace gvins::vio {
// Mono in-motion alignment (no stereo depth), over the last init_mono_motion_frames frames
// F_0..F_N−1, in the IMU frame I_0 of F_0, with the gyro-integrated rotations R_0j and the
// preintegrated positions α_j (ImuIntegration, biases zero):
//  1. structure up to scale: the frame k with the largest rotation-compensated parallax to F_0
//     gives the baseline direction of the camera centres (C_k − C_0 ⊥ f_0 × f_k for every
//     feature, f the rays in I_0: smallest singular vector; sign from the depths), and the
//     features of F_0 and F_k are triangulated with a unit baseline;
//  2. every frame's camera centre c̄_j (same unknown scale) from the bearings of those points,
//     linear least squares as in the stereo alignment;
//  3. s c̄_j = C_j − C_0 = v₀ Δt_j + ½ g Δt_j² + α_j + (R_0j − I) p_IC: linear in (s, v₀, g);
//     then |g| is fixed to the configured value and its direction refined on the sphere (two
//     tangent unknowns, four iterations, as in VINS-Mono's gravity refinement).
// The metric scale comes from the accelerometer, so the motion needs acceleration; the
// alignment is rejected if the scale is not positive, the free |g| is more than 1 m/s² off, the
// parallax is below 2°, fewer than 20 features are tracked through the window, or the scale's
// relative 1-σ exceeds init_mono_max_scale_sigma: the fit residuals' part (gravity direction free)
// and the accelerometer's part (the scale change a constant error of init_mono_accel_error along
// the worst body axis gives) combined. Step 0 estimates the gyro bias first
// (init_mono_gyro_bias). Without those a weakly accelerating flight passed the fit's check at a
// scale 35-40 % off (docs/vio_estimator.md, "Initialisation").
namespace {

Eigen::Vector3d ray(const Eigen::Vector2d& n) { return Eigen::Vector3d(n.x(), n.y(), 1.0).normalized(); }

using RayPair = std::pair<Eigen::Vector3d, Eigen::Vector3d>;

/// The window F_0..F_N−1 of the mono alignment and its steps (numbered as above).
class MonoWindow {
 public:
  MonoWindow(const SriSwfConfig& cfg, const std::deque<FeatureFrame>& frames, std::size_t first,
             std::span<const ImuSample> imu, const CameraExtrinsic& e0)
      : cfg_(cfg), frames_(frames), first_(first), M_(cfg.init_mono_motion_frames - 1), t0_(frames[first].t_ns),
        imu_(imu), e0_(e0), R0_(static_cast<std::size_t>(M_)), alpha_(static_cast<std::size_t>(M_)),
        alphaBa_(static_cast<std::size_t>(M_)), dts_(static_cast<std::size_t>(M_)), integs_(static_cast<std::size_t>(M_)) {
    integrateAll(Eigen::Vector3d::Zero());
    // Rays in I_0 of every feature of F_0.
    for (const FeatureObservation& o : frames_[first_].features) f0_.emplace(o.id, e0_.R_IC * ray(o.normalized0));
  }

  /// The IMU integrations from F_0 to every later frame with gyro bias bg: one pass over the
  /// window's samples, extended from frame to frame (issue 43: bounded work per attempt).
  void integrateAll(const Eigen::Vector3d& bg) {
    ImuIntegration integ(cfg_.imu, bg, Eigen::Vector3d::Zero());
    integ.integrate(imu_, t0_, t0_);
    for (int j = 0; j < M_; ++j) {
      const FeatureFrame& Fj = frame(j);
      integ.extend(imu_, Fj.t_ns);
      integs_[static_cast<std::size_t>(j)] = integ;
      R0_[static_cast<std::size_t>(j)] = integ.gamma();
      alpha_[static_cast<std::size_t>(j)] = integ.alpha();
      alphaBa_[static_cast<std::size_t>(j)] = -integ.biasJacobian().block<3, 3>(3, 3);
      dts_[static_cast<std::size_t>(j)] = static_cast<double>(Fj.t_ns - t0_) * 1e-9;
    }
    imu_intervals_ += integ.intervals();
  }
  /// IMU sample intervals integrated so far (all passes).
  std::int64_t imuIntervals() const { return imu_intervals_; }

  Eigen::Vector3d gyroBias();
  std::optional<InitStatus> structure();
  std::optional<InitStatus> cameraCentres();
  bool align(Eigen::Matrix<double, 7, 1>& x, double& sSigma, const Eigen::Vector3d& da) const;

 private:
  const FeatureFrame& frame(int j) const { return frames_[first_ + 1 + static_cast<std::size_t>(j)]; }
  int triangulateAll(const Eigen::Vector3d& base);
  double solve(const Eigen::Vector3d& g0, const Eigen::MatrixXd& T, Eigen::Matrix<double, 7, 1>& x,
               const Eigen::Vector3d& da) const;

  const SriSwfConfig& cfg_;
  const std::deque<FeatureFrame>& frames_;
  std::size_t first_;
  int M_;  // later frames
  std::int64_t t0_;
  std::span<const ImuSample> imu_;
  const CameraExtrinsic& e0_;
  std::vector<Eigen::Matrix3d> R0_;
  std::vector<Eigen::Vector3d> alpha_;
  std::vector<Eigen::Matrix3d> alphaBa_;  // dα_j / d(accelerometer error in the body): ∫∫ R_0(t)
  std::vector<double> dts_;
  std::vector<ImuIntegration> integs_;
  std::unordered_map<std::uint64_t, Eigen::Vector3d> f0_;
  std::vector<std::unordered_map<std::uint64_t, Eigen::Vector3d>> fj_;
  int kbest_ = -1;
  std::unordered_map<std::uint64_t, Eigen::Vector3d> pts_;
  std::vector<Eigen::Vector3d> cbar_;
  std::int64_t imu_intervals_ = 0;
};

// 0. Gyro bias from the epipolar constraints (cfg.init_mono_gyro_bias): the rays of F_0 and of
// a later frame j, rotated into I_0 by the gyro-integrated R_0j(b_g), are coplanar with the
// baseline d_j: d_j · (f_0 × R_0j r_j) = 0. Gauss-Newton on b_g over every frame with enough
// features, d_j re-estimated (smallest eigenvector) each iteration. A turn-on gyro bias of
// 0.015 rad/s rotates the rays of a 1 s window by 0.9°, as much as half the parallax needed.
Eigen::Vector3d MonoWindow::gyroBias() {
  const int M = M_;
  std::vector<std::vector<RayPair>> pairs(static_cast<std::size_t>(M));
  for (int j = 0; j < M; ++j) {
    for (const FeatureObservation& o : frame(j).features) {
      auto it = f0_.find(o.id);
      if (it != f0_.end()) pairs[static_cast<std::size_t>(j)].emplace_back(it->second, e0_.R_IC * ray(o.normalized0));
    }
  }
  std::vector<Eigen::Matrix3d> Rb(static_cast<std::size_t>(M));
  // First-order bias correction of the zero-bias integrations (Forster et al. 2017, eq. 44):
  // |b| dt ≤ 0.1 rad in a 1 s window; the final bias is integrated exactly afterwards.
  auto rotations = [&](const Eigen::Vector3d& b, std::vector<Eigen::Matrix3d>& out) {
    for (int j = 0; j < M; ++j) out[static_cast<std::size_t>(j)] = integs_[static_cast<std::size_t>(j)].gammaFor(b);
  };
  // Normal of the plane of the pair's two rays (zero when they are parallel).
  auto planeNormal = [](const Eigen::Matrix3d& R0j, const RayPair& p) {
    const Eigen::Vector3d n = p.first.cross(R0j * p.second);
    return n.norm() > 1e-9 ? Eigen::Vector3d(n.normalized()) : Eigen::Vector3d::Zero();
  };
  // Residuals d_j · n̂ of frames j ≥ M/2 (the longer baselines) with ≥ 20 shared features.
  auto residuals = [&](const std::vector<Eigen::Matrix3d>& R, const std::vector<Eigen::Vector3d>& d,
                       std::vector<double>& e) {
    e.clear();
    for (int j = M / 2; j < M; ++j) {
      const auto& pj = pairs[static_cast<std::size_t>(j)];
      if (pj.size() < 20) continue;
      for (const auto& p : pj) e.push_back(d[static_cast<std::size_t>(j)].dot(planeNormal(R[static_cast<std::size_t>(j)], p)));
    }
  };
  Eigen::Vector3d bg = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> d(static_cast<std::size_t>(M), Eigen::Vector3d::Zero());
  bool ok = true;
  for (int it = 0; it < 6; ++it) {
    rotations(bg, Rb);
    for (int j = M / 2; j < M; ++j) {
      Eigen::Matrix3d S = Eigen::Matrix3d::Zero();
      for (const auto& p : pairs[static_cast<std::size_t>(j)]) {
        const Eigen::Vector3d n = planeNormal(Rb[static_cast<std::size_t>(j)], p);
        S += n * n.transpose();
      }
      d[static_cast<std::size_t>(j)] = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(S).eigenvectors().col(0);
    }
    std::vector<double> e0v, ek;
    residuals(Rb, d, e0v);
    if (e0v.size() < 40) {
      ok = false;
      break;
    }
    Eigen::MatrixXd J(static_cast<Eigen::Index>(e0v.size()), 3);
    constexpr double h = 1e-5;  // rad/s
    std::vector<Eigen::Matrix3d> Rh(static_cast<std::size_t>(M));
    for (int k = 0; k < 3; ++k) {
      rotations(bg + h * Eigen::Vector3d::Unit(k), Rh);
      residuals(Rh, d, ek);
      for (std::size_t i = 0; i < e0v.size(); ++i) J(static_cast<Eigen::Index>(i), k) = (ek[i] - e0v[i]) / h;
    }
    const Eigen::VectorXd e = Eigen::Map<const Eigen::VectorXd>(e0v.data(), static_cast<Eigen::Index>(e0v.size()));
    const Eigen::Vector3d step = -(J.transpose() * J).ldlt().solve(J.transpose() * e);
    if (!step.allFinite()) {
      ok = false;
      break;
    }
    bg += step;
    if (step.norm() < 1e-6) break;
  }
  // A bias beyond any plausible turn-on value means the constraint was degenerate: keep none.
  if (!ok || !bg.allFinite() || bg.norm() > cfg_.init_mono_max_gyro_bias) bg.setZero();
  return bg;
}

// P = λ r0 = base + μ rk (least squares in λ, μ) for every feature of F_0 and F_k; the points
// with positive depths go to pts_, their count is returned.
int MonoWindow::triangulateAll(const Eigen::Vector3d& base) {
  const auto& fk = fj_[static_cast<std::size_t>(kbest_)];
  pts_.clear();
  int positive = 0;
  for (const auto& [id, rk] : fk) {
    const Eigen::Vector3d& r0 = f0_.at(id);
    Eigen::Matrix<double, 3, 2> A;
    A << r0, -rk;
    const Eigen::Vector2d lm = (A.transpose() * A).ldlt().solve(A.transpose() * base);
    if (lm(0) > 0 && lm(1) > 0) {
      ++positive;
      pts_.emplace(id, lm(0) * r0);
    }
  }
  return positive;
}

// 1. The frame with the largest median parallax to F_0, the baseline direction and the
// unit-baseline structure (relative to C_0). nullopt on success, else why not.
std::optional<InitStatus> MonoWindow::structure() {
  fj_.assign(static_cast<std::size_t>(M_), {});
  double best = 0.0;
  bool tracked = false;  // some frame shares >= 20 features with F_0
  for (int j = 0; j < M_; ++j) {
    std::vector<double> par;
    for (const FeatureObservation& o : frame(j).features) {
      auto it = f0_.find(o.id);
      if (it == f0_.end()) continue;
      const Eigen::Vector3d r = R0_[static_cast<std::size_t>(j)] * e0_.R_IC * ray(o.normalized0);
      fj_[static_cast<std::size_t>(j)].emplace(o.id, r);
      par.push_back(std::acos(std::clamp(r.dot(it->second), -1.0, 1.0)));
    }
    if (par.size() < 20) continue;
    tracked = true;
    const double med = initMedian(par);
    if (med > best) {
      best = med;
      kbest_ = j;
    }
  }
  if (!tracked) return InitStatus::kTooFewTracks;
  if (kbest_ < 0 || best < 2.0 * M_PI / 180.0) return InitStatus::kTooLittleParallax;
  const auto& fk = fj_[static_cast<std::size_t>(kbest_)];
  Eigen::Matrix3d S = Eigen::Matrix3d::Zero();
  for (const auto& [id, rk] : fk) {
    const Eigen::Vector3d n = f0_.at(id).cross(rk);
    if (n.norm() > 1e-9) S += n.normalized() * n.normalized().transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(S);
  Eigen::Vector3d d = es.eigenvectors().col(0);
  // Sign of the baseline: the one with more positive depths (pts_ then holds its points).
  const int forward = triangulateAll(d);
  int triangulated = triangulateAll(-d);
  if (triangulated > forward) {
    d = -d;
  } else {
    triangulated = triangulateAll(d);
  }
  if (triangulated < 20) return InitStatus::kTooFewTracks;
  return std::nullopt;
}

// 2. Camera centres c̄_j of all later frames from the bearings of the points.
std::optional<InitStatus> MonoWindow::cameraCentres() {
  cbar_.assign(static_cast<std::size_t>(M_), Eigen::Vector3d::Zero());
  for (int j = 0; j < M_; ++j) {
    Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
    Eigen::Vector3d g = Eigen::Vector3d::Zero();
    int n = 0;
    for (const auto& [id, r] : fj_[static_cast<std::size_t>(j)]) {
      auto it = pts_.find(id);
      if (it == pts_.end()) continue;
      const Eigen::Matrix3d K = so3::skew(r);  // r × (P − c) = 0
      H += K.transpose() * K;
      g += K.transpose() * (K * it->second);
      ++n;
    }
    if (n < 10) return InitStatus::kTooFewTracks;
    cbar_[static_cast<std::size_t>(j)] = H.ldlt().solve(g);
  }
  return std::nullopt;
}

// 3. s c̄_j − v₀ Δt_j − ½ g Δt_j² = α_j + (R_0j − I) p_IC; x = [s; v₀; g] or, with g = G·dir
// + T δ, [s; v₀; δ]. Returns the 1-σ of s from the fit residuals.
// da: a constant accelerometer error in the body frame, added to every α_j through ∫∫ R_0(t)
// (the excitation test; a body that turns carries it round, so it does not stay along gravity).
double MonoWindow::solve(const Eigen::Vector3d& g0, const Eigen::MatrixXd& T, Eigen::Matrix<double, 7, 1>& x,
                         const Eigen::Vector3d& da) const {
  const int M = M_;
  const int nx = 4 + static_cast<int>(T.cols());
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(nx, nx);
  Eigen::VectorXd b = Eigen::VectorXd::Zero(nx);
  for (int j = 0; j < M; ++j) {
    const double dt = dts_[static_cast<std::size_t>(j)];
    Eigen::MatrixXd J(3, nx);
    J.col(0) = cbar_[static_cast<std::size_t>(j)];
    J.block(0, 1, 3, 3) = -dt * Eigen::Matrix3d::Identity();
    J.rightCols(nx - 4) = -0.5 * dt * dt * T;
    const Eigen::Vector3d y = alpha_[static_cast<std::size_t>(j)] + alphaBa_[static_cast<std::size_t>(j)] * da +
                              (R0_[static_cast<std::size_t>(j)] - Eigen::Matrix3d::Identity()) * e0_.p_IC +
                              0.5 * dt * dt * g0;
    A += J.transpose() * J;
    b += J.transpose() * y;
  }
  const Eigen::VectorXd sol = A.ldlt().solve(b);
  x.head(4) = sol.head(4);
  x.tail(3) = g0 + T * sol.tail(nx - 4);
  double rss = 0.0;
  for (int j = 0; j < M; ++j) {
    const double dt = dts_[static_cast<std::size_t>(j)];
    const Eigen::Vector3d e = x(0) * cbar_[static_cast<std::size_t>(j)] - dt * x.segment(1, 3) -
                              0.5 * dt * dt * x.tail(3) - (alpha_[static_cast<std::size_t>(j)] + alphaBa_[static_cast<std::size_t>(j)] * da) -
                              (R0_[static_cast<std::size_t>(j)] - Eigen::Matrix3d::Identity()) * e0_.p_IC;
    rss += e.squaredNorm();
  }
  const double var = rss / std::max(1, 3 * M - nx);
  return std::sqrt(std::max(0.0, var * A.inverse()(0, 0)));
}

// Linear solve with |g| free, then |g| fixed and its direction refined; false if implausible.
bool MonoWindow::align(Eigen::Matrix<double, 7, 1>& x, double& sSigma, const Eigen::Vector3d& da) const {
  solve(Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity(), x, da);
  if (!(x(0) > 0.0) || std::abs(x.tail(3).norm() - cfg_.gravity) > 1.0) return false;
  Eigen::Vector3d gdir = x.tail(3).normalized();
  sSigma = 0.0;  // of the last refinement, i.e. with the gravity direction free
  for (int it = 0; it < 4; ++it) {
    Eigen::Matrix<double, 3, 2> T;
    const Eigen::Vector3d e1 = gdir.unitOrthogonal();
    T << e1, gdir.cross(e1);
    sSigma = solve(cfg_.gravity * gdir, T, x, da);
    gdir = x.tail(3).normalized();
  }
  solve(cfg_.gravity * gdir, Eigen::MatrixXd(3, 0), x, da);
  return x(0) > 0.0;
}

}  // namespace

std::optional<MotionAlignment> alignMonoInMotion(const SriSwfConfig& cfg, const std::deque<FeatureFrame>& init_frames,
                                                 std::span<const ImuSample> imu, const CameraExtrinsic& e0,
                                                 InitStatus* why, std::int64_t* imu_intervals,
                                                 MonoAlignmentQuality* quality) {
  auto fail = [why](InitStatus r) {
    if (why) *why = r;
    return std::nullopt;
  };
  const int N = cfg.init_mono_motion_frames;
  if (static_cast<int>(init_frames.size()) < N) return fail(InitStatus::kCollecting);
  const std::size_t first = init_frames.size() - static_cast<std::size_t>(N);
  const std::int64_t t0 = init_frames[first].t_ns;
  const std::int64_t tN = init_frames.back().t_ns;
  if (!imuCovers(imu, t0, tN)) return fail(InitStatus::kCollecting);
  MonoWindow w(cfg, init_frames, first, imu, e0);
  Eigen::Vector3d bg = Eigen::Vector3d::Zero();
  if (cfg.init_mono_gyro_bias) {
    bg = w.gyroBias();
    if (!bg.isZero()) w.integrateAll(bg);
  }
  if (imu_intervals) *imu_intervals += w.imuIntervals();
  if (const auto bad = w.structure()) return fail(*bad);
  if (const auto bad = w.cameraCentres()) return fail(*bad);
  Eigen::Matrix<double, 7, 1> x;
  double sSigma = 0.0;
  if (!w.align(x, sSigma, Eigen::Vector3d::Zero())) return fail(InitStatus::kInconsistent);
  if (quality) *quality = MonoAlignmentQuality{N, static_cast<double>(tN - t0) * 1e-9, x(0), sSigma / x(0), 0.0};
  const double bound = cfg.init_mono_max_scale_sigma;
  if (sSigma > bound * x(0)) return fail(InitStatus::kTooLittleAcceleration);
  // Excitation: the scale a constant accelerometer error of init_mono_accel_error (bias, and the
  // tilt that a wrong gravity direction leaves) along each body axis would give. The fit's own
  // residuals cannot show such a systematic error; with weak acceleration it moves the scale
  // by tens of percent while the residuals stay small. It is the accelerometer's part of the
  // scale's σ, combined with the residuals' part.
  double sensitivity = 0.0;
  auto combined = [&] { return std::hypot(sSigma / x(0), sensitivity); };
  if (cfg.init_mono_accel_error > 0.0) {
    for (int k = 0; k < 3 && combined() <= bound; ++k) {
      Eigen::Matrix<double, 7, 1> xk;
      double sk = 0.0;
      sensitivity = w.align(xk, sk, cfg.init_mono_accel_error * Eigen::Vector3d::Unit(k))
                        ? std::max(sensitivity, std::abs(xk(0) - x(0)) / x(0))
                        : std::numeric_limits<double>::infinity();
    }
  }
  if (quality) quality->sensitivity = sensitivity;
  if (combined() > bound) return fail(InitStatus::kTooLittleAcceleration);
  const Eigen::Vector3d gb = x.tail(3);
  return MotionAlignment{t0, tN, gb, Eigen::Vector3d(x.segment(1, 3)), bg, combined()};
}

}  // namespace gvins::vio
