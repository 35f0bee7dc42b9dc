// A self-contained visual-inertial simulation for the estimator tests: the analytic UAV circle of
// analytic_motion.hpp (20 m radius, 8 m/s, 30 m height, attitude wobble) or a standstill, a
// down-looking stereo rig, random ground landmarks, noisy pixel tracks (finite track lives) and
// a noisy IMU with turn-on biases and bias random walks (Kalibr discrete model, imu_noise.hpp).
// The truth (pose, velocity, biases) is known exactly at every frame.
#pragma once

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "analytic_motion.hpp"
#include "gvins/vio/feature_frame.hpp"
#include "gvins/vio/imu_sample.hpp"
#include "gvins/vio/imu_state.hpp"
#include "gvins/vio/sri_swf_estimator.hpp"

namespace gvins::vio::test {

struct SimScene {
  bool moving = true;  ///< false: standstill at 1.5 m above the landmarks
  double duration = 60.0;
  double imu_rate = 200.0;
  double cam_rate = 20.0;
  double pixel_noise = 0.5;
  double baseline = 0.4;
  int max_features = 150;
  double track_life = 3.0;  ///< s, mean life of a track before the tracker loses it
  std::uint64_t seed = 1;
  ImuNoise noise;

  AnalyticMotion motion;
  std::vector<Eigen::Vector3d> landmarks;
  std::vector<ImuSample> imu;
  std::vector<Eigen::Vector3d> bg_true, ba_true;  // per IMU sample
  std::vector<FeatureFrame> frames;
  CameraCalibration cam[2];

  Eigen::Matrix3d R(double t) const { return moving ? motion.R(t) : Eigen::Matrix3d(AnalyticMotion::rz(0.3)); }
  Eigen::Vector3d p(double t) const { return moving ? motion.p(t) : Eigen::Vector3d(1.0, 2.0, 1.5); }
  Eigen::Vector3d v(double t) const { return moving ? motion.v(t) : Eigen::Vector3d::Zero(); }

  ImuState truth(std::int64_t t_ns) const {
    const double t = static_cast<double>(t_ns) * 1e-9;
    ImuState s;
    s.t_ns = t_ns;
    s.R_WI = R(t);
    s.p_WI = p(t);
    s.v_WI = v(t);
    const auto k = static_cast<std::size_t>(std::llround(t * imu_rate));
    s.bg = bg_true[std::min(k, bg_true.size() - 1)];
    s.ba = ba_true[std::min(k, ba_true.size() - 1)];
    return s;
  }

