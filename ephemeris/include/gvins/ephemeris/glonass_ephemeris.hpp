// Broadcast GLONASS ephemeris (GLONASS ICD ed. 5.1, 4.4): PZ-90 state vector at tb with
// luni-solar accelerations, clock offset and frequency offset.
#pragma once

#include <Eigen/Core>

#include "gvins/base/gnss_time.hpp"
#include "gvins/base/satellite.hpp"

namespace gvins {

struct GlonassEphemeris {
  SatId sat;                 ///< R01..R27 (slot number)
  int frequencyChannel = 0;  ///< FDMA channel k, -7..+6
  GpsTime toe;               ///< tb as a GPST instant (RINEX epoch is UTC; converted)
  GpsTime tof;               ///< message frame time (RINEX "message frame time"), GPST
  int iode = 0;              ///< tb in 15-minute units within the day (identifies the set)
  int health = 0;            ///< Bn (0 = healthy) combined with l/Cn as broadcast
  int age = 0;               ///< En, days
  double accuracy = 0.0;     ///< FT as an accuracy in m (0 = unknown)

  Eigen::Vector3d position = Eigen::Vector3d::Zero();      ///< PZ-90, m
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();      ///< m/s
  Eigen::Vector3d acceleration = Eigen::Vector3d::Zero();  ///< luni-solar, m/s^2

  double tauN = 0.0;    ///< SV clock bias, s; the ICD defines t_sv - t_GLO = -tauN + gammaN (t - tb)
  double gammaN = 0.0;  ///< relative frequency bias
  double deltaTauN = 0.0;  ///< L1/L2 group delay difference, s
};

/// Whether the record allows use: health (Bn MSB / RINEX health flag) zero (GLONASS ICD 5.1, 4.4).
bool isHealthy(const GlonassEphemeris& eph);

}  // namespace gvins
