#include "gvins/sim/gait.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace gvins::sim {

void GaitConfig::validate() const {
  if (!(std::isfinite(stepLength) && stepLength >= 0.2 && stepLength <= 2.0))
    throw std::invalid_argument("gait: step length must be in [0.2, 2] m");
  if (!(std::isfinite(bob) && bob >= 0.0 && bob <= 0.2)) throw std::invalid_argument("gait: bob must be in [0, 0.2] m");
  if (!(std::isfinite(sway) && sway >= 0.0 && sway <= 0.2)) throw std::invalid_argument("gait: sway must be in [0, 0.2] m");
  if (!(std::isfinite(tiltDeg) && tiltDeg >= 0.0 && tiltDeg <= 20.0))
    throw std::invalid_argument("gait: tilt must be in [0, 20] deg");
}

GaitPhase gaitPhase(const GaitConfig& gait, const RouteSamples& samples) {
  GaitPhase g;
  const std::size_t n = samples.position.size();
  g.phase.assign(n, 0.0);
  g.weight.assign(n, 0.0);
  double s = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    if (k > 0) s += (samples.position[k] - samples.position[k - 1]).head<2>().norm();
    g.phase[k] = 2.0 * std::numbers::pi * s / gait.stepLength;
    const std::size_t a = k > 0 ? k - 1 : k, b = std::min(k + 1, n - 1);
    const double v = b > a ? (samples.position[b] - samples.position[a]).head<2>().norm() /
                                 (static_cast<double>(b - a) * samples.dt)
                           : 0.0;
    g.weight[k] = std::clamp(v, 0.0, 1.0);  // full amplitude from 1 m/s
  }
  return g;
}

void addGaitMotion(const GaitConfig& gait, const GaitPhase& g, RouteSamples& samples) {
  for (std::size_t k = 0; k < samples.position.size(); ++k) {
    const double h = samples.heading[k];
    const Eigen::Vector3d left(-std::sin(h), std::cos(h), 0.0);
    samples.position[k] += g.weight[k] * (gait.bob * std::sin(g.phase[k]) * Eigen::Vector3d::UnitZ() +
                                          gait.sway * std::sin(0.5 * g.phase[k]) * left);
  }
}

std::vector<Eigen::Vector3d> gaitAngles(const GaitConfig& gait, const GaitPhase& g) {
  const double a = gait.tiltDeg * std::numbers::pi / 180.0;
  std::vector<Eigen::Vector3d> out(g.phase.size());
  for (std::size_t k = 0; k < out.size(); ++k) {
    const double p = g.phase[k];
    out[k] = g.weight[k] * a * Eigen::Vector3d(std::sin(0.5 * p + 0.3), std::sin(p + 0.8), 0.5 * std::sin(0.5 * p + 1.9));
  }
  return out;
}

}  // namespace gvins::sim
