#include "gvins/gnss/carrier_smoothing.hpp"

#include <algorithm>
#include <cmath>

#include "gvins/base/signal.hpp"

namespace gvins {

CarrierSmoother::CarrierSmoother(CarrierSmoothingOptions options)
    : options_(options), slips_(options.slips), arcs_(static_cast<std::size_t>(numSatIndices())) {}

void CarrierSmoother::reset() {
  slips_.reset();
  for (Arc& a : arcs_) a = Arc{};
  lastEpoch_ = GpsTime{};
}

void CarrierSmoother::apply(ObsEpoch& epoch, const GlonassChannels& channels) {
  const GpsTime t = epoch.time;
  slips_.process(epoch, channels);
  lastEpoch_ = t;
  for (SatObs& so : epoch.sats) {
    if (!so.sat.valid()) continue;
    Arc& arc = arcs_[static_cast<std::size_t>(satIndex(so.sat))];
    std::optional<int> channel;
    if (so.sat.system == System::Glonass) channel = channels.get(so.sat.prn);
    work_.clear();
    bool usable = true;
    bool slip = false;
    for (const SignalObs& s : so.signals) {
      if (!s.hasCode()) continue;
      // The signal's own phase, else the best phase on its band (same carrier: the same range
      // change, e.g. GPS C1W with L1C).
      const SignalObs* p = s.hasPhase() ? &s : so.bestOnBand(s.code.band, SignalObs::kPhase);
      const auto lambda = carrierWavelength(so.sat.system, s.code.band, channel);
      if (!p || !lambda || !std::isfinite(s.pseudorange) || !std::isfinite(p->carrierPhase)) {
        usable = false;
        break;
      }
      if (slips_.flags(so.sat, p->code) & kSlipResetMask) slip = true;
      work_.push_back({s.code, s.pseudorange, *lambda * p->carrierPhase});
    }
    if (work_.empty()) continue;
    if (!usable) {
      arc.n = 0;
      arc.last = t;
      ++counts_.raw;
      continue;
    }
    bool restart = arc.n == 0;
    if (!restart && slip) {
      restart = true;
      ++counts_.slipRestarts;
    }
    if (!restart) {
      bool same = arc.signals.size() == work_.size();
      for (std::size_t i = 0; same && i < work_.size(); ++i) same = arc.signals[i].code == work_[i].code;
      if (!same) {
        restart = true;
        ++counts_.signalRestarts;
      }
    }
    const double dt = t - arc.last;
    if (!restart && !(dt > 0.0 && dt <= options_.slips.maxGap)) restart = true;  // also counted as a slip gap
    if (!restart) {
      for (std::size_t i = 0; i < work_.size(); ++i) {
        const double predicted = arc.signals[i].smoothed + (work_[i].phase - arc.signals[i].phase);
        if (std::abs(work_[i].smoothed - predicted) > options_.maxCodeCarrierJump) {
          restart = true;
          ++counts_.jumpRestarts;
          break;
        }
      }
    }
    arc.last = t;
    if (restart) {
      arc.signals = work_;
      arc.n = 1;
      arc.weight = 1.0;
      arc.start = t;
      ++counts_.raw;
      continue;
    }
    const double w = options_.window > 0.0 ? std::max(1.0 / (arc.n + 1), std::min(1.0, dt / options_.window)) : 1.0;
    arc.n += 1;
    arc.weight = w;
    std::size_t i = 0;
    for (SignalObs& s : so.signals) {
      if (!s.hasCode()) continue;
      Signal& a = arc.signals[i];
      const Signal& now = work_[i++];
      a.smoothed = w * now.smoothed + (1.0 - w) * (a.smoothed + (now.phase - a.phase));
      a.phase = now.phase;
      s.pseudorange = a.smoothed;
    }
    ++counts_.smoothed;
  }
}

int CarrierSmoother::samples(SatId sat) const {
  if (!sat.valid()) return 0;
  const Arc& a = arcs_[static_cast<std::size_t>(satIndex(sat))];
  return a.last == lastEpoch_ ? a.n : 0;
}

double CarrierSmoother::arcLength(SatId sat) const {
  if (samples(sat) < 2) return 0.0;
  const Arc& a = arcs_[static_cast<std::size_t>(satIndex(sat))];
  return a.last - a.start;
}

double CarrierSmoother::noiseFactor(SatId sat) const {
  const int n = samples(sat);
  if (n < 2) return 1.0;
  const Arc& a = arcs_[static_cast<std::size_t>(satIndex(sat))];
  // Running mean (w = 1/n): 1/n of the variance; exponential (w fixed): w/(2 − w).
  return std::sqrt(a.weight <= 1.0 / n + 1e-12 ? 1.0 / n : a.weight / (2.0 - a.weight));
}

}  // namespace gvins
