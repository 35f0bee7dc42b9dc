#include "gvins/gnss/doppler_consistency.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace gvins {

namespace {

double median(std::vector<double>& v) {
  if (v.empty()) return 0.0;
  const std::size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid), v.end());
  return v[mid];
}

}  // namespace

const char* toString(DopplerVerdict v) {
  switch (v) {
    case DopplerVerdict::Pending: return "undecided";
    case DopplerVerdict::Consistent: return "consistent";
    case DopplerVerdict::SignFlipped: return "sign flipped";
    case DopplerVerdict::Scaled: return "scaled";
    case DopplerVerdict::Inconsistent: return "inconsistent";
  }
  return "?";
}

std::string DopplerSignalReport::name() const {
  return std::string{systemLetter(system), ' ', 'L', code.band, code.attr};
}

DopplerConsistency::DopplerConsistency(std::string label, DopplerConsistencyOptions options)
    : label_(std::move(label)), options_(options), tracks_(static_cast<std::size_t>(numSatIndices())) {}

DopplerConsistency::SignalState& DopplerConsistency::state(System sys, ObsCode code) {
  for (SignalState& s : states_) {
    if (s.report.system == sys && s.report.code == code) return s;
  }
  states_.emplace_back();
  states_.back().report.system = sys;
  states_.back().report.code = code;
  return states_.back();
}

DopplerVerdict DopplerConsistency::verdict(System sys, ObsCode code) const {
  for (const SignalState& s : states_) {
    if (s.report.system == sys && s.report.code == code) return s.report.verdict;
  }
  return DopplerVerdict::Pending;
}

void DopplerConsistency::apply(ObsEpoch& epoch, const GlonassChannels& channels) {
  if (!options_.enabled) return;
  const bool fresh = !lastEpoch_ || elapsed(direction_, epoch.time, *lastEpoch_) > 1e-6;
  if (fresh) {
    ++counts_.epochs;
    sample(epoch, channels);
    lastEpoch_ = epoch.time;
  }
  for (SatObs& so : epoch.sats) {
    if (!so.sat.valid()) continue;
    for (SignalObs& s : so.signals) {
      if (!s.hasDoppler()) continue;
      const DopplerVerdict v = state(so.sat.system, s.code).report.verdict;
      if (v == DopplerVerdict::Consistent) {
        if (fresh) ++counts_.passed;
        continue;
      }
      if (v == DopplerVerdict::SignFlipped) {
        s.doppler = -s.doppler;
        if (fresh) ++counts_.corrected;
        continue;
      }
      s.doppler = 0.0;
      s.present = static_cast<std::uint8_t>(s.present & ~SignalObs::kDoppler);
      if (fresh) ++(v == DopplerVerdict::Pending ? counts_.withheld : counts_.dropped);
    }
  }
}

