// One simulated GNSS receiver (rover or base): epochs on a regular grid of its own clock with
// pseudorange, carrier phase, Doppler and C/N0 of every configured signal of every satellite
// above its elevation mask, and the truth behind them (gnss_sim_epoch.hpp for the model).
//
// Per satellite: light time solved iteratively with the satellite state at the true transmit
// time and the Earth's rotation during the flight; elevation mask; blockage, non-line-of-sight
// reception and scheduled outages. Per signal: C/N0 from elevation, thermal noise scaled by
// C/N0, Gauss-Markov multipath, integer ambiguity aligned with the pseudorange when tracking
// starts (as receivers that output aligned phases do), random cycle slips.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "gvins/sim/gnss_random.hpp"
#include "gvins/sim/gnss_receiver_clock.hpp"
#include "gvins/sim/gnss_sim_epoch.hpp"
#include "gvins/sim/gnss_sim_world.hpp"
#include "gvins/sim/urban_signal_path.hpp"

namespace gvins::sim {

/// Antenna phase centre in ECEF at a true GPST instant.
struct GnssAntennaState {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< m
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  ///< m/s
  /// Antenna axes (columns x, y, boresight z in ECEF) for the phase wind-up; zero: level, x north,
  /// y west.
  Eigen::Matrix3d axes = Eigen::Matrix3d::Zero();
};
using GnssAntennaMotion = std::function<GnssAntennaState(const GpsTime& gpst)>;
/// The path of a satellite's signal to the antenna (both ECEF: antenna position, unit vector
/// towards the satellite) through 3-D structure (urban_signal_path.hpp).
using GnssPathModel = std::function<UrbanSignalPath(const Eigen::Vector3d& antenna, const Eigen::Vector3d& toSatellite)>;

class GnssReceiverSim {
 public:
  /// `world` must outlive the receiver. Epoch tags lie on the grid of multiples of 1/rate (in
  /// receiver time); epochs whose true time falls outside the world's span are not produced.
  GnssReceiverSim(const GnssSimWorld& world, GnssReceiverRole role, GnssAntennaMotion motion);

  /// Decide blockage and non-line-of-sight reception per satellite ray with `model` (in
  /// addition to the random events of the configuration): a blocked satellite is lost, a
  /// reflected one delayed by the extra path with C/N0 lowered by nlos.cn0_drop_db, and the
  /// multipath scaled; each change of path restarts the carrier (new ambiguity). Events are
  /// recorded like the random ones ("blockage", "nlos" with the extra path at its start).
  void setPathModel(GnssPathModel model) { pathModel_ = std::move(model); }

  /// The next epoch (observations may be empty during a total outage); std::nullopt at the end.
  std::optional<GnssSimEpoch> next();
  /// Time tag of the epoch next() will consider (std::nullopt at the end).
  std::optional<GpsTime> peekTag() const;

  /// Closes open ambiguity arcs and event intervals (call after the last epoch).
  void finish();
  const std::vector<GnssAmbiguityArc>& arcs() const { return arcs_; }
  const std::vector<GnssSlipEvent>& slips() const { return slips_; }
  const std::vector<GnssEventInterval>& events() const { return events_; }
  const GnssReceiverClock& clock() const { return clock_; }
  GnssReceiverRole role() const { return role_; }
  const GnssReceiverConfig& config() const { return rc_; }
  std::int64_t epochs() const { return epochs_; }

 private:
  struct SignalTrack {
    ObsCode code;
    bool active = false;
    std::int64_t ambiguity = 0;
    int arc = -1;          // index into arcs_
    double mpCode = 0.0;   // unit-variance Gauss-Markov states
    double mpPhase = 0.0;
    bool mpStarted = false;
    GpsTime mpTime;
    const char* restartCause = nullptr;  // why the next arc starts (nullptr: satellite rise)
    GnssRandom rng;
  };
  struct SatTrack {
    SatId sat;
    double tau = 0.075;      // light time of the last epoch, s (warm start)
    bool tauValid = false;
    double cn0Offset = 0.0;
    bool blocked = false;
    GpsTime blockEnd;
    int blockEvent = -1;
    bool nlos = false;
    GpsTime nlosEnd;
    double nlosBias = 0.0;
    int nlosEvent = -1;
    int pathState = 0;   // path model: 0 line of sight, 1 reflected, 2 blocked
    int pathEvent = -1;  // its open event interval
    std::optional<double> windup;  // cycles, continued while the satellite is in view
    GnssRandom rng;
    std::vector<SignalTrack> signals;
  };
  /// One epoch (its stages: GnssEpochProducer in gnss_receiver_sim.cpp).
  void produce(const GpsTime& tag, const GpsTime& t, GnssSimEpoch& out);
  friend class GnssEpochProducer;
  static void lose(SatTrack& st, const char* cause);
  static void loseSignal(SignalTrack& sg, const char* cause);

  const GnssSimWorld& world_;
  const GnssSimConfig& cfg_;
  GnssReceiverRole role_;
  GnssReceiverConfig rc_;
  GnssAntennaMotion motion_;
  GnssPathModel pathModel_;
  GnssReceiverClock clock_;
  GpsTime gridStart_;
  std::int64_t k_ = 0;
  bool done_ = false;
  bool first_ = true;
  std::int64_t epochs_ = 0;
  GpsTime lastTag_;
  std::vector<SatTrack> sats_;
  std::vector<GnssAmbiguityArc> arcs_;
  std::vector<GnssSlipEvent> slips_;
  std::vector<GnssEventInterval> events_;
  std::vector<bool> outageActive_;
};

}  // namespace gvins::sim
