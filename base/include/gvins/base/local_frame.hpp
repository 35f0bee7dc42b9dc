// Local-level frames (East-North-Up and North-East-Down) and satellite azimuth/elevation.
#pragma once

#include <Eigen/Core>

#include "gvins/base/geodetic.hpp"

namespace gvins {

/// Rotation R such that v_enu = R * v_ecef at the given latitude/longitude (radians).
Eigen::Matrix3d ecefToEnuRotation(double lat, double lon);
/// Rotation R such that v_ned = R * v_ecef.
Eigen::Matrix3d ecefToNedRotation(double lat, double lon);

/// ENU coordinates of an ECEF point relative to an ECEF origin (the origin's geodetic latitude
/// and longitude define the axes).
Eigen::Vector3d ecefToEnu(const Eigen::Vector3d& ecef, const Eigen::Vector3d& originEcef);
/// Inverse of ecefToEnu.
Eigen::Vector3d enuToEcef(const Eigen::Vector3d& enu, const Eigen::Vector3d& originEcef);

struct AzEl {
  double azimuth = 0.0;    ///< radians, clockwise from north, [0, 2 pi)
  double elevation = 0.0;  ///< radians, [-pi/2, pi/2]
};

/// Azimuth and elevation of a satellite seen from a receiver (both ECEF). For a receiver near the
/// Earth's centre (|r| < 1 km, e.g. an unknown position) the elevation is pi/2.
AzEl azimuthElevation(const Eigen::Vector3d& receiverEcef, const Eigen::Vector3d& satelliteEcef);
/// Same with the receiver's geodetic coordinates already known.
AzEl azimuthElevation(const Geodetic& receiver, const Eigen::Vector3d& receiverEcef,
                      const Eigen::Vector3d& satelliteEcef);
/// Same with the receiver's ECEF-to-ENU rotation (ecefToEnuRotation of its latitude and
/// longitude) already known, for many satellites seen from one place.
AzEl azimuthElevation(const Eigen::Matrix3d& ecefToEnu, const Eigen::Vector3d& receiverEcef,
                      const Eigen::Vector3d& satelliteEcef);

}  // namespace gvins