void DopplerConsistency::sample(const ObsEpoch& epoch, const GlonassChannels& channels) {
  const GpsTime t = epoch.time;
  std::vector<SignalState*> touched;
  for (const SatObs& so : epoch.sats) {
    if (!so.sat.valid()) continue;
    std::optional<int> channel;
    if (so.sat.system == System::Glonass) channel = channels.get(so.sat.prn).value_or(0);
    auto& list = tracks_[static_cast<std::size_t>(satIndex(so.sat))];
    for (const SignalObs& s : so.signals) {
      if (!s.hasDoppler() || !std::isfinite(s.doppler)) continue;
      Track* tr = nullptr;
      for (Track& x : list) {
        if (x.code == s.code) tr = &x;
      }
      const bool hasPhase = s.hasPhase() && std::isfinite(s.carrierPhase) && s.carrierPhase != 0.0;
      const bool hasCode = s.hasCode() && std::isfinite(s.pseudorange) && s.pseudorange != 0.0;
      SignalState& st = state(so.sat.system, s.code);
      const auto lam = carrierWavelength(so.sat.system, s.code.band, channel);
      if (tr && lam && st.report.verdict == DopplerVerdict::Pending) {
        // dt signed (rates are the same both ways), span in processing order.
        const double dt = t - tr->time;
        const double span = elapsed(direction_, t, tr->time);
        // The interval's loss of lock is flagged at its later epoch.
        const bool lockLost = direction_ == TimeDirection::Forward ? s.lossOfLock() : tr->lossOfLock;
        if (span > 0.0 && span <= options_.maxGap) {
          const double vd = -*lam * 0.5 * (tr->doppler + s.doppler);  // m/s, Doppler range rate
          double vl = 0.0, tol = 0.0;
          bool ok = false;
          if (hasPhase && tr->hasPhase && !lockLost) {
            vl = *lam * (s.carrierPhase - tr->phase) / dt;
            tol = options_.phaseTolerance + options_.dopplerJerk * dt * dt / 12.0;
            ok = true;
          } else if (!hasPhase && hasCode && tr->hasCode) {
            // Signals without phase only: a phase-less interval of a phase signal is a slip.
            vl = (s.pseudorange - tr->pseudorange) / dt;
            tol = 2.0 * std::sqrt(2.0) * options_.codeSigma / span + options_.phaseTolerance +
                  options_.dopplerJerk * dt * dt / 12.0;
            ok = true;
          }
          if (ok && std::isfinite(vl)) {
            st.samples.push_back({std::abs(vd - vl) / tol, std::abs(vd + vl) / tol, vd, vl, tol, hasPhase});
            const int idx = satIndex(so.sat);
            if (std::find(st.satellites.begin(), st.satellites.end(), idx) == st.satellites.end())
              st.satellites.push_back(idx);
            if (!st.lastInterval || *st.lastInterval != t) {
              ++st.intervals;
              st.lastInterval = t;
            }
            if (std::find(touched.begin(), touched.end(), &st) == touched.end()) touched.push_back(&st);
          }
        }
      }
      if (!tr) {
        list.push_back(Track{});
        list.back().code = s.code;
        tr = &list.back();
      }
      tr->time = t;
      tr->hasPhase = hasPhase;
      tr->hasCode = hasCode;
      tr->phase = s.carrierPhase;
      tr->pseudorange = s.pseudorange;
      tr->doppler = s.doppler;
      tr->lossOfLock = s.lossOfLock();
    }
  }
  for (SignalState* s : touched) decide(*s);
}

void DopplerConsistency::decide(SignalState& s) {
  const int n = static_cast<int>(s.samples.size());
  const bool enoughSatellites = static_cast<int>(s.satellites.size()) >= options_.minSatellites ||
                                s.intervals >= options_.patientIntervals;
  if (n < options_.minSamples || s.intervals < options_.minIntervals || !enoughSatellites) return;
  std::vector<double> c, f;
  c.reserve(s.samples.size());
  f.reserve(s.samples.size());
  for (const Sample& x : s.samples) {
    c.push_back(x.consistent);
    f.push_back(x.flipped);
  }
  const double mc = median(c), mf = median(f);
  // One hypothesis within its tolerance and the other clearly rejected (a signal whose range
  // rates are all small, e.g. one satellite near its closest approach, cannot tell them apart yet).
  constexpr double kRejected = 3.0;
  DopplerVerdict verdict = DopplerVerdict::Pending;
  double factor = 1.0;
  if (mc <= 1.0 && mf > kRejected) {
    verdict = DopplerVerdict::Consistent;
  } else if (mf <= 1.0 && mc > kRejected) {
    verdict = DopplerVerdict::SignFlipped;
    factor = -1.0;
  } else if (mc > kRejected && mf > kRejected) {
    // A scale error: the ratio v_D / v_L from the samples with a well-determined ratio (|v_L|
    // far above the tolerance), then the residual about that line.
    verdict = DopplerVerdict::Inconsistent;
    std::vector<double> k;
    for (const Sample& x : s.samples) {
      if (std::abs(x.vl) > 20.0 * x.tolerance) k.push_back(x.vd / x.vl);
    }
    if (static_cast<int>(k.size()) * 2 >= n) {
      const double ratio = median(k);
      std::vector<double> res;
      for (const Sample& x : s.samples) res.push_back(std::abs(x.vd - ratio * x.vl) / x.tolerance);
      if (median(res) <= 1.0 && std::abs(ratio - 1.0) > options_.scaleTolerance &&
          std::abs(ratio + 1.0) > options_.scaleTolerance) {
        verdict = DopplerVerdict::Scaled;
        factor = ratio;
      }
    }
  } else if (s.intervals >= options_.maxPendingIntervals) {
    // Never clearly apart (e.g. only geostationary satellites): the hypothesis within tolerance
    // that fits better (the RINEX convention on a tie); neither within tolerance: not trusted.
    if (mc <= 1.0 && mc <= mf) {
      verdict = DopplerVerdict::Consistent;
    } else if (mf <= 1.0) {
      verdict = DopplerVerdict::SignFlipped;
      factor = -1.0;
    } else {
      verdict = DopplerVerdict::Inconsistent;
    }
  }
  if (verdict == DopplerVerdict::Pending) {
    if (s.samples.size() > 1000) s.samples.erase(s.samples.begin(), s.samples.begin() + 500);
    return;
  }
  DopplerSignalReport& r = s.report;
  r.verdict = verdict;
  r.factor = factor;
  r.samples = n;
  r.fromPhase = 2 * std::count_if(s.samples.begin(), s.samples.end(), [](const Sample& x) { return x.phase; }) >= n;
  r.satellites = static_cast<int>(s.satellites.size());
  // Medians in m/s for the report.
  std::vector<double> cm, fm;
  for (const Sample& x : s.samples) {
    cm.push_back(std::abs(x.vd - x.vl));
    fm.push_back(std::abs(x.vd + x.vl));
  }
  r.medianConsistent = median(cm);
  r.medianFlipped = median(fm);
  s.samples.clear();
  s.samples.shrink_to_fit();
  if (r.verdict != DopplerVerdict::Consistent) warn(r);
}

