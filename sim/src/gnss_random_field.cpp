#include "gvins/sim/gnss_random_field.hpp"

#include <cmath>

#include "gvins/base/constants.hpp"
#include "gvins/sim/gnss_random.hpp"

namespace gvins::sim {

GnssRandomField::GnssRandomField(const GnssRandomFieldConfig& config, std::uint64_t seed, int features)
    : config_(config) {
  GnssRandom rng(seed);
  const double L = config.correlationLength;
  // Wavelengths below 50 m are dropped (the exponential model's heavy tail would otherwise put a
  // few features at centimetre scales, which no atmosphere has).
  const double maxW = 2.0 * constants::kPi / 50.0;
  w_.reserve(static_cast<std::size_t>(features));
  phase_.reserve(static_cast<std::size_t>(features));
  for (int k = 0; k < features; ++k) {
    Eigen::Vector2d w;
    do {
      const Eigen::Vector2d z(rng.normal(), rng.normal());
      if (config.covariance == GnssRandomFieldConfig::Covariance::Gaussian) {
        w = z * (std::sqrt(2.0) / L);
      } else {
        double g;
        do g = std::abs(rng.normal());
        while (g < 1e-12);
        w = z / (g * L);
      }
    } while (w.norm() > maxW);
    w_.push_back(w);
    phase_.push_back(rng.uniform(0.0, 2.0 * constants::kPi));
  }
  const double dir = rng.uniform(0.0, 2.0 * constants::kPi);
  wind_ = config.speed * Eigen::Vector2d(std::sin(dir), std::cos(dir));
  amplitude_ = features > 0 ? config.sigma * std::sqrt(2.0 / features) : 0.0;
}

double GnssRandomField::value(const Eigen::Vector2d& x, double t) const {
  if (amplitude_ == 0.0) return 0.0;
  const Eigen::Vector2d p = x - wind_ * t;
  double sum = 0.0;
  for (std::size_t k = 0; k < w_.size(); ++k) sum += std::cos(w_[k].dot(p) + phase_[k]);
  return amplitude_ * sum;
}

}  // namespace gvins::sim
