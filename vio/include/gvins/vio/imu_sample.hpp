// One inertial measurement: angular rate and specific force in the IMU frame at a time stamp.
#pragma once

#include <cstdint>

#include <Eigen/Core>

namespace gvins::vio {

/// EuRoC `imu0/data.csv` row: w_RS_S (rad/s) and a_RS_S (m/s^2), both in the IMU frame S,
/// time stamp in integer nanoseconds on the sensor clock.
struct ImuSample {
  std::int64_t t_ns = 0;
  Eigen::Vector3d gyro = Eigen::Vector3d::Zero();   ///< rad/s
  Eigen::Vector3d accel = Eigen::Vector3d::Zero();  ///< m/s^2 (specific force: +g up at rest)
};

}  // namespace gvins::vio
