#include "gvins/sim/recorded_trajectory.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Geometry>

#include "gvins/vio/so3.hpp"
#include "band_matrix.hpp"
#include "time_jet.hpp"

namespace gvins::sim {

using detail::Jet;

RecordedTrajectory::RecordedTrajectory(const RecordedTrajectoryConfig& config)
    : RecordedTrajectory(vio::readImuCsv(config.imuCsv), vio::readGroundTruthCsv(config.groundTruthCsv), config) {}

RecordedTrajectory::RecordedTrajectory(const std::vector<vio::ImuSample>& imu,
                                       const std::vector<vio::GroundTruthSample>& truth,
                                       const RecordedTrajectoryConfig& config) {
  if (!(config.knotInterval >= 0.005 && config.knotInterval <= 1.0) || !(config.smoothing >= 0.0) ||
      !std::isfinite(config.smoothing) || !(config.startOffset >= 0.0) || !(config.duration >= 0.0) ||
      !std::isfinite(config.startOffset) || !std::isfinite(config.duration))
    throw std::invalid_argument("RecordedTrajectory: knot interval in [0.005, 1] s, offsets and smoothing >= 0");
  if (truth.size() < 20) throw std::invalid_argument("RecordedTrajectory: fewer than 20 ground-truth samples");
  for (const auto& g : truth)
    if (!g.hasVelocityAndBiases)
      throw std::invalid_argument("RecordedTrajectory: the ground truth needs the 17-column form (velocity, biases)");
  start_ns_ = truth.front().state.t_ns + static_cast<std::int64_t>(std::llround(config.startOffset * 1e9));
  const double span = static_cast<double>(truth.back().state.t_ns - start_ns_) * 1e-9;
  duration_ = config.duration > 0.0 ? config.duration : span;
  if (!(duration_ > 1.0) || duration_ > span + 1e-9)
    throw std::invalid_argument("RecordedTrajectory: the ground truth does not cover the requested span");
  fit(truth, config);
  // IMU samples covering the flight (plus two on each side for the propagator's interpolation).
  const std::int64_t end_ns = start_ns_ + static_cast<std::int64_t>(std::llround(duration_ * 1e9));
  std::size_t a = 0, b = imu.size();
  while (a < imu.size() && imu[a].t_ns < start_ns_) ++a;
  while (b > 0 && imu[b - 1].t_ns > end_ns) --b;
  if (a >= b) throw std::invalid_argument("RecordedTrajectory: the IMU log does not overlap the flight");
  a = a >= 2 ? a - 2 : 0;
  b = std::min(imu.size(), b + 2);
  imu_.assign(imu.begin() + static_cast<long>(a), imu.begin() + static_cast<long>(b));
  for (const auto& g : truth) {
    biasT_.push_back(static_cast<double>(g.state.t_ns - start_ns_) * 1e-9);
    biasG_.push_back(g.state.bg);
    biasA_.push_back(g.state.ba);
  }
}

void RecordedTrajectory::fit(const std::vector<vio::GroundTruthSample>& truth, const RecordedTrajectoryConfig& cfg) {
  const double dt = cfg.knotInterval;
  const double tFirst = static_cast<double>(truth.front().state.t_ns - start_ns_) * 1e-9;
  const double tLast = static_cast<double>(truth.back().state.t_ns - start_ns_) * 1e-9;
  const double t0 = tFirst - 4.0 * dt;
  const auto n = static_cast<std::size_t>(std::ceil((tLast - t0) / dt)) + 5;
  detail::BandMatrix N(n);
  std::vector<std::vector<double>> rhs(7, std::vector<double>(n, 0.0));
  // Sign-continuous quaternions.
  std::vector<Eigen::Vector4d> q(truth.size());
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const Eigen::Quaterniond qi(truth[i].state.R_WI);
    q[i] = Eigen::Vector4d(qi.w(), qi.x(), qi.y(), qi.z());
    if (i > 0 && q[i].dot(q[i - 1]) < 0.0) q[i] = -q[i];
  }
  // Positions relative to the first sample (conditioning).
  const Eigen::Vector3d p0 = truth.front().state.p_WI;
  double w[8];
  for (std::size_t s = 0; s < truth.size(); ++s) {
    const double x = (static_cast<double>(truth[s].state.t_ns - start_ns_) * 1e-9 - t0) / dt;
    const auto k = static_cast<long>(std::floor(x));
    UniformBSpline<3>::basis(x - static_cast<double>(k), 0, w);
    const Eigen::Vector3d p = truth[s].state.p_WI - p0;
    for (int m = 0; m < 8; ++m) {
      const auto i = static_cast<std::size_t>(k - 3 + m);
      for (int m2 = 0; m2 <= m; ++m2) N.add(i, static_cast<std::size_t>(k - 3 + m2), w[m] * w[m2]);
      for (int d = 0; d < 3; ++d) rhs[static_cast<std::size_t>(d)][i] += w[m] * p[d];
      for (int d = 0; d < 4; ++d) rhs[static_cast<std::size_t>(3 + d)][i] += w[m] * q[s][d];
    }
  }
  // Penalty lambda * sum (third difference of c)^2: D^T D with rows (-1, 3, -3, 1).
  const double lam = cfg.smoothing;
  const double d3[4] = {-1.0, 3.0, -3.0, 1.0};
  for (std::size_t r = 0; r + 3 < n; ++r)
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b <= a; ++b) N.add(r + static_cast<std::size_t>(a), r + static_cast<std::size_t>(b), lam * d3[a] * d3[b]);
  // A tiny ridge keeps the far ends (not observed) definite.
  for (std::size_t i = 0; i < n; ++i) N.add(i, i, 1e-9);
  N.factor();
  for (auto& r : rhs) N.solve(r);
  std::vector<Eigen::Vector3d> cp(n);
  std::vector<Eigen::Matrix<double, 4, 1>> cq(n);
  for (std::size_t i = 0; i < n; ++i) {
    cp[i] = Eigen::Vector3d(rhs[0][i], rhs[1][i], rhs[2][i]) + p0;
    cq[i] << rhs[3][i], rhs[4][i], rhs[5][i], rhs[6][i];
  }
  pos_ = UniformBSpline<3>(t0, dt, std::move(cp));
  quat_ = UniformBSpline<4>(t0, dt, std::move(cq));
  // Residuals over the flight.
  double sp = 0.0, sr = 0.0;
  std::size_t cnt = 0;
  posMax_ = 0.0;
  for (const auto& g : truth) {
    const double t = static_cast<double>(g.state.t_ns - start_ns_) * 1e-9;
    if (t < 0.0 || t > duration_) continue;
    const TrajectoryState s = evaluate(t);
    const double ep = (s.p_WB - g.state.p_WI).norm();
    const double er = vio::so3::log(g.state.R_WI.transpose() * s.R_WB).norm();
    sp += ep * ep;
    sr += er * er;
    posMax_ = std::max(posMax_, ep);
    ++cnt;
  }
  posRms_ = std::sqrt(sp / static_cast<double>(std::max<std::size_t>(cnt, 1)));
  rotRms_ = std::sqrt(sr / static_cast<double>(std::max<std::size_t>(cnt, 1)));
}

