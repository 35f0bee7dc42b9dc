#include "gvins/base/observation.hpp"

#include <algorithm>

namespace gvins {

const SignalObs* SatObs::find(ObsCode code) const {
  for (const auto& s : signals) {
    if (s.code == code) return &s;
  }
  return nullptr;
}

SignalObs* SatObs::find(ObsCode code) {
  for (auto& s : signals) {
    if (s.code == code) return &s;
  }
  return nullptr;
}

const SignalObs* SatObs::bestOnBand(char band, std::uint8_t need) const {
  const std::string_view prio = attributePriority(sat.system, band);
  const SignalObs* best = nullptr;
  std::size_t bestRank = prio.size() + 1;
  for (const auto& s : signals) {
    if (s.code.band != band || (s.present & need) != need) continue;
    const std::size_t pos = prio.find(s.code.attr);
    const std::size_t rank = pos == std::string_view::npos ? prio.size() : pos;
    if (rank < bestRank) {
      best = &s;
      bestRank = rank;
    }
  }
  return best;
}

const SatObs* ObsEpoch::find(SatId s) const {
  for (const auto& o : sats) {
    if (o.sat == s) return &o;
  }
  return nullptr;
}

SatObs* ObsEpoch::find(SatId s) {
  for (auto& o : sats) {
    if (o.sat == s) return &o;
  }
  return nullptr;
}

SatObs& ObsEpoch::add(SatId s) {
  if (SatObs* o = find(s)) return *o;
  sats.push_back(SatObs{s, {}});
  return sats.back();
}

void GlonassChannels::set(int slot, int channel) {
  if (slot < 1 || slot > 27 || channel < -7 || channel > 6) return;
  k_[slot] = static_cast<std::int8_t>(channel);
  known_[slot] = true;
}

std::optional<int> GlonassChannels::get(int slot) const {
  if (slot < 1 || slot > 27 || !known_[slot]) return std::nullopt;
  return k_[slot];
}

bool GlonassChannels::empty() const {
  return std::none_of(known_.begin(), known_.end(), [](bool b) { return b; });
}

void GlonassChannels::mergeMissing(const GlonassChannels& other) {
  for (int s = 1; s <= 27; ++s) {
    if (!known_[s] && other.known_[s]) set(s, other.k_[s]);
  }
}

}  // namespace gvins
