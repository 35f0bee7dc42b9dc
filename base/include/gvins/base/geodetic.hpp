// WGS 84 geodetic coordinates and conversions to and from ECEF.
#pragma once

#include <Eigen/Core>

namespace gvins {

/// Geodetic latitude and longitude in radians, ellipsoidal height in metres (WGS 84).
struct Geodetic {
  double lat = 0.0;
  double lon = 0.0;
  double height = 0.0;
};

/// ECEF position (m) of a geodetic point.
Eigen::Vector3d geodeticToEcef(const Geodetic& g);
/// Geodetic coordinates of an ECEF position; round trip exact to < 1e-6 m for any point outside the Earth's
/// core (iterative, converges in a few steps). The origin maps to lat = 0, lon = 0, h = -a.
Geodetic ecefToGeodetic(const Eigen::Vector3d& ecef);

/// Convenience: degrees in, radians stored.
Geodetic geodeticFromDegrees(double latDeg, double lonDeg, double height);

}  // namespace gvins
