// Standstill test, stereo in-motion alignment and the frame buffer of the SRI-SWF estimator's
// initialisation (visual_inertial_initializer.hpp, docs/vio_estimator.md "Initialisation").
#include "gvins/vio/visual_inertial_initializer.hpp"

#include <algorithm>
#include <cmath>
#include <unordered_map>
#include <utility>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

#include "gvins/vio/imu_integration.hpp"
#include "gvins/vio/so3.hpp"

namespace gvins::vio {

double initMedian(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

bool imuAtRest(const SriSwfConfig& cfg, std::span<const ImuSample> imu, std::int64_t t0, std::int64_t t1,
               Eigen::Vector3d& ma, Eigen::Vector3d& mg, int& n) {
  ma.setZero();
  mg.setZero();
  Eigen::Vector3d sa = Eigen::Vector3d::Zero(), sg = Eigen::Vector3d::Zero();
  n = 0;
  for (const ImuSample& s : imu) {
    if (s.t_ns < t0 || s.t_ns > t1) continue;
    ma += s.accel;
    mg += s.gyro;
    sa += s.accel.cwiseAbs2();
    sg += s.gyro.cwiseAbs2();
    ++n;
  }
  if (n < 10) return false;
  ma /= n;
  mg /= n;
  const Eigen::Vector3d va = (sa / n - ma.cwiseAbs2()).cwiseMax(0.0);
  const Eigen::Vector3d vg = (sg / n - mg.cwiseAbs2()).cwiseMax(0.0);
  return std::sqrt(va.maxCoeff()) <= cfg.static_max_accel_std && std::sqrt(vg.maxCoeff()) <= cfg.static_max_gyro_std;
}

Standstill standstill(const SriSwfConfig& cfg, std::span<const ImuSample> imu, const FeatureFrame& frame,
                      const std::deque<FeatureFrame>& frames, Eigen::Vector3d& ma, Eigen::Vector3d& mg, int& n) {
  const std::int64_t t1 = frame.t_ns;
  const std::int64_t t0 = t1 - static_cast<std::int64_t>(cfg.init_window * 1e9);
  if (!imuCovers(imu, t0, t1)) return Standstill::kUndecided;
  const FeatureFrame* ref = nullptr;
  for (const FeatureFrame& fr : frames) {
    if (fr.t_ns >= t0) {
      ref = &fr;
      break;
    }
  }
  if (!ref || static_cast<double>(t1 - ref->t_ns) < 0.5e9 * cfg.init_window) return Standstill::kUndecided;
  if (!imuAtRest(cfg, imu, t0, t1, ma, mg, n)) return Standstill::kNo;
  std::unordered_map<std::uint64_t, Eigen::Vector2d> refpx;
  for (const FeatureObservation& o : ref->features) refpx.emplace(o.id, o.pixel0);
  std::vector<double> par;
  for (const FeatureObservation& o : frame.features) {
    auto it = refpx.find(o.id);
    if (it != refpx.end()) par.push_back((o.pixel0 - it->second).norm());
  }
  if (par.size() < 5) {
    // Without tracks the spread alone would pass a steady coordinated turn (constant specific force
    // and rate in the body): the IMU alone must also show gravity and a bias-sized rate.
    if (std::abs(ma.norm() - cfg.gravity) > 3.0 * cfg.static_max_accel_std || mg.norm() > cfg.init_mono_max_gyro_bias)
      return Standstill::kNo;
    // Features seen in the window but not tracked through it: the scene changes, so the quiet IMU
    // is a steady motion (a descent at constant rate towards the ground loses its tracks by the
    // expansion of the image), not a standstill. Only a camera that sees (almost) nothing over
    // the whole window leaves the IMU to decide alone.
    for (const FeatureFrame& fr : frames) {
      if (fr.t_ns >= t0 && fr.t_ns <= t1 && fr.features.size() >= 5) return Standstill::kFeaturesMove;
    }
    if (frame.features.size() >= 5) return Standstill::kFeaturesMove;
    return Standstill::kImuOnly;
  }
  return initMedian(par) <= cfg.static_max_parallax ? Standstill::kYes : Standstill::kFeaturesMove;
}

std::optional<double> stereoDepth(const SriSwfConfig& cfg, const CameraExtrinsic& e0, const CameraExtrinsic& e1,
                                  const FeatureObservation& o) {
  const Eigen::Matrix3d R10 = e1.R_IC.transpose() * e0.R_IC;
  const Eigen::Vector3d t10 = e1.R_IC.transpose() * (e0.p_IC - e1.p_IC);
  const Eigen::Vector3d b0(o.normalized0.x(), o.normalized0.y(), 1.0);
  const Eigen::Vector3d b1(o.normalized1.x(), o.normalized1.y(), 1.0);
  const Eigen::Vector3d a = b1.cross(R10 * b0);
  const Eigen::Vector3d c = b1.cross(t10);
  const double den = a.squaredNorm();
  if (den <= 0.0) return std::nullopt;
  const double d = -a.dot(c) / den;
  if (!(d >= cfg.min_depth && d <= cfg.max_depth)) return std::nullopt;
  return d;
}


// Linear visual-inertial alignment over the buffered stereo frames (in motion).
std::optional<MotionAlignment> alignStereoInMotion(const SriSwfConfig& cfg, const std::deque<FeatureFrame>& init_frames,
                                                  std::span<const ImuSample> imu, const CameraExtrinsic& e0,
                                                  const CameraExtrinsic& e1, InitStatus* why) {
  auto fail = [why](InitStatus r) {
    if (why) *why = r;
    return std::nullopt;
  };
  const int N = cfg.init_motion_frames;
  if (static_cast<int>(init_frames.size()) < N) return fail(InitStatus::kCollecting);
  const FeatureFrame& F0 = init_frames[init_frames.size() - static_cast<std::size_t>(N)];
  const std::int64_t t0 = F0.t_ns;
  const std::int64_t tN = init_frames.back().t_ns;
  if (!imuCovers(imu, t0, tN)) return fail(InitStatus::kCollecting);
  std::unordered_map<std::uint64_t, Eigen::Vector3d> pts;  // in I0
  for (const FeatureObservation& o : F0.features) {
    if (!o.stereo) continue;
    if (auto d = stereoDepth(cfg, e0, e1, o)) {
      pts.emplace(o.id, e0.R_IC * (*d * Eigen::Vector3d(o.normalized0.x(), o.normalized0.y(), 1.0)) + e0.p_IC);
    }
  }
  if (pts.size() < 15) return fail(InitStatus::kTooFewTracks);
  Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> b = Eigen::Matrix<double, 6, 1>::Zero();
  std::vector<double> dts;
  std::vector<Eigen::Vector3d> ys;
  for (std::size_t j = init_frames.size() - static_cast<std::size_t>(N) + 1; j < init_frames.size(); ++j) {
    const FeatureFrame& Fj = init_frames[j];
    ImuIntegration integ(cfg.imu, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
    integ.integrate(imu, t0, Fj.t_ns);
    const Eigen::Matrix3d R0j = integ.gamma();
    // Translation t of I_j in I_0 from bearings of the stereo points: [b]× p_Cj = 0.
    std::vector<std::pair<Eigen::Matrix3d, Eigen::Vector3d>> rows;
    for (const FeatureObservation& o : Fj.features) {
      auto it = pts.find(o.id);
      if (it == pts.end()) continue;
      const Eigen::Vector3d bj = Eigen::Vector3d(o.normalized0.x(), o.normalized0.y(), 1.0).normalized();
      const Eigen::Matrix3d K = so3::skew(bj) * e0.R_IC.transpose();
      rows.emplace_back(-K * R0j.transpose(), -K * (R0j.transpose() * it->second - e0.p_IC));
    }
    if (rows.size() < 10) return fail(InitStatus::kTooFewTracks);
    Eigen::Vector3d t = Eigen::Vector3d::Zero();
    std::vector<char> use(rows.size(), 1);
    for (int pass = 0; pass < 2; ++pass) {
      Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
      Eigen::Vector3d g = Eigen::Vector3d::Zero();
      for (std::size_t k = 0; k < rows.size(); ++k) {
        if (!use[k]) continue;
        H += rows[k].first.transpose() * rows[k].first;
        g += rows[k].first.transpose() * rows[k].second;
      }
      t = H.ldlt().solve(g);
      std::vector<double> res(rows.size());
      for (std::size_t k = 0; k < rows.size(); ++k) res[k] = (rows[k].first * t - rows[k].second).norm();
      const double med = initMedian(res);
      for (std::size_t k = 0; k < rows.size(); ++k) use[k] = res[k] <= 3.0 * med + 1e-12;
    }
    const double dt = static_cast<double>(Fj.t_ns - t0) * 1e-9;
    const Eigen::Vector3d y = t - integ.alpha();
    Eigen::Matrix<double, 3, 6> J;
    J << dt * Eigen::Matrix3d::Identity(), 0.5 * dt * dt * Eigen::Matrix3d::Identity();
    A += J.transpose() * J;
    b += J.transpose() * y;
    dts.push_back(dt);
    ys.push_back(y);
  }
  const Eigen::Matrix<double, 6, 1> x = A.ldlt().solve(b);
  Eigen::Vector3d gb = x.tail<3>();
  if (std::abs(gb.norm() - cfg.gravity) > 1.0) return fail(InitStatus::kInconsistent);
  gb *= cfg.gravity / gb.norm();
  double sdd = 0.0;
  Eigen::Vector3d sv = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < dts.size(); ++k) {
    sv += dts[k] * (ys[k] - 0.5 * dts[k] * dts[k] * gb);
    sdd += dts[k] * dts[k];
  }
  const Eigen::Vector3d vb = sv / sdd;
  return MotionAlignment{t0, tN, gb, vb, Eigen::Vector3d::Zero()};
}


std::optional<InitialState> VisualInertialInitializer::fromStandstill(const FeatureFrame& frame,
                                                                    std::span<const ImuSample> imu) {
  const SriSwfConfig& cfg = cfg_;
  Eigen::Vector3d ma, mg;
  int n = 0;
  const Standstill st = standstill(cfg, imu, frame, frames_, ma, mg, n);
  standstill_ = st;
  if (!(st == Standstill::kYes || (st == Standstill::kImuOnly && cfg.init_static_without_tracks))) {
    status_ = st == Standstill::kImuOnly        ? InitStatus::kStaticNoTracks
              : st == Standstill::kFeaturesMove ? InitStatus::kMovingNoAcceleration
                                                : InitStatus::kCollecting;
    return std::nullopt;
  }
  const std::int64_t t1 = frame.t_ns;
  ImuState s;
  s.t_ns = t1;
  s.R_WI = Eigen::Quaterniond::FromTwoVectors(ma.normalized(), Eigen::Vector3d::UnitZ()).toRotationMatrix();
  s.bg = mg;
  const double sigma_mean = cfg.imu.gyroscope_noise_density * std::sqrt(cfg.imu.rate_hz) / std::sqrt(double(n));
  const double sbg = std::max(5.0 * sigma_mean, 1e-3);
  const Eigen::Matrix3d Pw =
      Eigen::Vector3d(cfg.init_tilt_sigma * cfg.init_tilt_sigma, cfg.init_tilt_sigma * cfg.init_tilt_sigma,
                      cfg.init_yaw_sigma * cfg.init_yaw_sigma)
          .asDiagonal();
  return InitialState{s, Pw, cfg.init_velocity_sigma, sbg};
}


// State from an in-motion alignment: gravity and velocity in the IMU frame at t0
// (attitude from gravity, yaw 0), propagated to tN; tilt prior 1.5× init_tilt_sigma, velocity
// prior 3× init_velocity_sigma and (mono) the scale's relative σ times the speed.
InitialState VisualInertialInitializer::fromMotion(const MotionAlignment& a, std::span<const ImuSample> imu) const {
  const SriSwfConfig& cfg = cfg_;
  ImuState s;
  s.t_ns = a.t0;
  s.bg = a.gyro_bias;
  s.R_WI = Eigen::Quaterniond::FromTwoVectors(-a.gravity_I0.normalized(), Eigen::Vector3d::UnitZ()).toRotationMatrix();
  s.v_WI = s.R_WI * a.velocity_I0;
  prop_.propagate(s, imu, a.tN);
  const double tilt = 1.5 * cfg.init_tilt_sigma;
  const Eigen::Matrix3d Pw =
      Eigen::Vector3d(tilt * tilt, tilt * tilt, cfg.init_yaw_sigma * cfg.init_yaw_sigma).asDiagonal();
  const double sigma_v = std::hypot(3.0 * cfg.init_velocity_sigma, a.scale_sigma * s.v_WI.norm());
  return InitialState{s, Pw, sigma_v, cfg.init_gyro_bias_sigma};
}


// Bounded cost (issue 43): the mono alignment runs only when the cheap excitation test passes, at
// most every init_mono_attempt_interval after a failure, and less often while it keeps failing for
// the same reason.
std::optional<MotionAlignment> VisualInertialInitializer::tryMono(const FeatureFrame& frame,
                                                                 std::span<const ImuSample> imu,
                                                                 const CameraExtrinsic& e0) {
  const SriSwfConfig& cfg = cfg_;
  const int N = cfg.init_mono_motion_frames;
  if (static_cast<int>(frames_.size()) < N) {
    status_ = InitStatus::kCollecting;
    return std::nullopt;
  }
  const std::int64_t t0 = frames_[frames_.size() - static_cast<std::size_t>(N)].t_ns;
  if (cfg.init_mono_min_accel_change > 0.0) {
    const std::optional<double> ex = accelerationChange(imu, t0, frame.t_ns);
    if (!ex) {
      status_ = InitStatus::kCollecting;
      return std::nullopt;
    }
    if (*ex < cfg.init_mono_min_accel_change) {
      // The standstill test's finding (at rest without tracks, constant velocity) says more.
      if (status_ != InitStatus::kStaticNoTracks && status_ != InitStatus::kMovingNoAcceleration)
        status_ = InitStatus::kTooLittleAcceleration;
      return std::nullopt;
    }
  }
  // Back-off: the interval doubles (up to 8 init_mono_attempt_interval) while the attempts fail for
  // the same reason, and returns to init_mono_attempt_interval when the reason changes.
  if (last_attempt_ns_ && static_cast<double>(frame.t_ns - *last_attempt_ns_) * 1e-9 < attempt_interval_) {
    status_ = last_attempt_status_;  // the reason found by the last attempt still stands
    return std::nullopt;
  }
  const bool again = last_attempt_ns_.has_value();
  last_attempt_ns_ = frame.t_ns;
  ++work_.mono_attempts;
  std::optional<MotionAlignment> a = alignMonoInMotion(cfg, frames_, imu, e0, &status_, &work_.mono_imu_intervals);
  attempt_interval_ = again && status_ == last_attempt_status_
                          ? std::min(2.0 * attempt_interval_, 8.0 * cfg.init_mono_attempt_interval)
                          : cfg.init_mono_attempt_interval;
  last_attempt_status_ = status_;
  return a;
}

std::optional<double> accelerationChange(std::span<const ImuSample> imu, std::int64_t t0, std::int64_t t1) {
  if (!imuCovers(imu, t0, t1) || t1 - t0 < 200'000'000) return std::nullopt;
  // Specific force rotated into the frame at t0 by the integrated gyro (first order per sample),
  // averaged over 0.1 s bins; the result is the largest distance of a bin mean from their mean.
  auto it = std::lower_bound(imu.begin(), imu.end(), t0, [](const ImuSample& a, std::int64_t t) { return a.t_ns < t; });
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  std::vector<Eigen::Vector3d> bins;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int count = 0;
  std::int64_t bin_end = t0 + 100'000'000;
  std::int64_t prev = it->t_ns;
  for (; it != imu.end() && it->t_ns <= t1; ++it) {
    const double dt = static_cast<double>(it->t_ns - prev) * 1e-9;
    prev = it->t_ns;
    R = R * so3::exp(it->gyro * dt);
    if (it->t_ns > bin_end) {
      if (count > 0) bins.push_back(sum / count);
      sum.setZero();
      count = 0;
      bin_end += 100'000'000;
    }
    sum += R * it->accel;
    ++count;
  }
  if (count > 0) bins.push_back(sum / count);
  if (bins.size() < 2) return std::nullopt;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& b : bins) mean += b;
  mean /= static_cast<double>(bins.size());
  double worst = 0.0;
  for (const Eigen::Vector3d& b : bins) worst = std::max(worst, (b - mean).norm());
  return worst;
}

std::optional<InitialState> VisualInertialInitializer::tryInitialize(const FeatureFrame& frame,
                                                                   std::span<const ImuSample> imu,
                                                                   const std::vector<CameraExtrinsic>& ext) {
  const SriSwfConfig& cfg = cfg_;
  const bool stereo = cfg.cameras.size() > 1;
  ++work_.frames;
  frames_.push_back(frame);
  const std::int64_t horizon = static_cast<std::int64_t>(cfg.init_window * 1e9);
  const int keep = stereo ? cfg.init_motion_frames : cfg.init_mono_motion_frames;
  while (frames_.size() > static_cast<std::size_t>(keep) && frame.t_ns - frames_.front().t_ns > horizon) {
    frames_.pop_front();
  }
  std::optional<InitialState> s = fromStandstill(frame, imu);
  // A start at rest is the standstill test's to decide: while its window is not complete and the
  // IMU rests over the buffered frames, the in-motion alignment (which a 10 Hz rig completes
  // before one init_window) would fit a velocity to stereo noise (far points of a forward camera)
  // with the prior σ of a motion, 3 init_velocity_sigma; it waits for the standstill test.
  Eigen::Vector3d ma, mg;
  int n = 0;
  const bool resting = standstill_ == Standstill::kUndecided &&
                       imuAtRest(cfg, imu, frames_.front().t_ns, frame.t_ns, ma, mg, n);
  if (!s && cfg.init_in_motion && !resting) {
    std::optional<MotionAlignment> a;
    if (stereo) {
      a = alignStereoInMotion(cfg, frames_, imu, ext[0], ext[1], &status_);
    } else if (cfg.init_mono_in_motion) {
      a = tryMono(frame, imu, ext[0]);
    }
    if (a) s = fromMotion(*a, imu);
  }
  if (s) {
    frames_.clear();
    status_ = InitStatus::kInitialized;
  }
  return s;
}

}  // namespace gvins::vio
