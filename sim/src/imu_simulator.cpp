#include "gvins/sim/imu_simulator.hpp"

#include <cmath>
#include <stdexcept>

#include "gvins/base/constants.hpp"
#include "gvins/sim/normal_gravity.hpp"
#include "gvins/sim/random.hpp"

namespace gvins::sim {

void ImuSimConfig::validate() const {
  auto bad = [](double x) { return !std::isfinite(x) || x < 0.0; };
  if (!std::isfinite(rateHz) || rateHz < 10.0 || rateHz > 2000.0)
    throw std::invalid_argument("imu: rate_hz must be in [10, 2000]");
  if (bad(noise.gyroscope_noise_density) || bad(noise.gyroscope_random_walk) ||
      bad(noise.accelerometer_noise_density) || bad(noise.accelerometer_random_walk))
    throw std::invalid_argument("imu: noise densities and random walks must be finite and >= 0");
  if (bad(gyroBiasSigma) || bad(accelBiasSigma) || !gyroBias.allFinite() || !accelBias.allFinite())
    throw std::invalid_argument("imu: biases must be finite (sigmas >= 0)");
  if (!std::isfinite(gravity) || gravity > 30.0) throw std::invalid_argument("imu: gravity out of range");
}

double flatGravity(const ImuSimConfig& config, const LocalFrame& frame) {
  return config.gravity > 0.0 ? config.gravity : normalGravity(frame.origin);
}

void idealImu(const TrajectoryState& s, const LocalFrame& frame, const ImuSimConfig& config, double flatG,
              Eigen::Vector3d& gyro, Eigen::Vector3d& accel) {
  if (config.earth == EarthModel::Flat) {
    gyro = s.omega_B;
    accel = s.R_WB.transpose() * (s.a_WB + Eigen::Vector3d(0.0, 0.0, flatG));
    return;
  }
  const Eigen::Matrix3d R_EW = frame.rotationEcefFromW();
  const Eigen::Vector3d omegaIeW = R_EW.transpose() * Eigen::Vector3d(0.0, 0.0, constants::kWgs84OmegaE);
  const Eigen::Vector3d gammaW = R_EW.transpose() * normalGravityEcef(frame.toGeodetic(s.p_WB));
  gyro = s.omega_B + s.R_WB.transpose() * omegaIeW;
  accel = s.R_WB.transpose() * (s.a_WB + 2.0 * omegaIeW.cross(s.v_WB) - gammaW);
}

SimulatedImu simulateImu(const Trajectory& trajectory, const LocalFrame& frame, const ImuSimConfig& config,
                         std::uint64_t seed) {
  config.validate();
  SimulatedImu out;
  out.gravity = flatGravity(config, frame);
  out.period_ns = std::llround(1e9 / config.rateHz);
  const double dt = static_cast<double>(out.period_ns) * 1e-9;
  const auto n = static_cast<std::size_t>(std::floor(trajectory.duration() / dt + 1e-9)) + 1;
  out.samples.reserve(n);
  out.gyroBias.reserve(n);
  out.accelBias.reserve(n);

  Rng rng(seed, nameHash("imu"));
  Eigen::Vector3d bg = config.gyroBias, ba = config.accelBias;
  for (int i = 0; i < 3; ++i) bg[i] += rng.normal(config.gyroBiasSigma);
  for (int i = 0; i < 3; ++i) ba[i] += rng.normal(config.accelBiasSigma);
  const vio::ImuNoise& q = config.noise;
  const double sgw = config.whiteNoise ? q.gyroscope_noise_density / std::sqrt(dt) : 0.0;
  const double saw = config.whiteNoise ? q.accelerometer_noise_density / std::sqrt(dt) : 0.0;
  const double sgb = config.biasRandomWalk ? q.gyroscope_random_walk * std::sqrt(dt) : 0.0;
  const double sab = config.biasRandomWalk ? q.accelerometer_random_walk * std::sqrt(dt) : 0.0;

  const std::int64_t start = frame.startStampNs();
  for (std::size_t k = 0; k < n; ++k) {
    const std::int64_t offset = static_cast<std::int64_t>(k) * out.period_ns;
    const TrajectoryState s = trajectory.evaluate(static_cast<double>(offset) * 1e-9);
    Eigen::Vector3d w, f;
    idealImu(s, frame, config, out.gravity, w, f);
    vio::ImuSample m;
    m.t_ns = start + offset;
    // Draw in a fixed order (gyro white, accel white, gyro walk, accel walk) for reproducibility.
    Eigen::Vector3d nw, na, dbg, dba;
    for (int i = 0; i < 3; ++i) nw[i] = rng.normal(sgw);
    for (int i = 0; i < 3; ++i) na[i] = rng.normal(saw);
    for (int i = 0; i < 3; ++i) dbg[i] = rng.normal(sgb);
    for (int i = 0; i < 3; ++i) dba[i] = rng.normal(sab);
    m.gyro = w + bg + nw;
    m.accel = f + ba + na;
    out.samples.push_back(m);
    out.gyroBias.push_back(bg);
    out.accelBias.push_back(ba);
    bg += dbg;
    ba += dba;
  }
  return out;
}

}  // namespace gvins::sim
