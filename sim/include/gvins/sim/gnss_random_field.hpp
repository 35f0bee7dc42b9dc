// A stationary Gaussian random field over a horizontal plane, drifting with a constant wind
// (Taylor's frozen-flow hypothesis, as used for tropospheric turbulence by Treuhaft & Lanyi,
// Radio Science 22(2), 1987). Sampled by random Fourier features: f(x) = sigma sqrt(2/K)
// sum_k cos(w_k . x + phi_k), with w_k drawn from the spectral density of the covariance
// (Bochner's theorem; Rahimi & Recht, NIPS 2007). For a Gaussian covariance exp(-d^2/L^2) the
// frequencies are N(0, 2/L^2 I); for an exponential covariance exp(-d/L) in two dimensions they
// follow a bivariate Cauchy law (spectral density proportional to (1 + L^2 |w|^2)^(-3/2)).
// Evaluation anywhere costs K cosines; values at nearby points are correlated as configured, so
// two receivers a few kilometres apart see almost the same residual.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "gvins/sim/gnss_sim_config.hpp"

namespace gvins::sim {

class GnssRandomField {
 public:
  /// `features` cosines (64 give a field whose one-point distribution is close to Gaussian and
  /// whose covariance follows the model within a few percent on average over realisations).
  GnssRandomField(const GnssRandomFieldConfig& config, std::uint64_t seed, int features = 64);

  /// Value at horizontal position x (m, any local plane) and time t (s).
  double value(const Eigen::Vector2d& x, double t) const;
  const GnssRandomFieldConfig& config() const { return config_; }
  /// The drift velocity (m/s) in the plane's axes.
  const Eigen::Vector2d& wind() const { return wind_; }

 private:
  GnssRandomFieldConfig config_;
  std::vector<Eigen::Vector2d> w_;
  std::vector<double> phase_;
  Eigen::Vector2d wind_ = Eigen::Vector2d::Zero();
  double amplitude_ = 0.0;
};

}  // namespace gvins::sim
