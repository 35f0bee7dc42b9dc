#include "gvins/gnss/base_station.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "gvins/base/constants.hpp"
#include "gvins/base/geodetic.hpp"
#include "gvins/base/local_frame.hpp"
#include "gvins/gnss/satellite_observation_model.hpp"
#include "gvins/gnss/zero_difference.hpp"

namespace gvins {

namespace {
bool signalLess(const BaseSignal& a, const BaseSignal& b) {
  return a.sat == b.sat ? a.code < b.code : a.sat < b.sat;
}
}  // namespace

const char* toString(BaseAvailability a) {
  switch (a) {
    case BaseAvailability::Ok: return "ok";
    case BaseAvailability::NoPosition: return "base position unknown";
    case BaseAvailability::NoData: return "no base data yet";
    case BaseAvailability::TooOld: return "base data too old";
  }
  return "?";
}

const BaseSignal* BaseSnapshot::find(SatId sat, ObsCode code) const {
  BaseSignal key;
  key.sat = sat;
  key.code = code;
  const auto it = std::lower_bound(signals.begin(), signals.end(), key, signalLess);
  if (it == signals.end() || !(it->sat == sat) || !(it->code == code)) return nullptr;
  return &*it;
}

bool BaseSnapshot::has(SatId sat) const {
  BaseSignal key;
  key.sat = sat;
  key.code = ObsCode('0', 'A');
  const auto it = std::lower_bound(signals.begin(), signals.end(), key, signalLess);
  return it != signals.end() && it->sat == sat;
}

BaseStation::BaseStation(const EphemerisStore& nav, const RtkConfig& config)
    : nav_(nav), config_(config), slips_(config.slip) {}

void BaseStation::setPosition(const Eigen::Vector3d& arp) {
  if (position_ && (*position_ - arp).norm() < 1e-3) return;
  if (position_) {
    ++stats_.positionChanges;
    for (Epoch& e : epochs_) {
      e.modelled = false;
      e.signals.clear();
    }
  }
  position_ = arp;
}

void BaseStation::setGlonassChannels(const GlonassChannels& channels) {
  channels_ = channels;
  channels_.mergeMissing(nav_.glonassChannels());
}

std::optional<GpsTime> BaseStation::latestTime() const {
  if (epochs_.empty()) return std::nullopt;
  return epochs_.back().time;
}

void BaseStation::setDirection(TimeDirection d) {
  if (d == direction_) return;
  direction_ = d;
  clear();
  slips_.setDirection(d);
  doppler_.setDirection(d);
}

void BaseStation::clear() {
  epochs_.clear();
  slips_.reset();
}

void BaseStation::addEpoch(const ObsEpoch& epoch) {
  if (!epochs_.empty() && !(elapsed(direction_, epoch.time, epochs_.back().time) > 1e-6)) {
    ++stats_.outOfOrder;
    return;
  }
  ++stats_.epochs;
  GlonassChannels ch = channels_;
  ch.mergeMissing(nav_.glonassChannels());
  Epoch e;
  e.time = epoch.time;
  e.raw = epoch;
  doppler_.apply(e.raw, ch);  // sign-flipped / bad Doppler never reaches the slip detector
  slips_.process(e.raw, ch);
  epochs_.push_back(std::move(e));
  // Keep what alignment can still use: the newest epoch may be one past the rover time, the one
  // held up to maxAge older, and the rate window of extrapolation up to maxInterpolationGap before
  // that; at least two epochs, at most kMaxEpochs.
  const double keep = config_.maxAge + config_.maxInterpolationGap + 1.0;
  while (epochs_.size() > 2 && elapsed(direction_, epochs_.back().time, epochs_[1].time) > keep) epochs_.pop_front();
  while (epochs_.size() > kMaxEpochs) epochs_.pop_front();
  // Record slip flags and arcs now: the detector only knows the latest epoch.
  Epoch& last = epochs_.back();
  for (const SatObs& so : last.raw.sats) {
    if (!so.sat.valid() || !config_.useSystem(so.sat.system)) continue;
    for (const SignalObs& s : so.signals) {
      BaseSignal b;
      b.sat = so.sat;
      b.code = s.code;
      b.hasPhase = s.hasPhase() && s.carrierPhase != 0.0 && std::isfinite(s.carrierPhase);
      b.hasCode = s.hasCode() && s.pseudorange > 1e6 && s.pseudorange < 1e8;
      b.snr = s.hasSnr() ? s.snr : 0.0;
      if (!b.hasPhase && !b.hasCode) continue;
      if (b.hasPhase) {
        b.slipFlags = slips_.flags(so.sat, s.code);
        b.arcStart = slips_.arcStart(so.sat, s.code).value_or(last.time);
      }
      last.signals.push_back(b);
    }
  }
  std::sort(last.signals.begin(), last.signals.end(), signalLess);
  if (position_) model(last);
}

void BaseStation::model(Epoch& e) {
  if (e.modelled || !position_) return;
  const Eigen::Vector3d& rb = *position_;
  ObservationModelOptions modelOptions;  // az/el and the troposphere (satellite_observation_model.hpp)
  modelOptions.troposphere = config_.troposphere ? TroposphereMeteo::StandardAtmosphere : TroposphereMeteo::Off;
  const SatelliteObservationModel model(rb, e.time, modelOptions);
  GlonassChannels ch = channels_;
  ch.mergeMissing(nav_.glonassChannels());
  std::vector<BaseSignal> out;
  out.reserve(e.signals.size());
  std::size_t i = 0;
  while (i < e.signals.size()) {
    const SatId sat = e.signals[i].sat;
    std::size_t j = i;
    while (j < e.signals.size() && e.signals[j].sat == sat) ++j;
    const SatObs* so = e.raw.find(sat);
    // Transmit time from any plausible pseudorange of the satellite.
    double pr = 0.0;
    if (so) {
      for (const SignalObs& s : so->signals) {
        if (s.hasCode() && s.pseudorange > 1e6 && s.pseudorange < 1e8) {
          pr = s.pseudorange;
          break;
        }
      }
    }
    const auto tx = so ? satelliteAtTransmit(nav_, sat, e.time, pr) : std::nullopt;
    if (!tx) {
      ++stats_.noEphemeris;
      i = j;
      continue;
    }
    const double range = geometricRange(tx->state.position, rb);
    const SatelliteModelTerms terms = model.terms(tx->state.position, sat.system, 0.0);
    const AzEl& azel = terms.azel;
    const double tropo = terms.troposphere.slant;
    const double computed = range - constants::kSpeedOfLight * tx->state.clockBias + tropo;
    std::optional<int> channel;
    if (sat.system == System::Glonass) channel = ch.get(sat.prn);
    for (std::size_t k = i; k < j; ++k) {
      BaseSignal b = e.signals[k];
      const SignalObs* s = so->find(b.code);
      if (!s) continue;
      b.elevation = azel.elevation;
      const auto lam = carrierWavelength(sat.system, b.code.band, channel);
      b.wavelength = lam ? *lam : 0.0;
      if (b.hasPhase && lam) b.phaseOmc = *lam * s->carrierPhase - computed;
      else b.hasPhase = false;
      if (b.hasCode) b.codeOmc = s->pseudorange - computed;
      if (b.hasPhase || b.hasCode) out.push_back(b);
    }
    i = j;
  }
  e.signals = std::move(out);
  e.modelled = true;
  e.ratesValid = false;
}

BaseAvailability BaseStation::snapshot(const GpsTime& t, BaseSnapshot& out) {
  out.signals.clear();
  out.interpolated = false;
  out.extrapolated = false;
  if (!position_) return BaseAvailability::NoPosition;
  if (epochs_.empty()) return BaseAvailability::NoData;
  // eB: newest epoch not after t (within the sync tolerance); eA: the one after it (in
  // processing order).
  int b = -1;
  for (int k = static_cast<int>(epochs_.size()) - 1; k >= 0; --k) {
    if (elapsed(direction_, epochs_[static_cast<std::size_t>(k)].time, t) <= kSyncTolerance) {
      b = k;
      break;
    }
  }
  const int a = b + 1 < static_cast<int>(epochs_.size()) ? b + 1 : -1;
  if (b < 0) return BaseAvailability::NoData;
  Epoch& eb = epochs_[static_cast<std::size_t>(b)];
  model(eb);
  const double ageB = elapsed(direction_, t, eb.time);
  if (std::abs(ageB) <= kSyncTolerance) {
    out.time = eb.time;
    out.age = ageB;
    out.signals = eb.signals;
    return BaseAvailability::Ok;
  }
  if (config_.interpolateBase && a >= 0) {
    Epoch& ea = epochs_[static_cast<std::size_t>(a)];
    const double gap = elapsed(direction_, ea.time, eb.time);
    if (gap <= config_.maxInterpolationGap && gap > 0.0) {
      model(ea);
      const double w = ageB / gap;
      out.time = t;
      out.age = std::min(ageB, elapsed(direction_, ea.time, t));
      out.interpolated = true;
      std::size_t j = 0;
      for (const BaseSignal& s0 : eb.signals) {
        while (j < ea.signals.size() && signalLess(ea.signals[j], s0)) ++j;
        if (j == ea.signals.size()) break;
        const BaseSignal& s1 = ea.signals[j];
        if (!(s1.sat == s0.sat) || !(s1.code == s0.code)) continue;
        BaseSignal s = s1;
        s.hasCode = s0.hasCode && s1.hasCode;
        s.hasPhase = s0.hasPhase && s1.hasPhase && s1.arcStart == s0.arcStart;
        if (s.hasCode) s.codeOmc = s0.codeOmc + w * (s1.codeOmc - s0.codeOmc);
        if (s.hasPhase) s.phaseOmc = s0.phaseOmc + w * (s1.phaseOmc - s0.phaseOmc);
        s.elevation = s0.elevation + w * (s1.elevation - s0.elevation);
        s.slipFlags = s0.slipFlags;
        s.arcStart = s0.arcStart;
        if (s.hasCode || s.hasPhase) out.signals.push_back(s);
      }
      return BaseAvailability::Ok;
    }
  }
  if (ageB <= config_.maxAge) {
    out.time = eb.time;
    out.age = ageB;
    out.signals = eb.signals;
    if (config_.extrapolateBase) extrapolate(b, t, out);
    return BaseAvailability::Ok;
  }
  return BaseAvailability::TooOld;
}

void BaseStation::extrapolate(int b, const GpsTime& t, BaseSnapshot& out) {
  Epoch& eb = epochs_[static_cast<std::size_t>(b)];
  // Rate window: the buffered epochs at most maxInterpolationGap before the held one; the rate of
  // each phase is the least-squares slope of its OMC over the epochs of the same arc, provided
  // they span at least kMinRateSpan seconds (shorter spans make the rate noise, multiplied by the
  // age, larger than the effect).
  int first = b;
  while (first > 0 && elapsed(direction_, eb.time, epochs_[static_cast<std::size_t>(first - 1)].time) <= config_.maxInterpolationGap)
    --first;
  if (elapsed(direction_, eb.time, epochs_[static_cast<std::size_t>(first)].time) < kMinRateSpan) return;
  const GpsTime firstTime = epochs_[static_cast<std::size_t>(first)].time;
  if (!eb.ratesValid || !(eb.ratesFirst == firstTime) || eb.ratesCount != b - first) {
    for (int k = first; k < b; ++k) model(epochs_[static_cast<std::size_t>(k)]);
    eb.rates.assign(eb.signals.size(), std::numeric_limits<double>::quiet_NaN());
    std::vector<double> all;
    // Sums for the slope over (t - t_b, omc - omc_b), the held epoch included. Epochs outer,
    // signals inner: both signal lists are sorted, so each epoch is one merge pass over
    // contiguous memory (signals outer touched every epoch's list once per signal: 7000 scattered
    // reads per base epoch, 0.2 ms). Per signal the sums still run over the epochs in order.
    struct Sums {
      double n = 1.0, st = 0.0, sy = 0.0, stt = 0.0, sty = 0.0, tmin = 0.0;
    };
    std::vector<Sums> sums(eb.signals.size());
    for (int k = first; k < b; ++k) {
      const Epoch& e = epochs_[static_cast<std::size_t>(k)];
      const double x = elapsed(direction_, e.time, eb.time);  // rates per second of processing order
      std::size_t j = 0;
      for (std::size_t i = 0; i < eb.signals.size(); ++i) {
        const BaseSignal& s1 = eb.signals[i];
        if (!s1.hasPhase) continue;
        while (j < e.signals.size() && signalLess(e.signals[j], s1)) ++j;
        if (j == e.signals.size()) break;
        const BaseSignal& s0 = e.signals[j];
        if (!(s0.sat == s1.sat) || !(s0.code == s1.code) || !s0.hasPhase || !(s0.arcStart == s1.arcStart)) continue;
        const double y = s0.phaseOmc - s1.phaseOmc;
        Sums& a = sums[i];
        a.n += 1.0;
        a.st += x;
        a.sy += y;
        a.stt += x * x;
        a.sty += x * y;
        a.tmin = std::min(a.tmin, x);
      }
    }
    for (std::size_t i = 0; i < eb.signals.size(); ++i) {
      if (!eb.signals[i].hasPhase) continue;
      const Sums& a = sums[i];
      const double den = a.n * a.stt - a.st * a.st;
      if (a.n < 2.0 || -a.tmin < kMinRateSpan || !(den > 0.0)) continue;
      eb.rates[i] = (a.n * a.sty - a.st * a.sy) / den;
      all.push_back(eb.rates[i]);
    }
    eb.ratesUsable = all.size() >= 3;
    if (eb.ratesUsable) {
      const std::size_t mid = all.size() / 2;
      std::nth_element(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(mid), all.end());
      const double common = all[mid];
      for (double& r : eb.rates) r -= common;  // NaN stays NaN
    }
    eb.ratesValid = true;
    eb.ratesFirst = firstTime;
    eb.ratesCount = b - first;
  }
  if (!eb.ratesUsable || eb.rates.size() != out.signals.size()) return;
  const double age = elapsed(direction_, t, eb.time);
  for (std::size_t i = 0; i < out.signals.size(); ++i) {
    if (std::isfinite(eb.rates[i])) out.signals[i].phaseOmc += eb.rates[i] * age;
  }
  out.extrapolated = true;
}

}  // namespace gvins
