// Simulated IMU: samples of angular rate and specific force at a fixed rate along a
// trajectory, with white noise and bias random walks (Kalibr's discrete model; imu_noise.hpp)
// plus a random turn-on bias.
//
// Noise-free, a sample is the exact instantaneous angular rate and specific force of the
// trajectory at its stamp, the measurement model of vio::ImuPropagator (imu_propagation.hpp),
// which therefore reproduces the truth (test_imu_simulator.cpp: < 1 mm after 60 s).
//
// Earth models:
//   flat (default, what gvins::vio assumes): W is treated as inertial with uniform gravity
//     (0, 0, -g): gyro = omega_B, accel = R_WB^T (a_WB + g e_z).
//   rotating: W is Earth-fixed (ENU at the origin) and the IMU senses the Earth's rotation
//     and the local normal gravity: gyro = omega_B + R_WB^T omega_ie^W,
//     accel = R_WB^T (a_WB + 2 omega_ie^W x v_WB - gamma^W(p)), gamma the normal gravity vector
//     (gravitation plus centrifugal) at the current position (Groves, "Principles of GNSS,
//     Inertial, and Multisensor Integrated Navigation Systems", 2nd ed. 2013, eqs. 2.139, 5.45
//     rewritten in a local Earth-fixed frame).
//
// Defaults: the noise densities and random walks of the ADIS16448 MEMS IMU of the EuRoC MAV
// (its mav0/imu0/sensor.yaml, Burri et al., IJRR 2016), i.e. vio::ImuNoise's defaults; turn-on
// biases of 1-sigma 0.01 rad/s (0.57 deg/s) and 0.05 m/s^2 per axis, the order of the biases
// the EuRoC ground truth estimates for that IMU (V1_02: gyro (-0.002, 0.021, 0.076) rad/s,
// accel (-0.014, 0.105, 0.093) m/s^2).
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "gvins/sim/local_frame.hpp"
#include "gvins/sim/trajectory.hpp"
#include "gvins/vio/imu_noise.hpp"
#include "gvins/vio/imu_sample.hpp"

namespace gvins::sim {

enum class EarthModel { Flat, Rotating };

struct ImuSimConfig {
  double rateHz = 200.0;
  /// Noise densities and random walks (Kalibr names); noise.rate_hz is set to rateHz.
  vio::ImuNoise noise;
  bool whiteNoise = true;
  bool biasRandomWalk = true;
  /// Turn-on biases: fixed value plus a random draw of the given 1-sigma per axis.
  Eigen::Vector3d gyroBias = Eigen::Vector3d::Zero();
  Eigen::Vector3d accelBias = Eigen::Vector3d::Zero();
  double gyroBiasSigma = 0.01;   ///< rad/s
  double accelBiasSigma = 0.05;  ///< m/s^2
  EarthModel earth = EarthModel::Flat;
  /// Flat model: gravity magnitude (m/s^2); <= 0 selects the WGS 84 normal gravity at the
  /// origin (normal_gravity.hpp).
  double gravity = 0.0;

  /// Throws std::invalid_argument for rates outside [10, 2000] Hz or negative/non-finite noise.
  void validate() const;
};

struct SimulatedImu {
  std::vector<vio::ImuSample> samples;        ///< stamps in GPST ns (LocalFrame::stampNs)
  std::vector<Eigen::Vector3d> gyroBias;      ///< true bias at each sample
  std::vector<Eigen::Vector3d> accelBias;
  double gravity = 9.81;                      ///< magnitude used by the flat model
  std::int64_t period_ns = 0;
};

/// Gravity magnitude the flat model uses for this configuration and frame.
double flatGravity(const ImuSimConfig& config, const LocalFrame& frame);

/// Noise- and bias-free angular rate and specific force of a truth state.
void idealImu(const TrajectoryState& s, const LocalFrame& frame, const ImuSimConfig& config, double flatG,
              Eigen::Vector3d& gyro, Eigen::Vector3d& accel);

/// Samples at stamps startStamp + k period (period = round(1e9 / rate) ns) over the trajectory.
SimulatedImu simulateImu(const Trajectory& trajectory, const LocalFrame& frame, const ImuSimConfig& config,
                         std::uint64_t seed);

}  // namespace gvins::sim
