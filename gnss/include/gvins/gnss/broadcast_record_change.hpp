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

/// The broadcast record one carrier-phase arc of a satellite uses, followed epoch by epoch, and the
/// sum of the modelled-range jumps of its record changes: the metres to add to the arc's phase so
/// that one ambiguity keeps fitting across them.
class BroadcastRecordContinuity {
 public:
  struct Step {
    bool found = false;    ///< `nav` has a record for the satellite
    bool changed = false;  ///< it differs from the previous epoch's
    double jump = 0.0;     ///< m, added to shift() (0 without a change)
  };
  /// Follows the record `nav` selects for `sat` at `selectTime` (the uncorrected transmit time
  /// t_rx − P/c, where satelliteAtTransmit selects); a change adds its jump at `transmitTime` for
  /// a receiver at `receiver`. Without a record nothing changes.
  Step update(const EphemerisStore& nav, SatId sat, const GpsTime& selectTime, const GpsTime& transmitTime,
              const Eigen::Vector3d& receiver);
  /// m, to add to the arc's phase.
  double shift() const { return shift_; }

 private:
  std::optional<BroadcastRecord> record_;
  double shift_ = 0.0;
};

}  // namespace gvins
