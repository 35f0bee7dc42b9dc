// Receiver velocity and clock drift from Doppler range rates by weighted least squares.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "gvins/base/satellite.hpp"
#include "gvins/gnss/fault_exclusion.hpp"

namespace gvins {

/// One Doppler measurement converted to a range rate.
struct RangeRateMeasurement {
  SatId sat;
  Eigen::Vector3d satPosition = Eigen::Vector3d::Zero();  ///< ECEF at transmit time, m
  Eigen::Vector3d satVelocity = Eigen::Vector3d::Zero();  ///< ECEF, m/s
  double satClockDrift = 0.0;  ///< s/s
  double rangeRate = 0.0;      ///< -wavelength * Doppler, m/s
  double variance = 0.0;       ///< (m/s)^2
};

struct VelocitySolution {
  bool valid = false;
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();              ///< ECEF, m/s
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();            ///< ECEF, (m/s)^2
  double clockDrift = 0.0;          ///< receiver clock drift times c, m/s
  double clockDriftVariance = 0.0;  ///< (m/s)^2
  int numMeasurements = 0;          ///< used
  std::vector<SatId> excluded;
  double chi2 = 0.0;
  int dof = 0;
  bool testPassed = false;
};

/// Solves v_r and c*dtr_dot from range rates observed at a known receiver position:
/// rangeRate = e . (v_s - v_r) + Sagnac rate + c dtr_dot - c dts_dot, with e the unit vector from
/// receiver to satellite. The model is linear, so one weighted least-squares step is exact.
/// Faulty measurements are excluded with detectAndExclude.
VelocitySolution solveDopplerVelocity(const std::vector<RangeRateMeasurement>& meas,
                                      const Eigen::Vector3d& receiverPosition,
                                      const FaultExclusionOptions& fde);

}  // namespace gvins
