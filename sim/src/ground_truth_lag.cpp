#include "gvins/sim/ground_truth_lag.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace gvins::sim {

std::vector<double> gyroLagCost(const RecordedTrajectory& trajectory, double from, double to, double step) {
  if (!(step > 0.0) || !(to >= from) || !std::isfinite(from) || !std::isfinite(to) || (to - from) / step > 1e4) {
    throw std::invalid_argument("gyroLagCost: need from <= to and a step > 0 (at most 10000 lags)");
  }
  const double reach = std::max(std::abs(from), std::abs(to));
  const double t0 = 1.0 + reach;
  const double t1 = trajectory.duration() - 1.0 - reach;
  if (!(t1 > t0)) throw std::invalid_argument("gyroLagCost: the recording is too short for these lags");
  // The gyro samples inside the span with their bias removed.
  std::vector<double> ts;
  std::vector<Eigen::Vector3d> w;
  for (const vio::ImuSample& m : trajectory.imuSamples()) {
    const double t = static_cast<double>(m.t_ns - trajectory.startStamp()) * 1e-9;
    if (t < t0 || t > t1) continue;
    Eigen::Vector3d bg, ba;
    trajectory.biases(t, bg, ba);
    ts.push_back(t);
    w.push_back(m.gyro - bg);
  }
  if (ts.empty()) throw std::invalid_argument("gyroLagCost: no IMU samples inside the recording");
  // Means over blocks of 10 samples (50 ms at 200 Hz): the airframe's vibration (rotor
  // harmonics, ~0.05 rad/s RMS on the EuRoC MAV) averages out, the lag's effect ω̇ τ does not.
  constexpr std::size_t kBlock = 10;
  const std::size_t blocks = ts.size() / kBlock;
  if (blocks == 0) throw std::invalid_argument("gyroLagCost: fewer than 10 IMU samples inside the recording");
  std::vector<Eigen::Vector3d> wm(blocks, Eigen::Vector3d::Zero());
  for (std::size_t b = 0; b < blocks; ++b) {
    for (std::size_t i = b * kBlock; i < (b + 1) * kBlock; ++i) wm[b] += w[i];
    wm[b] /= static_cast<double>(kBlock);
  }
  const int n = static_cast<int>(std::floor((to - from) / step + 1e-9)) + 1;
  std::vector<double> cost(static_cast<std::size_t>(n), 0.0);
  for (int k = 0; k < n; ++k) {
    const double lag = from + k * step;
    double s = 0.0;
    for (std::size_t b = 0; b < blocks; ++b) {
      Eigen::Vector3d m = Eigen::Vector3d::Zero();
      for (std::size_t i = b * kBlock; i < (b + 1) * kBlock; ++i) m += trajectory.evaluate(ts[i] + lag).omega_B;
      s += (wm[b] - m / static_cast<double>(kBlock)).squaredNorm();
    }
    cost[static_cast<std::size_t>(k)] = s / static_cast<double>(blocks);
  }
  return cost;
}

double gyroLag(const RecordedTrajectory& trajectory, double maxLag) {
  if (!(maxLag > 0.0) || maxLag > 0.1) throw std::invalid_argument("gyroLag: maxLag in (0, 0.1] s");
  const double step = 0.25e-3;
  const int half = static_cast<int>(std::ceil(maxLag / step));
  const std::vector<double> c = gyroLagCost(trajectory, -half * step, half * step, step);
  const auto k = static_cast<std::size_t>(std::min_element(c.begin(), c.end()) - c.begin());
  if (k == 0 || k + 1 == c.size()) throw std::runtime_error("gyroLag: the best lag is at the edge of ±maxLag");
  // Vertex of the parabola through (−1, c[k−1]), (0, c[k]), (1, c[k+1]).
  const double den = c[k - 1] - 2.0 * c[k] + c[k + 1];
  const double u = den > 0.0 ? 0.5 * (c[k - 1] - c[k + 1]) / den : 0.0;
  return (static_cast<double>(k) - half + u) * step;
}

}  // namespace gvins::sim
