// Analytic rigid-body motion with closed-form angular rate and specific force, used as
// independent truth for IMU propagation and integration tests: a 20 m circle at 8 m/s with a
// vertical oscillation and roll/pitch/yaw wobble (a UAV-like flight).
#pragma once

#include <cmath>
#include <vector>

#include <Eigen/Core>

#include "gvins/vio/imu_sample.hpp"
#include "gvins/vio/imu_state.hpp"

namespace gvins::vio::test {

struct AnalyticMotion {
  double g = 9.81;

  static Eigen::Matrix3d rx(double a) {
    Eigen::Matrix3d m;
    m << 1, 0, 0, 0, std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a);
    return m;
  }
  static Eigen::Matrix3d ry(double a) {
    Eigen::Matrix3d m;
    m << std::cos(a), 0, std::sin(a), 0, 1, 0, -std::sin(a), 0, std::cos(a);
    return m;
  }
  static Eigen::Matrix3d rz(double a) {
    Eigen::Matrix3d m;
    m << std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a), 0, 0, 0, 1;
    return m;
  }
  // Euler angles (ZYX) and their rates.
  void angles(double t, Eigen::Vector3d& e, Eigen::Vector3d& de) const {
    e << 0.15 * std::sin(1.3 * t), 0.1 * std::sin(1.1 * t + 0.5), 0.4 * t + M_PI / 2 + 0.1 * std::sin(0.7 * t);
    de << 0.15 * 1.3 * std::cos(1.3 * t), 0.1 * 1.1 * std::cos(1.1 * t + 0.5), 0.4 + 0.07 * std::cos(0.7 * t);
  }
  Eigen::Matrix3d R(double t) const {
    Eigen::Vector3d e, de;
    angles(t, e, de);
    return rz(e.z()) * ry(e.y()) * rx(e.x());
  }
  Eigen::Vector3d p(double t) const {
    return {20.0 * std::cos(0.4 * t), 20.0 * std::sin(0.4 * t), 30.0 + std::sin(1.9 * t)};
  }
  Eigen::Vector3d v(double t) const {
    return {-8.0 * std::sin(0.4 * t), 8.0 * std::cos(0.4 * t), 1.9 * std::cos(1.9 * t)};
  }
  Eigen::Vector3d acc(double t) const {
    return {-3.2 * std::cos(0.4 * t), -3.2 * std::sin(0.4 * t), -1.9 * 1.9 * std::sin(1.9 * t)};
  }
  /// Body angular rate: w = Rx^T Ry^T e_z dyaw + Rx^T e_y dpitch + e_x droll.
  Eigen::Vector3d gyro(double t) const {
    Eigen::Vector3d e, de;
    angles(t, e, de);
    const Eigen::Matrix3d Rx = rx(e.x()), Ry = ry(e.y());
    return Rx.transpose() * Ry.transpose() * Eigen::Vector3d::UnitZ() * de.z() +
           Rx.transpose() * Eigen::Vector3d::UnitY() * de.y() + Eigen::Vector3d::UnitX() * de.x();
  }
  Eigen::Vector3d specificForce(double t) const {
    return R(t).transpose() * (acc(t) + Eigen::Vector3d(0, 0, g));
  }
  ImuState state(double t) const {
    ImuState s;
    s.t_ns = static_cast<std::int64_t>(std::llround(t * 1e9));
    s.R_WI = R(t);
    s.p_WI = p(t);
    s.v_WI = v(t);
    return s;
  }
  /// Noise-free samples of the true signals (plus constant biases) at rate_hz over [0, duration].
  std::vector<ImuSample> samples(double duration, double rate_hz, const Eigen::Vector3d& bg = Eigen::Vector3d::Zero(),
                                 const Eigen::Vector3d& ba = Eigen::Vector3d::Zero()) const {
    std::vector<ImuSample> out;
    const auto n = static_cast<long>(std::llround(duration * rate_hz));
    const std::int64_t period = std::llround(1e9 / rate_hz);
    for (long i = 0; i <= n; ++i) {
      ImuSample s;
      s.t_ns = i * period;
      const double t = static_cast<double>(s.t_ns) * 1e-9;
      s.gyro = gyro(t) + bg;
      s.accel = specificForce(t) + ba;
      out.push_back(s);
    }
    return out;
  }
};

}  // namespace gvins::vio::test
