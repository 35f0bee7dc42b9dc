#include "gvins/ephemeris/ephemeris_cache.hpp"

namespace gvins {

EphemerisCache::EphemerisCache(const EphemerisStore& store, EphemerisSelection policy)
    : store_(&store), policy_(policy) {}

template <class Record, class Choose>
const Record* EphemerisCache::lookup(std::vector<Entry<Record>>& entries, SatId sat, const GpsTime& t, Choose choose) {
  if (!sat.valid()) return nullptr;
  if (entries.empty()) entries.resize(static_cast<std::size_t>(numSatIndices()));
  Entry<Record>& e = entries[static_cast<std::size_t>(satIndex(sat))];
  if (!e.filled || e.revision != store_->revision() || t < e.choice.from || e.choice.until < t) {
    e.choice = choose();
    e.revision = store_->revision();
    e.filled = true;
  }
  return e.choice.record;
}

const KeplerEphemeris* EphemerisCache::kepler(SatId sat, const GpsTime& t) {
  return lookup(kepler_, sat, t, [&] { return store_->chooseKepler(sat, t, policy_); });
}

const GlonassEphemeris* EphemerisCache::glonass(SatId sat, const GpsTime& t) {
  return lookup(glonass_, sat, t, [&] { return store_->chooseGlonass(sat, t, policy_); });
}

}  // namespace gvins
