// True satellite orbits and clocks for the simulator, built from a navigation file's broadcast
// records so that SPP/RTK with the same file remove them up to a realistic signal-in-space error.
//
// Per satellite the broadcast records (healthy ones unless configured otherwise; Galileo I/NAV,
// or F/NAV where a satellite has no I/NAV) are sorted by reference time (toe, GLONASS tb).
// Between two consecutive reference times the true state is the blend (1 - w) s_i(t) + w s_j(t)
// with the quintic smoothstep w (C^2), so the truth is continuous over any span and equals each
// record at its reference time; near the ends one record is used. On top come a per-satellite
// orbit error in the radial/along-track/cross-track frame and a clock error, each a constant
// plus a drift, scaled by the configured SISRE.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "gvins/base/gnss_time.hpp"
#include "gvins/base/observation.hpp"
#include "gvins/ephemeris/ephemeris_store.hpp"
#include "gvins/sim/gnss_sim_config.hpp"

namespace gvins::sim {

/// True state of a satellite at a GPST instant (ECEF of that instant).
struct GnssSatelliteState {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();   ///< m
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();   ///< m/s
  double clock = 0.0;       ///< satellite time - GPST, s (relativistic term included)
  double clockDrift = 0.0;  ///< s/s
  /// The broadcast part (what a user computes from the records) and the simulated errors.
  Eigen::Vector3d broadcastPosition = Eigen::Vector3d::Zero();
  double broadcastClock = 0.0;
  Eigen::Vector3d orbitError = Eigen::Vector3d::Zero();  ///< position - broadcastPosition, m
  double clockError = 0.0;                               ///< clock - broadcastClock, s
};

class GnssConstellation {
 public:
  /// Satellites of the configured systems with records around [start, end] (+- the records'
  /// validity windows of EphemerisStore).
  GnssConstellation(const EphemerisStore& nav, const GnssSimConfig& config, const GpsTime& start,
                    const GpsTime& end, std::uint64_t seed);

  const std::vector<SatId>& satellites() const { return sats_; }
  /// Whether the truth is defined at t (some record within its validity window).
  bool covers(SatId sat, const GpsTime& t) const;
  /// True state at t; std::nullopt when not covered. With `extension` > 0 also up to that many
  /// seconds beyond the validity windows, from the nearest record (the smooth continuation of the
  /// truth at the window's edge; for products that need interpolation nodes around the run).
  std::optional<GnssSatelliteState> state(SatId sat, const GpsTime& t, double extension = 0.0) const;
  /// Broadcast group delay of a pseudorange on `code` (s), blended like the clock.
  double groupDelay(SatId sat, ObsCode code, const GpsTime& t) const;
  /// GLONASS FDMA channel (from the navigation data).
  std::optional<int> glonassChannel(SatId sat) const;
  const GlonassChannels& glonassChannels() const { return channels_; }

 private:
  struct Record {
    GpsTime ref;
    double halfWindow = 0.0;
    const KeplerEphemeris* kepler = nullptr;
    const GlonassEphemeris* glonass = nullptr;
  };
  struct Sat {
    SatId id;
    std::vector<Record> records;
    // Orbit (radial, along, cross) and clock errors: value = e0 + e1 * (t - start) / 3600.
    Eigen::Vector4d e0 = Eigen::Vector4d::Zero();
    Eigen::Vector4d e1 = Eigen::Vector4d::Zero();
  };
  const Sat* find(SatId sat) const;
  // Indices of the records blended at t and the weight of the second; false if not covered.
  bool bracket(const Sat& s, const GpsTime& t, int& i, int& j, double& w, double& wDot, double extension = 0.0) const;

  GpsTime start_;
  std::vector<SatId> sats_;
  std::vector<Sat> data_;
  std::vector<int> index_;  // satIndex -> position in data_ (-1: none)
  GlonassChannels channels_;
};

}  // namespace gvins::sim
