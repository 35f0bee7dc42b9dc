#include "gvins/sim/gnss_receiver_clock.hpp"

#include <cmath>

#include "gvins/base/constants.hpp"

namespace gvins::sim {

GnssReceiverClock::GnssReceiverClock(const GnssClockConfig& config, std::uint64_t seed)
    : config_(config), rng_(seed), reportRng_(splitMix64(seed ^ 0x7E9047ULL)) {
  for (int s = 0; s < kNumSystems; ++s) isb_[s] = rng_.normal(config_.isbSigma[s]);
  isb_[systemIndex(System::Gps)] = 0.0;  // the reference
}

void GnssReceiverClock::processNoise(const GnssClockConfig& c, double dt, double& q11, double& q12, double& q22) {
  const double sf = 0.5 * c.h0;
  const double sg = 2.0 * constants::kPi * constants::kPi * c.hMinus2;
  q11 = sf * dt + sg * dt * dt * dt / 3.0;
  q12 = 0.5 * sg * dt * dt;
  q22 = sg * dt;
}

GpsTime GnssReceiverClock::advanceToTag(const GpsTime& tag) {
  if (!started_) {
    started_ = true;
    lastTag_ = tag;
    bias_ = rng_.uniform(-config_.initialBiasMax, config_.initialBiasMax);
    drift_ = rng_.normal(config_.initialDriftSigma);
    return tag - bias_;
  }
  const double dtTag = tag - lastTag_;
  lastTag_ = tag;
  const double w1 = rng_.normal(), w2 = rng_.normal();
  // The process runs in true time; the true interval is the tag interval minus the change of the
  // bias, so solve the (contracting) fixed point dt = dtTag - (bias(dt) - bias).
  double dt = dtTag, b = bias_, d = drift_;
  for (int it = 0; it < 4; ++it) {
    double q11, q12, q22;
    processNoise(config_, std::max(dt, 0.0), q11, q12, q22);
    const double l11 = std::sqrt(std::max(q11, 0.0));
    const double l21 = l11 > 0.0 ? q12 / l11 : 0.0;
    const double l22 = std::sqrt(std::max(q22 - l21 * l21, 0.0));
    b = bias_ + drift_ * dt + l11 * w1;
    d = drift_ + l21 * w1 + l22 * w2;
    dt = dtTag - (b - bias_);
  }
  bias_ = b;
  drift_ = d;
  return tag - bias_;
}

}  // namespace gvins::sim
