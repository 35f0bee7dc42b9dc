#include "gvins/gnss/clock_jump_repair.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>

#include "gvins/base/constants.hpp"
#include "gvins/base/signal.hpp"

namespace gvins {
namespace {

constexpr double kMs = constants::kSpeedOfLight * 1e-3;  // m per millisecond of clock

}  // namespace

ClockJumpRepair::ClockJumpRepair(std::string label, ClockJumpOptions options)
    : label_(std::move(label)), options_(options) {}

std::int64_t ClockJumpRepair::detect(std::vector<double>& samples) const {
  if (static_cast<int>(samples.size()) < options_.minSatellites) return 0;
  const auto mid = samples.begin() + static_cast<std::ptrdiff_t>(samples.size() / 2);
  std::nth_element(samples.begin(), mid, samples.end());
  const double median = *mid;
  const auto k = static_cast<std::int64_t>(std::llround(median / kMs));
  if (k == 0) return 0;
  const double jump = static_cast<double>(k) * kMs;
  const auto agree = std::count_if(samples.begin(), samples.end(),
                                   [&](double x) { return std::abs(x - jump) < options_.tolerance; });
  if (agree < options_.minSatellites || 2 * agree <= static_cast<std::ptrdiff_t>(samples.size())) return 0;
  return k;
}

void ClockJumpRepair::warn(const char* what, std::int64_t ms, const GpsTime& t) {
  char buf[200];
  std::snprintf(buf, sizeof buf, "%s: receiver clock jump of %+lld ms in the %s at %d %.3f (corrected)", label_.c_str(),
                static_cast<long long>(ms), what, t.week(), t.tow());
  warnings_.emplace_back(buf);
}

void ClockJumpRepair::apply(ObsEpoch& epoch, const GlonassChannels& channels) {
  if (!options_.enabled) return;
  struct Value {
    SignalObs* s;
    Key key;
    double code, phase, lambda;  // m (corrected by the offsets so far); lambda 0: no phase
  };
  std::vector<Value> values;
  std::vector<double> codeSamples, phaseSamples;
  const GpsTime t = epoch.time;
  auto sample = [&](std::map<Key, History>& map, const Key& key, double v, std::vector<double>& out) {
    const auto it = map.find(key);
    if (it == map.end() || it->second.n < 2) return;
    const History& h = it->second;
    const double dt1 = h.t[1] - h.t[0], dt2 = t - h.t[1];
    if (!(dt1 > 0.0 && dt2 > 0.0 && dt1 <= options_.maxGap && dt2 <= options_.maxGap)) return;
    out.push_back(v - h.v[1] - (h.v[1] - h.v[0]) * dt2 / dt1);
  };
  for (SatObs& so : epoch.sats) {
    std::optional<int> channel;
    if (so.sat.system == System::Glonass) channel = channels.get(so.sat.prn);
    for (SignalObs& s : so.signals) {
      Value v{&s, Key{static_cast<int>(so.sat.system), so.sat.prn, s.code.band, s.code.attr}, 0.0, 0.0, 0.0};
      if (s.hasCode() && s.pseudorange > 1e6) {
        v.code = s.pseudorange - static_cast<double>(codeMs_) * kMs;
        sample(code_, v.key, v.code, codeSamples);
      }
      const auto lambda = carrierWavelength(so.sat.system, s.code.band, channel);
      if (s.hasPhase() && s.carrierPhase != 0.0 && lambda) {
        v.lambda = *lambda;
        v.phase = *lambda * s.carrierPhase - static_cast<double>(phaseMs_) * kMs;
        if (s.lossOfLock()) phase_.erase(v.key);  // a slip: no second difference across it
        sample(phase_, v.key, v.phase, phaseSamples);
      }
      values.push_back(v);
    }
  }
  const std::int64_t kc = detect(codeSamples), kp = detect(phaseSamples);
  if (kc != 0) {
    codeMs_ += kc;
    ++jumps_;
    warn("pseudoranges", kc, t);
  }
  if (kp != 0) {
    phaseMs_ += kp;
    if (kc == 0) ++jumps_;
    warn("carrier phases", kp, t);
  }
  auto remember = [&](std::map<Key, History>& map, const Key& key, double v) {
    History& h = map[key];
    if (h.n > 0) {
      const double dt = t - h.t[h.n - 1];
      if (!(dt > 0.0 && dt <= options_.maxGap)) h.n = 0;  // a gap (or time going back): start again
    }
    if (h.n == 2) {
      h.t[0] = h.t[1];
      h.v[0] = h.v[1];
      h.n = 1;
    }
    h.t[h.n] = t;
    h.v[h.n] = v;
    ++h.n;
  };
  for (Value& v : values) {
    if (v.code != 0.0) {
      v.code -= static_cast<double>(kc) * kMs;
      if (codeMs_ != 0) v.s->pseudorange = v.code;  // untouched while nothing was removed
      remember(code_, v.key, v.code);
    }
    if (v.lambda > 0.0) {
      v.phase -= static_cast<double>(kp) * kMs;
      if (phaseMs_ != 0) v.s->carrierPhase = v.phase / v.lambda;
      remember(phase_, v.key, v.phase);
    }
  }
}

}  // namespace gvins