void DopplerConsistency::warn(const DopplerSignalReport& r) {
  const char* against = r.fromPhase ? "carrier-phase" : "pseudorange";
  char buf[256];
  switch (r.verdict) {
    case DopplerVerdict::SignFlipped:
      std::snprintf(buf, sizeof buf, "%s: Doppler sign flipped on %s (corrected)", label_.c_str(), r.name().c_str());
      break;
    case DopplerVerdict::Scaled:
      std::snprintf(buf, sizeof buf, "%s: Doppler scaled by %.4g against the %s rate on %s (dropped)", label_.c_str(),
                    r.factor, against, r.name().c_str());
      break;
    default:
      std::snprintf(buf, sizeof buf, "%s: Doppler inconsistent with the %s rate on %s (dropped)", label_.c_str(),
                    against, r.name().c_str());
      break;
  }
  warnings_.emplace_back(buf);
}

std::string DopplerConsistency::countsText() const {
  char buf[200];
  std::snprintf(buf, sizeof buf, "%lld passed, %lld corrected, %lld dropped, %lld withheld (undecided)",
                static_cast<long long>(counts_.passed), static_cast<long long>(counts_.corrected),
                static_cast<long long>(counts_.dropped), static_cast<long long>(counts_.withheld));
  return buf;
}

std::vector<DopplerSignalReport> DopplerConsistency::signals() const {
  std::vector<DopplerSignalReport> out;
  for (const SignalState& s : states_) {
    out.push_back(s.report);
    if (s.report.verdict == DopplerVerdict::Pending) {
      out.back().samples = static_cast<int>(s.samples.size());
      out.back().satellites = static_cast<int>(s.satellites.size());
    }
  }
  return out;
}

std::vector<std::string> DopplerConsistency::summary() const {
  std::vector<std::string> out;
  for (const DopplerSignalReport& r : signals()) {
    if (r.verdict == DopplerVerdict::Consistent) continue;
    char buf[320];
    const char* action = r.verdict == DopplerVerdict::SignFlipped ? "corrected"
                         : r.verdict == DopplerVerdict::Pending   ? "withheld"
                                                                  : "dropped";
    std::snprintf(buf, sizeof buf,
                  "%s: Doppler %s on %s (%s; %d samples, %d satellites, median |v_D-v_%s| %.3g m/s, |v_D+v_%s| %.3g m/s)",
                  label_.c_str(), toString(r.verdict), r.name().c_str(), action, r.samples, r.satellites,
                  r.fromPhase ? "L" : "P", r.medianConsistent, r.fromPhase ? "L" : "P", r.medianFlipped);
    out.emplace_back(buf);
  }
  return out;
}

}  // namespace gvins
