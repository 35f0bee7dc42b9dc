// Broadcast record changes in carrier-phase processing with broadcast orbits and clocks.
//
// A receiver's store switches a satellite to a newer broadcast record every so often (GPS/QZSS
// about every 2 h, BeiDou 1 h, Galileo 10 min, GLONASS 30 min). Each record carries its own
// orbit/clock error (decimetres), so the modelled range ρ − c·dt_s jumps at the switch while the
// measured carrier phase is continuous: a float ambiguity that had absorbed the old record's
// error is then off by the jump. Evaluating both records at the same transmit time gives the
// jump exactly (the error that is common to both records cancels), and the phase model can carry
// it over: the ambiguity keeps fitting.
#pragma once

#include <optional>
#include <variant>

#include <Eigen/Core>

#include "gvins/ephemeris/ephemeris_store.hpp"

namespace gvins {

/// A copy of the broadcast record a store selects for a satellite (Kepler systems or GLONASS).
struct BroadcastRecord {
  std::variant<KeplerEphemeris, GlonassEphemeris> record;
};

/// The record `nav` selects for `sat` at (transmit) time t with its default policy, the one
/// EphemerisStore::satelliteState uses without precise products or SSR; nullopt when there is none.
std::optional<BroadcastRecord> selectedBroadcastRecord(const EphemerisStore& nav, SatId sat, const GpsTime& t);

/// Same record: same system message, reference time and issue of data.
bool sameBroadcastRecord(const BroadcastRecord& a, const BroadcastRecord& b);

/// Change (m) of the modelled range ρ − c·dt_s for a receiver at `receiver` (ECEF, m) when the
/// record `from` is replaced by `to` at transmit time t: [|x_to − r| − c dt_to] − [|x_from − r| − c dt_from].
double broadcastRecordRangeChange(const BroadcastRecord& from, const BroadcastRecord& to, const GpsTime& t,
                                  const Eigen::Vector3d& receiver);

}  // namespace gvins
