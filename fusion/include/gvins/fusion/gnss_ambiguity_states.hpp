// The float ambiguity states of the GNSS fusion (vio+dopp+ppp, docs/gnss_fusion.md "Float PPP"):
// one client block of size 1 (m) per satellite arc of the ionosphere-free carrier phase, in front
// of the state (ClientBlockRegion::kFront: visual rows never reach those columns and a block that
// ends with its arc is cheap to marginalize there). Each starts with its prior N(N₀, σ²), is
// constant along its arc except for the random walk of satellites on broadcast orbits and clocks
// (one step for all of them per epoch), and is marginalized when its arc ends. GnssAmbiguityStates
// owns those blocks by satellite: creation, prior, propagation, values, removal, and what the
// fusion keeps along each arc (GnssAmbiguityArc).
#pragma once

#include <cstddef>
#include <map>
#include <optional>
#include <vector>

#include "gvins/base/gnss_time.hpp"
#include "gvins/base/satellite.hpp"
#include "gvins/gnss/broadcast_record_change.hpp"
#include "gvins/sri/block.hpp"
#include "gvins/vio/estimator_backend.hpp"

namespace gvins::fusion {

/// What the fusion keeps along the arc of an ambiguity state besides the state itself.
struct GnssAmbiguityArc {
  GpsTime start;       ///< start of the carrier arc the state belongs to
  GpsTime lastRow;     ///< last epoch with a phase row
  int rejections = 0;  ///< consecutive gated-out phase rows
  std::optional<double> windup;  ///< cycles, continued over the arc
  /// Broadcast satellites: the record of the last phase row and the jumps of the record changes
  /// since the state started (added to the phase).
  BroadcastRecordContinuity records;
};

template <typename Scalar>
class GnssAmbiguityStates {
 public:
  std::size_t size() const { return states_.size(); }
  bool empty() const { return states_.empty(); }
  bool contains(SatId sat) const { return states_.count(sat) > 0; }
  /// The block of `sat`'s state; invalid if none.
  sri::BlockId block(SatId sat) const;
  /// The arc of `sat`'s state; nullptr if none.
  GnssAmbiguityArc* arc(SatId sat);
  /// The estimate of `sat`'s state (m; contains(sat) only).
  double value(const vio::EstimatorBackend<Scalar>& est, SatId sat) const;
  /// The estimates of every state (m), by satellite.
  std::map<SatId, double> values(const vio::EstimatorBackend<Scalar>& est) const;

  /// Adds the state of `sat`'s arc that started at `arcStart`: estimate `x`, prior σ `sigma` (m),
  /// in front of the state. `sat` must have none (drop() the old arc's first; std::logic_error).
  GnssAmbiguityArc& add(vio::EstimatorBackend<Scalar>& est, SatId sat, double x, double sigma, const GpsTime& arcStart);
  /// One random-walk step to time t of the states of `sats` that exist (satellites on broadcast
  /// records): variance q²·Δt each, q `randomWalk` (m/√s), Δt since the last call (none at the
  /// first call; every call moves that time, even without a step).
  void propagate(vio::EstimatorBackend<Scalar>& est, const std::vector<SatId>& sats, const GpsTime& t,
                 double randomWalk);
  /// Marginalizes `sat`'s state (arc ended, slipped or rejected); nothing if it has none.
  void drop(vio::EstimatorBackend<Scalar>& est, SatId sat);
  /// Drops the states whose last phase row is more than `maxAge` s before `now`.
  void dropStale(vio::EstimatorBackend<Scalar>& est, const GpsTime& now, double maxAge);
  /// Marginalizes every state, one after the other by satellite, and restarts the random-walk
  /// time (an outage).
  void dropAll(vio::EstimatorBackend<Scalar>& est);
  /// Forgets every state (the estimator's state is gone).
  void forget();

 private:
  struct State {
    sri::BlockId id;
    GnssAmbiguityArc arc;
  };
  std::map<SatId, State> states_;
  std::optional<GpsTime> time_;  // last random-walk step (or call of propagate)
};

extern template class GnssAmbiguityStates<float>;
extern template class GnssAmbiguityStates<double>;

}  // namespace gvins::fusion
