// Low-precision position of the Sun in the Earth-fixed frame, for satellite attitude models
// (yaw-steering axes, antenna offsets) and eclipse checks, where an arcminute is plenty.
//
// Model: Montenbruck & Gill, "Satellite Orbits" (Springer 2000), 3.3.2: mean anomaly and ecliptic
// longitude from a truncated series (about 0.1-1 arcmin, 0.1 % in distance), the ecliptic rotated
// by the obliquity 23.43929111 deg and the longitude advanced by the precession 1.3972 deg per
// century (mean equinox of date); Earth-fixed through the Greenwich mean sidereal time (IAU 1982,
// Aoki et al. 1982) with UT1 = UTC. Precession in latitude, nutation and polar motion are ignored
// (together below 3e-4 rad in direction).
#pragma once

#include <Eigen/Core>

#include "gvins/base/gnss_time.hpp"

namespace gvins {

/// Sun position (m) in the Earth-fixed frame at a GPST instant.
Eigen::Vector3d sunPositionEcef(const GpsTime& t);

/// Greenwich mean sidereal time (rad, in [0, 2π)) at a GPST instant (UT1 taken as UTC).
double greenwichMeanSiderealTime(const GpsTime& t);

}  // namespace gvins
