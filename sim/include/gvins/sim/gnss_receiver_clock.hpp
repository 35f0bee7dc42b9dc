// Simulated receiver clock: a two-state (bias, drift) random process driven by the oscillator's
// Allan-variance coefficients, plus constant inter-system biases.
//
// The receiver takes its epochs on a regular grid of its own clock (the RINEX time tags); the
// true GPST of an epoch is tag - bias. The bias enters every pseudorange and carrier phase as
// c * (bias + isb[system]).
#pragma once

#include <array>
#include <cstdint>

#include "gvins/base/gnss_time.hpp"
#include "gvins/base/satellite.hpp"
#include "gvins/sim/gnss_random.hpp"
#include "gvins/sim/gnss_sim_config.hpp"

namespace gvins::sim {

class GnssReceiverClock {
 public:
  GnssReceiverClock(const GnssClockConfig& config, std::uint64_t seed);

  /// Moves the clock to the epoch whose receiver time tag is `tag` (tags increase) and returns
  /// the true GPST of that epoch, tag - bias. The first call draws the initial state.
  GpsTime advanceToTag(const GpsTime& tag);

  /// Receiver time minus GPST, s (common oscillator part).
  double bias() const { return bias_; }
  /// d(bias)/dt, s/s.
  double drift() const { return drift_; }
  /// Inter-system bias of a system (GPS = 0), s.
  double isb(System s) const { return isb_[systemIndex(s)]; }
  /// Total clock term of a system's measurements, s.
  double systemBias(System s) const { return bias_ + isb(s); }
  /// What the receiver writes as its clock offset: the bias with the receiver's estimation noise.
  double reportedOffset() { return bias_ + reportRng_.normal(config_.reportSigma); }

  /// Discrete process noise of the two-state model over dt seconds (Brown & Hwang 2012, 9.3):
  /// S_f = h0/2, S_g = 2 pi^2 h_-2, Q = [[S_f dt + S_g dt^3/3, S_g dt^2/2], [S_g dt^2/2, S_g dt]].
  static void processNoise(const GnssClockConfig& c, double dt, double& q11, double& q12, double& q22);

 private:
  GnssClockConfig config_;
  GnssRandom rng_;
  GnssRandom reportRng_;
  std::array<double, kNumSystems> isb_{};
  bool started_ = false;
  GpsTime lastTag_;
  double bias_ = 0.0;
  double drift_ = 0.0;
};

}  // namespace gvins::sim
