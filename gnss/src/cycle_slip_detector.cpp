#include "gvins/gnss/cycle_slip_detector.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace gvins {

CycleSlipDetector::CycleSlipDetector(CycleSlipOptions options)
    : options_(options), tracks_(static_cast<std::size_t>(numSatIndices())) {}

CycleSlipDetector::Track* CycleSlipDetector::find(SatId sat, ObsCode code) {
  auto& v = tracks_[static_cast<std::size_t>(satIndex(sat))];
  for (Track& t : v) {
    if (t.code == code) return &t;
  }
  return nullptr;
}

const CycleSlipDetector::Track* CycleSlipDetector::find(SatId sat, ObsCode code) const {
  const auto& v = tracks_[static_cast<std::size_t>(satIndex(sat))];
  for (const Track& t : v) {
    if (t.code == code) return &t;
  }
  return nullptr;
}

std::uint8_t CycleSlipDetector::flags(SatId sat, ObsCode code) const {
  if (!sat.valid()) return kSlipNone;
  const Track* t = find(sat, code);
  if (!t || !t->valid || t->flagsTime != lastEpoch_) return kSlipNone;
  return t->flags;
}

std::optional<GpsTime> CycleSlipDetector::arcStart(SatId sat, ObsCode code) const {
  if (!sat.valid()) return std::nullopt;
  const Track* t = find(sat, code);
  if (!t || !t->valid) return std::nullopt;
  return t->arcStart;
}

void CycleSlipDetector::reset() {
  for (auto& v : tracks_) v.clear();
}

void CycleSlipDetector::setDirection(TimeDirection d) {
  direction_ = d;
  reset();
}

void CycleSlipDetector::restart(SatId sat, ObsCode code) {
  if (!sat.valid()) return;
  if (Track* t = find(sat, code)) {
    t->valid = false;
    t->hasGf = false;
  }
}

void CycleSlipDetector::process(const ObsEpoch& epoch, const GlonassChannels& channels) {
  const GpsTime t = epoch.time;
  lastEpoch_ = t;
  pending_.clear();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const SatObs& so : epoch.sats) {
    if (!so.sat.valid()) continue;
    std::optional<int> channel;
    if (so.sat.system == System::Glonass) channel = channels.get(so.sat.prn);
    auto& list = tracks_[static_cast<std::size_t>(satIndex(so.sat))];
    const std::size_t first = pending_.size();
    list.reserve(list.size() + so.signals.size());  // no reallocation while pointers are held
    // Reference of the geometry-free tests: the phase on the lowest band with a known wavelength.
    int refIndex = -1;
    char refBand = '9' + 1;
    for (const SignalObs& s : so.signals) {
      if (!s.hasPhase() || !std::isfinite(s.carrierPhase) || s.carrierPhase == 0.0) continue;
      Track* tr = find(so.sat, s.code);
      if (!tr) {
        list.push_back(Track{});
        list.back().code = s.code;
        tr = &list.back();
      }
      const auto lam = carrierWavelength(so.sat.system, s.code.band, channel);
      std::uint8_t f = 0;
      double dres = nan;
      if (!tr->valid) {
        f |= kSlipNewArc;
      } else {
        const double dt = t - tr->last;  // signed: negative backward
        const double gap = elapsed(direction_, t, tr->last);
        if (!(gap > 0.0) || gap > options_.maxGap) {
          f |= kSlipGap;
        } else if (options_.doppler && lam && s.hasDoppler() && tr->hasDoppler) {
          const double predicted = -0.5 * (tr->doppler + s.doppler) * dt;  // cycles
          dres = *lam * ((s.carrierPhase - tr->phase) - predicted);
        }
      }
      if (options_.useLli) {
        // Backward, the flagged epoch's slip lies between it and the epoch processed next.
        if (direction_ == TimeDirection::Forward) {
          if (s.lossOfLock()) f |= kSlipLli;
        } else {
          if (tr->valid && tr->lliPending) f |= kSlipLli;
          tr->lliPending = s.lossOfLock();
        }
      }
      if (s.halfCycle()) f |= kSlipHalfCycle;
      tr->flags = f;
      tr->flagsTime = t;
      pending_.push_back({tr, lam ? *lam : 0.0, dres});
      if (lam && s.code.band < refBand) {
        refBand = s.code.band;
        refIndex = static_cast<int>(pending_.size() - 1);
      }
      // Keep the previous time in `last` until the geometry-free test below has used it; the
      // new phase/Doppler values are stored now (they are not needed in their old form again).
      tr->phase = s.carrierPhase;
      tr->hasDoppler = s.hasDoppler();
      tr->doppler = s.doppler;
    }
    // Geometry-free tests against the reference signal.
    if (refIndex >= 0) {
      Pending& ref = pending_[static_cast<std::size_t>(refIndex)];
      Track* rt = ref.track;
      const bool refNew = (rt->flags & (kSlipNewArc | kSlipGap)) != 0;
      for (std::size_t i = first; i < pending_.size(); ++i) {
        if (static_cast<int>(i) == refIndex || pending_[i].wavelength == 0.0) continue;
        Track* tr = pending_[i].track;
        const double gf = ref.wavelength * rt->phase - pending_[i].wavelength * tr->phase;
        const bool comparable = options_.geometryFree && !refNew && tr->hasGf && tr->gfRef == rt->code &&
                                (tr->flags & (kSlipNewArc | kSlipGap)) == 0;
        if (comparable) {
          const double dt = elapsed(direction_, t, tr->last);
          if (std::abs(gf - tr->gf) > options_.geometryFreeThreshold + options_.geometryFreeRate * dt) {
            tr->flags |= kSlipGeometryFree;
            rt->flags |= kSlipGeometryFree;
          }
        }
        tr->gf = gf;
        tr->gfRef = rt->code;
        tr->hasGf = true;
      }
    }
  }
  // Doppler test with the common (receiver clock) part removed.
  work_.clear();
  for (const Pending& p : pending_) {
    if (std::isfinite(p.dopplerResidual)) work_.push_back(p.dopplerResidual);
  }
  if (options_.doppler && work_.size() >= 3) {
    const std::size_t mid = work_.size() / 2;
    std::nth_element(work_.begin(), work_.begin() + static_cast<std::ptrdiff_t>(mid), work_.end());
    const double median = work_[mid];
    for (Pending& p : pending_) {
      if (!std::isfinite(p.dopplerResidual)) continue;
      const double dt = elapsed(direction_, t, p.track->last);
      const double thr = options_.dopplerThreshold + options_.dopplerJerk * dt * dt * dt / 12.0;
      if (std::abs(p.dopplerResidual - median) > thr) p.track->flags |= kSlipDoppler;
    }
  }
  for (Pending& p : pending_) {
    Track* tr = p.track;
    tr->last = t;
    tr->valid = true;
    if (tr->flags & kSlipResetMask) tr->arcStart = t;
    ++counts_.checked;
    if (tr->flags & kSlipNewArc) ++counts_.newArcs;
    if (tr->flags & kSlipLli) ++counts_.lli;
    if (tr->flags & kSlipGap) ++counts_.gaps;
    if (tr->flags & kSlipGeometryFree) ++counts_.geometryFree;
    if (tr->flags & kSlipDoppler) ++counts_.doppler;
    if (tr->flags & kSlipHalfCycle) ++counts_.halfCycle;
  }
}

}  // namespace gvins
