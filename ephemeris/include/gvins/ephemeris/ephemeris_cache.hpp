// Per-satellite cache of broadcast-record selections: epoch after epoch a processor asks for the
// record of the same satellites at nearby times, and the answer changes only every few minutes.
#pragma once

#include <cstdint>
#include <vector>

#include "gvins/ephemeris/ephemeris_store.hpp"

namespace gvins {

class EphemerisCache {
 public:
  /// `store` must outlive the cache; records may be added to it meanwhile (the cache notices).
  explicit EphemerisCache(const EphemerisStore& store, EphemerisSelection policy = {});

  /// Always the record store.selectKepler(sat, t, policy) / selectGlonass(...) returns; the search
  /// is made again only when t leaves the span of the last choice for the satellite (see
  /// EphemerisChoice) or the store has changed.
  const KeplerEphemeris* kepler(SatId sat, const GpsTime& t);
  const GlonassEphemeris* glonass(SatId sat, const GpsTime& t);

 private:
  template <class Record>
  struct Entry {
    EphemerisChoice<Record> choice;
    std::uint64_t revision = 0;
    bool filled = false;
  };
  template <class Record, class Choose>
  const Record* lookup(std::vector<Entry<Record>>& entries, SatId sat, const GpsTime& t, Choose choose);

  const EphemerisStore* store_;
  EphemerisSelection policy_;
  std::vector<Entry<KeplerEphemeris>> kepler_;  // by satIndex
  std::vector<Entry<GlonassEphemeris>> glonass_;
};

}  // namespace gvins