TrajectoryState RecordedTrajectory::evaluate(double tIn) const {
  const double t = std::clamp(tIn, 0.0, duration_);
  TrajectoryState s;
  s.t = t;
  Eigen::Vector3d p[3];
  pos_.evaluate(t, 2, p);
  s.p_WB = p[0];
  s.v_WB = p[1];
  s.a_WB = p[2];
  Eigen::Matrix<double, 4, 1> q[3];
  quat_.evaluate(t, 2, q);
  Jet c[4];
  for (int i = 0; i < 4; ++i) c[i] = Jet(q[0](i), q[1](i), q[2](i));
  const Jet inv = detail::inverse(detail::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2] + c[3] * c[3]));
  const Jet w = inv * c[0], x = inv * c[1], y = inv * c[2], z = inv * c[3];
  const Jet one(1.0), two(2.0);
  detail::JetMat3 R;
  const Jet e[3][3] = {{one - two * (y * y + z * z), two * (x * y - w * z), two * (x * z + w * y)},
                       {two * (x * y + w * z), one - two * (x * x + z * z), two * (y * z - w * x)},
                       {two * (x * z - w * y), two * (y * z + w * x), one - two * (x * x + y * y)}};
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) {
      R.v(r, k) = e[r][k].v;
      R.d1(r, k) = e[r][k].d1;
      R.d2(r, k) = e[r][k].d2;
    }
  s.R_WB = R.v;
  detail::angularRates(R, s.omega_B, s.alpha_B);
  return s;
}

void RecordedTrajectory::biases(double t, Eigen::Vector3d& bg, Eigen::Vector3d& ba) const {
  const auto it = std::lower_bound(biasT_.begin(), biasT_.end(), t);
  if (it == biasT_.begin()) {
    bg = biasG_.front();
    ba = biasA_.front();
    return;
  }
  if (it == biasT_.end()) {
    bg = biasG_.back();
    ba = biasA_.back();
    return;
  }
  const auto i = static_cast<std::size_t>(it - biasT_.begin());
  const double f = (t - biasT_[i - 1]) / (biasT_[i] - biasT_[i - 1]);
  bg = (1.0 - f) * biasG_[i - 1] + f * biasG_[i];
  ba = (1.0 - f) * biasA_[i - 1] + f * biasA_[i];
}

}  // namespace gvins::sim
