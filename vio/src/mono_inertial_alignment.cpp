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
// relative 1-σ (fit residuals, gravity direction free) exceeds init_mono_max_scale_sigma, or
// if a constant accelerometer error of init_mono_accel_error would move the scale by more than
// that (excitation test). Step 0 estimates the gyro bias first (init_mono_gyro_bias). Without
// those two a weakly accelerating flight passed the fit's check at a scale 35-40 % off
// (docs/vio_estimator.md, "Initialisation").
std::optional<MotionAlignment> alignMonoInMotion(const SriSwfConfig& cfg, const std::deque<FeatureFrame>& init_frames,
                                                std::span<const ImuSample> imu, const CameraExtrinsic& e0,
                                                 InitStatus* why) {
  auto fail = [why](InitStatus r) {
    if (why) *why = r;
    return std::nullopt;
  };
  const int N = cfg.init_mono_motion_frames;
  if (static_cast<int>(init_frames.size()) < N) return fail(InitStatus::kCollecting);
  const std::size_t first = init_frames.size() - static_cast<std::size_t>(N);
  const FeatureFrame& F0 = init_frames[first];
  const std::int64_t t0 = F0.t_ns;
  const std::int64_t tN = init_frames.back().t_ns;
  if (!imuCovers(imu, t0, tN)) return fail(InitStatus::kCollecting);
  const int M = N - 1;  // later frames
  std::vector<Eigen::Matrix3d> R0(static_cast<std::size_t>(M));
  std::vector<Eigen::Vector3d> alpha(static_cast<std::size_t>(M));
  std::vector<double> dts(static_cast<std::size_t>(M));
  std::vector<ImuIntegration> integs(static_cast<std::size_t>(M));
  auto integrateAll = [&](const Eigen::Vector3d& bg) {
    for (int j = 0; j < M; ++j) {
      const FeatureFrame& Fj = init_frames[first + 1 + static_cast<std::size_t>(j)];
      ImuIntegration& integ = integs[static_cast<std::size_t>(j)];
      integ = ImuIntegration(cfg.imu, bg, Eigen::Vector3d::Zero());
      integ.integrate(imu, t0, Fj.t_ns);
      R0[static_cast<std::size_t>(j)] = integ.gamma();
      alpha[static_cast<std::size_t>(j)] = integ.alpha();
      dts[static_cast<std::size_t>(j)] = static_cast<double>(Fj.t_ns - t0) * 1e-9;
    }
  };
  integrateAll(Eigen::Vector3d::Zero());
  // Rays in I_0 of every feature of F_0 in every later frame that sees it.
  auto ray = [](const Eigen::Vector2d& n) { return Eigen::Vector3d(n.x(), n.y(), 1.0).normalized(); };
  std::unordered_map<std::uint64_t, Eigen::Vector3d> f0;
  for (const FeatureObservation& o : F0.features) f0.emplace(o.id, e0.R_IC * ray(o.normalized0));
  // 0. Gyro bias from the epipolar constraints (cfg.init_mono_gyro_bias): the rays of F_0 and of
  // a later frame j, rotated into I_0 by the gyro-integrated R_0j(b_g), are coplanar with the
  // baseline d_j: d_j · (f_0 × R_0j r_j) = 0. Gauss-Newton on b_g over every frame with enough
  // features, d_j re-estimated (smallest eigenvector) each iteration. A turn-on gyro bias of
  // 0.015 rad/s rotates the rays of a 1 s window by 0.9°, as much as half the parallax needed.
  Eigen::Vector3d bg = Eigen::Vector3d::Zero();
  if (cfg.init_mono_gyro_bias) {
    std::vector<std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>>> pairs(static_cast<std::size_t>(M));
    for (int j = 0; j < M; ++j) {
      for (const FeatureObservation& o : init_frames[first + 1 + static_cast<std::size_t>(j)].features) {
        auto it = f0.find(o.id);
        if (it != f0.end()) pairs[static_cast<std::size_t>(j)].emplace_back(it->second, e0.R_IC * ray(o.normalized0));
      }
    }
    std::vector<Eigen::Matrix3d> Rb(static_cast<std::size_t>(M));
    // First-order bias correction of the zero-bias integrations (Forster et al. 2017, eq. 44):
    // |b| dt ≤ 0.1 rad in a 1 s window; the final bias is integrated exactly below.
    auto rotations = [&](const Eigen::Vector3d& b, std::vector<Eigen::Matrix3d>& out) {
      for (int j = 0; j < M; ++j) out[static_cast<std::size_t>(j)] = integs[static_cast<std::size_t>(j)].gammaFor(b);
    };
    // Normal of the plane of the pair's two rays (zero when they are parallel).
    auto planeNormal = [](const Eigen::Matrix3d& R0j, const std::pair<Eigen::Vector3d, Eigen::Vector3d>& p) {
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
    if (!ok || !bg.allFinite() || bg.norm() > cfg.init_mono_max_gyro_bias) bg.setZero();
    if (!bg.isZero()) integrateAll(bg);
  }
  std::vector<std::unordered_map<std::uint64_t, Eigen::Vector3d>> fj(static_cast<std::size_t>(M));
  int kbest = -1;
  double best = 0.0;
  bool tracked = false;  // some frame shares >= 20 features with F_0
  for (int j = 0; j < M; ++j) {
    std::vector<double> par;
    for (const FeatureObservation& o : init_frames[first + 1 + static_cast<std::size_t>(j)].features) {
      auto it = f0.find(o.id);
      if (it == f0.end()) continue;
      const Eigen::Vector3d r = R0[static_cast<std::size_t>(j)] * e0.R_IC * ray(o.normalized0);
      fj[static_cast<std::size_t>(j)].emplace(o.id, r);
      par.push_back(std::acos(std::clamp(r.dot(it->second), -1.0, 1.0)));
    }
    if (par.size() < 20) continue;
    tracked = true;
    const double med = initMedian(par);
    if (med > best) {
      best = med;
      kbest = j;
    }
  }
  if (!tracked) return fail(InitStatus::kTooFewTracks);
  if (kbest < 0 || best < 2.0 * M_PI / 180.0) return fail(InitStatus::kTooLittleParallax);
  const auto& fk = fj[static_cast<std::size_t>(kbest)];
  // 1. Baseline direction and unit-baseline structure (relative to C_0).
  Eigen::Matrix3d S = Eigen::Matrix3d::Zero();
  for (const auto& [id, rk] : fk) {
    const Eigen::Vector3d n = f0.at(id).cross(rk);
    if (n.norm() > 1e-9) S += n.normalized() * n.normalized().transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(S);
  Eigen::Vector3d d = es.eigenvectors().col(0);
  std::unordered_map<std::uint64_t, Eigen::Vector3d> pts;
  auto triangulateAll = [&](const Eigen::Vector3d& base) {
    pts.clear();
    int positive = 0;
    for (const auto& [id, rk] : fk) {
      const Eigen::Vector3d& r0 = f0.at(id);
      // P = λ r0 = base + μ rk (least squares in λ, μ).
      Eigen::Matrix<double, 3, 2> A;
      A << r0, -rk;
      const Eigen::Vector2d lm = (A.transpose() * A).ldlt().solve(A.transpose() * base);
      if (lm(0) > 0 && lm(1) > 0) {
        ++positive;
        pts.emplace(id, lm(0) * r0);
      }
    }
    return positive;
  };
  // Sign of the baseline: the one with more positive depths (pts then holds its points).
  const int forward = triangulateAll(d);
  int triangulated = triangulateAll(-d);
  if (triangulated > forward) {
    d = -d;
  } else {
    triangulated = triangulateAll(d);
  }
  if (triangulated < 20) return fail(InitStatus::kTooFewTracks);
  // 2. Camera centres c̄_j of all later frames from the bearings of the points.
  std::vector<Eigen::Vector3d> cbar(static_cast<std::size_t>(M));
  for (int j = 0; j < M; ++j) {
    Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
    Eigen::Vector3d g = Eigen::Vector3d::Zero();
    int n = 0;
    for (const auto& [id, r] : fj[static_cast<std::size_t>(j)]) {
      auto it = pts.find(id);
      if (it == pts.end()) continue;
      const Eigen::Matrix3d K = so3::skew(r);  // r × (P − c) = 0
      H += K.transpose() * K;
      g += K.transpose() * (K * it->second);
      ++n;
    }
    if (n < 10) return fail(InitStatus::kTooFewTracks);
    cbar[static_cast<std::size_t>(j)] = H.ldlt().solve(g);
  }
  // 3. s c̄_j − v₀ Δt_j − ½ g Δt_j² = α_j + (R_0j − I) p_IC; x = [s; v₀; g] or, with g = G·dir
  // + T δ, [s; v₀; δ]. Returns the 1-σ of s from the fit residuals.
  // da: a constant acceleration error added to every α_j (the excitation test below).
  auto solve = [&](const Eigen::Vector3d& g0, const Eigen::MatrixXd& T, Eigen::Matrix<double, 7, 1>& x,
                   const Eigen::Vector3d& da) {
    const int nx = 4 + static_cast<int>(T.cols());
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(nx, nx);
    Eigen::VectorXd b = Eigen::VectorXd::Zero(nx);
    for (int j = 0; j < M; ++j) {
      const double dt = dts[static_cast<std::size_t>(j)];
      Eigen::MatrixXd J(3, nx);
      J.col(0) = cbar[static_cast<std::size_t>(j)];
      J.block(0, 1, 3, 3) = -dt * Eigen::Matrix3d::Identity();
      J.rightCols(nx - 4) = -0.5 * dt * dt * T;
      const Eigen::Vector3d y = alpha[static_cast<std::size_t>(j)] + 0.5 * dt * dt * da +
                                (R0[static_cast<std::size_t>(j)] - Eigen::Matrix3d::Identity()) * e0.p_IC +
                                0.5 * dt * dt * g0;
      A += J.transpose() * J;
      b += J.transpose() * y;
    }
    const Eigen::VectorXd sol = A.ldlt().solve(b);
    x.head(4) = sol.head(4);
    x.tail(3) = g0 + T * sol.tail(nx - 4);
    double rss = 0.0;
    for (int j = 0; j < M; ++j) {
      const double dt = dts[static_cast<std::size_t>(j)];
      const Eigen::Vector3d e = x(0) * cbar[static_cast<std::size_t>(j)] - dt * x.segment(1, 3) -
                                0.5 * dt * dt * x.tail(3) - (alpha[static_cast<std::size_t>(j)] + 0.5 * dt * dt * da) -
                                (R0[static_cast<std::size_t>(j)] - Eigen::Matrix3d::Identity()) * e0.p_IC;
      rss += e.squaredNorm();
    }
    const double var = rss / std::max(1, 3 * M - nx);
    return std::sqrt(std::max(0.0, var * A.inverse()(0, 0)));
  };
  // Linear solve with |g| free, then |g| fixed and its direction refined; false if implausible.
  auto align = [&](Eigen::Matrix<double, 7, 1>& x, double& sSigma, const Eigen::Vector3d& da) {
    solve(Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity(), x, da);
    if (!(x(0) > 0.0) || std::abs(x.tail(3).norm() - cfg.gravity) > 1.0) return false;
    Eigen::Vector3d gdir = x.tail(3).normalized();
    sSigma = 0.0;  // of the last refinement, i.e. with the gravity direction free
    for (int it = 0; it < 4; ++it) {
      Eigen::Matrix<double, 3, 2> T;
      const Eigen::Vector3d e1 = gdir.unitOrthogonal();
      T << e1, gdir.cross(e1);
      sSigma = solve(cfg.gravity * gdir, T, x, da);
      gdir = x.tail(3).normalized();
    }
    solve(cfg.gravity * gdir, Eigen::MatrixXd(3, 0), x, da);
    return x(0) > 0.0;
  };
  Eigen::Matrix<double, 7, 1> x;
  double sSigma = 0.0;
  if (!align(x, sSigma, Eigen::Vector3d::Zero())) return fail(InitStatus::kInconsistent);
  if (sSigma > cfg.init_mono_max_scale_sigma * x(0)) return fail(InitStatus::kTooLittleAcceleration);
  // Excitation: the scale a constant accelerometer error of init_mono_accel_error (bias, and the
  // tilt that a wrong gravity direction leaves) along each body axis would give. The fit's own
  // residuals cannot show such a systematic error; with weak acceleration it moves the scale
  // by tens of percent while the residuals stay small.
  double sensitivity = 0.0;
  if (cfg.init_mono_accel_error > 0.0) {
    for (int k = 0; k < 3 && sensitivity <= cfg.init_mono_max_scale_sigma; ++k) {
      Eigen::Matrix<double, 7, 1> xk;
      double sk = 0.0;
      sensitivity = align(xk, sk, cfg.init_mono_accel_error * Eigen::Vector3d::Unit(k))
                        ? std::max(sensitivity, std::abs(xk(0) - x(0)) / x(0))
                        : std::numeric_limits<double>::infinity();
    }
  }
  if (sensitivity > cfg.init_mono_max_scale_sigma) return fail(InitStatus::kTooLittleAcceleration);
  const Eigen::Vector3d gb = x.tail(3);
  return MotionAlignment{t0, tN, gb, Eigen::Vector3d(x.segment(1, 3)), bg};
}


}  // namespace gvins::vio
