// Everything the rover and the base receiver of a run share: the configuration, the broadcast
// ephemerides, the true satellite orbits and clocks, the atmosphere, the place and the time span.
#pragma once

#include <cstdint>

#include <Eigen/Core>

#include "gvins/base/geodetic.hpp"
#include "gvins/base/gnss_time.hpp"
#include "gvins/ephemeris/ephemeris_store.hpp"
#include "gvins/ephemeris/rinex_nav.hpp"
#include "gvins/sim/gnss_atmosphere.hpp"
#include "gvins/sim/gnss_constellation.hpp"
#include "gvins/sim/gnss_sim_config.hpp"

namespace gvins::sim {

/// ECEF position of the base antenna: `positionLlh` if given, else `distance` along the
/// `azimuthDeg` direction from the origin on the ellipsoid (geodesic direct problem on the
/// origin's osculating sphere, exact to millimetres over tens of kilometres) at the origin's
/// height + `height`.
Eigen::Vector3d gnssBasePosition(const GnssBaseConfig& base, const Geodetic& origin);

class GnssSimWorld {
 public:
  /// Truth on the true-GPST span [start, start + duration].
  GnssSimWorld(const GnssSimConfig& config, const NavData& nav, const Geodetic& origin, const GpsTime& start,
               double duration, std::uint64_t seed);
  GnssSimWorld(const GnssSimWorld&) = delete;
  GnssSimWorld& operator=(const GnssSimWorld&) = delete;

  const GnssSimConfig& config() const { return config_; }
  const NavData& nav() const { return nav_; }
  const EphemerisStore& store() const { return store_; }
  const GnssConstellation& constellation() const { return constellation_; }
  const GnssAtmosphere& atmosphere() const { return atmosphere_; }
  const Geodetic& origin() const { return origin_; }
  const GpsTime& start() const { return start_; }
  GpsTime end() const { return start_ + duration_; }
  double duration() const { return duration_; }
  std::uint64_t seed() const { return seed_; }
  /// Base antenna position (ECEF), whether or not the base is enabled.
  const Eigen::Vector3d& basePosition() const { return basePosition_; }

 private:
  GnssSimConfig config_;
  NavData nav_;
  EphemerisStore store_;
  Geodetic origin_;
  GpsTime start_;
  double duration_;
  std::uint64_t seed_;
  GnssConstellation constellation_;
  GnssAtmosphere atmosphere_;
  Eigen::Vector3d basePosition_;
};

}  // namespace gvins::sim
