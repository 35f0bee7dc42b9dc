// Where and when a simulated flight happens: the geodetic origin of the local world frame
// W (East-North-Up, Earth-fixed) and the GPST instant of the flight start. Maps W to ECEF and
// flight seconds to GPST and to the sensor time stamps of the dataset.
//
// Sensor time stamps (imu0/cam0/ground truth data.csv) are integer GPST nanoseconds since the
// GPS epoch 1980-01-06 00:00:00 GPST; GNSS observation epochs are GPST. Both clocks are the same.
#pragma once

#include <cstdint>

#include <Eigen/Core>

#include "gvins/base/geodetic.hpp"
#include "gvins/base/gnss_time.hpp"

namespace gvins::sim {

struct LocalFrame {
  Geodetic origin;    ///< WGS 84 origin of W (radians, ellipsoidal height in m)
  GpsTime startTime;  ///< GPST of t = 0; whole nanoseconds (sensor stamps are exact integers)

  /// ECEF position of the origin.
  Eigen::Vector3d originEcef() const;
  /// Rotation R_EW: v_ECEF = R_EW v_W (columns: east, north, up at the origin).
  Eigen::Matrix3d rotationEcefFromW() const;
  /// ECEF position of a point given in W.
  Eigen::Vector3d toEcef(const Eigen::Vector3d& p_W) const;
  /// W coordinates of an ECEF position.
  Eigen::Vector3d fromEcef(const Eigen::Vector3d& p_E) const;
  /// A free vector (velocity, acceleration, direction) from W to ECEF axes.
  Eigen::Vector3d vectorToEcef(const Eigen::Vector3d& v_W) const { return rotationEcefFromW() * v_W; }
  /// Geodetic coordinates of a point given in W.
  Geodetic toGeodetic(const Eigen::Vector3d& p_W) const;

  /// GPST of flight time t (seconds from the start).
  GpsTime gpsTime(double t) const { return startTime + t; }
  /// Flight time (s) of a GPST instant.
  double flightTime(const GpsTime& gpst) const { return gpst - startTime; }
  /// Sensor stamp (GPST ns since the GPS epoch) of the start.
  std::int64_t startStampNs() const;
  /// Sensor stamp of flight time t, rounded to the nearest nanosecond.
  std::int64_t stampNs(double t) const;
  /// Flight time (s) of a sensor stamp.
  double flightTimeOfStamp(std::int64_t stamp_ns) const;
};

}  // namespace gvins::sim