  void build() {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> N(0.0, 1.0);
    std::uniform_real_distribution<double> U(0.0, 1.0);
    // Cameras: looking down (camera z = −body z), cam1 `baseline` along body x.
    for (int c = 0; c < 2; ++c) {
      cam[c].name = c == 0 ? "cam0" : "cam1";
      cam[c].intrinsics.width = 752;
      cam[c].intrinsics.height = 480;
      cam[c].intrinsics.fx = cam[c].intrinsics.fy = 458.0;
      cam[c].intrinsics.cx = 376.0;
      cam[c].intrinsics.cy = 240.0;
      cam[c].T_BS.setIdentity();
      cam[c].T_BS.topLeftCorner<3, 3>() = Eigen::Vector3d(1, -1, -1).asDiagonal();
      cam[c].T_BS.topRightCorner<3, 1>() = Eigen::Vector3d(0.05 + c * baseline, 0.02, -0.05);
    }
    // Landmarks: uniform on [−60, 60]² around the circle centre, heights 0..4 m (moving), or a
    // dense patch under the standstill pose.
    landmarks.clear();
    const int nl = moving ? 2500 : 600;
    for (int i = 0; i < nl; ++i) {
      if (moving) {
        landmarks.emplace_back(-60 + 120 * U(rng), -60 + 120 * U(rng), 4.0 * U(rng));
      } else {
        landmarks.emplace_back(1.0 - 3 + 6 * U(rng), 2.0 - 2 + 4 * U(rng), -0.5 * U(rng));
      }
    }
    std::vector<double> priority(landmarks.size()), phase(landmarks.size());
    for (std::size_t i = 0; i < landmarks.size(); ++i) {
      priority[i] = U(rng);
      phase[i] = U(rng);
    }
    // IMU.
    noise.rate_hz = imu_rate;
    const double sg = noise.gyroscope_noise_density * std::sqrt(imu_rate);
    const double sa = noise.accelerometer_noise_density * std::sqrt(imu_rate);
    const double sbg = noise.gyroscope_random_walk / std::sqrt(imu_rate);
    const double sba = noise.accelerometer_random_walk / std::sqrt(imu_rate);
    Eigen::Vector3d bg(0.01 * N(rng), 0.01 * N(rng), 0.01 * N(rng));
    Eigen::Vector3d ba(0.05 * N(rng), 0.05 * N(rng), 0.05 * N(rng));
    imu.clear();
    bg_true.clear();
    ba_true.clear();
    const auto n = static_cast<long>(std::llround(duration * imu_rate));
    const std::int64_t period = std::llround(1e9 / imu_rate);
    for (long i = 0; i <= n + 20; ++i) {
      ImuSample s;
      s.t_ns = i * period;
      const double t = static_cast<double>(s.t_ns) * 1e-9;
      const Eigen::Vector3d w = moving ? motion.gyro(t) : Eigen::Vector3d::Zero();
      const Eigen::Vector3d f =
          moving ? motion.specificForce(t) : Eigen::Vector3d(R(t).transpose() * Eigen::Vector3d(0, 0, motion.g));
      s.gyro = w + bg + sg * Eigen::Vector3d(N(rng), N(rng), N(rng));
      s.accel = f + ba + sa * Eigen::Vector3d(N(rng), N(rng), N(rng));
      imu.push_back(s);
      bg_true.push_back(bg);
      ba_true.push_back(ba);
      bg += sbg * Eigen::Vector3d(N(rng), N(rng), N(rng));
      ba += sba * Eigen::Vector3d(N(rng), N(rng), N(rng));
    }
    // Frames.
    frames.clear();
    const auto nf = static_cast<long>(std::floor(duration * cam_rate));
    const std::int64_t cam_period = std::llround(1e9 / cam_rate);
    for (long k = 1; k <= nf; ++k) {
      FeatureFrame fr;
      fr.t_ns = k * cam_period + 1'000'000;  // not on an IMU stamp
      fr.index = static_cast<std::uint64_t>(k - 1);
      const double t = static_cast<double>(fr.t_ns) * 1e-9;
      const Eigen::Matrix3d Rw = R(t);
      const Eigen::Vector3d pw = p(t);
      struct Cand {
        double prio;
        FeatureObservation o;
      };
      std::vector<Cand> cands;
      for (std::size_t i = 0; i < landmarks.size(); ++i) {
        FeatureObservation o;
        bool ok = true;
        for (int c = 0; c < 2 && ok; ++c) {
          const Eigen::Matrix3d Ric = cam[c].T_BS.topLeftCorner<3, 3>();
          const Eigen::Vector3d pic = cam[c].T_BS.topRightCorner<3, 1>();
          const Eigen::Vector3d pc = Ric.transpose() * (Rw.transpose() * (landmarks[i] - pw) - pic);
          if (pc.z() < 0.3) {
            ok = false;
            break;
          }
          const auto& K = cam[c].intrinsics;
          Eigen::Vector2d px(K.fx * pc.x() / pc.z() + K.cx, K.fy * pc.y() / pc.z() + K.cy);
          if (px.x() < 2 || px.y() < 2 || px.x() > K.width - 3 || px.y() > K.height - 3) {
            if (c == 0) ok = false;
            break;
          }
          px += pixel_noise * Eigen::Vector2d(N(rng), N(rng));
          const Eigen::Vector2d nz((px.x() - K.cx) / K.fx, (px.y() - K.cy) / K.fy);
          if (c == 0) {
            o.pixel0 = px;
            o.normalized0 = nz;
          } else {
            o.pixel1 = px;
            o.normalized1 = nz;
            o.stereo = true;
          }
        }
        if (!ok) continue;
        // Track identity: the landmark and its track segment (finite track lives).
        const double seg = std::floor(t / track_life + phase[i]);
        o.id = static_cast<std::uint64_t>(i) + 1'000'000ull * static_cast<std::uint64_t>(seg + 1);
        cands.push_back({priority[i], o});
      }
      std::sort(cands.begin(), cands.end(), [](const Cand& a, const Cand& b) { return a.prio > b.prio; });
      if (static_cast<int>(cands.size()) > max_features) cands.resize(static_cast<std::size_t>(max_features));
      for (auto& c : cands) fr.features.push_back(c.o);
      frames.push_back(std::move(fr));
    }
  }

  SriSwfConfig config() const {
    SriSwfConfig c;
    c.imu = noise;
    c.gravity = motion.g;
    c.cameras = {cam[0], cam[1]};
    c.pixel_noise = pixel_noise;
    return c;
  }
};

}  // namespace gvins::vio::test
