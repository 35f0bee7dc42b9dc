// Satellite states of one rover epoch, computed once per satellite and shared by the steps of a
// processing chain that need them (the fusion's satellite models, the single differences):
// evaluating an orbit (broadcast Kepler/GLONASS integration or a precise-orbit interpolation) is
// the larger part of forming either.
#pragma once

#include <optional>
#include <utility>
#include <vector>

#include "gvins/base/gnss_time.hpp"
#include "gvins/base/satellite.hpp"
#include "gvins/ephemeris/ephemeris_store.hpp"
#include "gvins/gnss/zero_difference.hpp"

namespace gvins {

class TransmitStates {
 public:
  /// `nav` must outlive this object. All states use the default EphemerisSelection.
  TransmitStates(const EphemerisStore& nav, const GpsTime& receiveTime) : nav_(&nav), receiveTime_(receiveTime) {}

  const GpsTime& receiveTime() const { return receiveTime_; }

  /// satelliteAtTransmit(nav, sat, receiveTime, pseudorange) the first time a satellite is asked
  /// for with a plausible pseudorange, the stored result afterwards (also when it was nullopt).
  /// A later caller with another code of the same satellite gets the first caller's transmit
  /// time: they differ by the codes' ionospheric and group delays (tens of ns, under 0.1 mm of
  /// satellite motion and 1e-13 s of satellite clock).
  std::optional<TransmitState> get(SatId sat, double pseudorange) {
    for (const auto& [s, st] : states_) {
      if (s == sat) return st;
    }
    if (!(pseudorange > 1e6 && pseudorange < 1e8)) return std::nullopt;
    states_.emplace_back(sat, satelliteAtTransmit(*nav_, sat, receiveTime_, pseudorange));
    return states_.back().second;
  }

 private:
  const EphemerisStore* nav_;
  GpsTime receiveTime_;
  std::vector<std::pair<SatId, std::optional<TransmitState>>> states_;
};

/// The state from `states` when it is given and holds this receive time, else
/// satelliteAtTransmit(nav, ...) directly: the one call for steps that may or may not share.
inline std::optional<TransmitState> transmitState(TransmitStates* states, const EphemerisStore& nav, SatId sat,
                                                  const GpsTime& receiveTime, double pseudorange) {
  if (states && states->receiveTime() == receiveTime) return states->get(sat, pseudorange);
  return satelliteAtTransmit(nav, sat, receiveTime, pseudorange);
}

}  // namespace gvins
