// IMU noise parameters with the Kalibr / EuRoC `sensor.yaml` names and units.
//
// Continuous-time model (Kalibr wiki "IMU Noise Model"): measured = true + bias + white noise,
// white noise with spectral density sigma (the `*_noise_density`), bias a random walk driven by
// white noise of density sigma_b (the `*_random_walk`). Sampled at `rate_hz`, a sample's white
// noise has standard deviation sigma * sqrt(rate_hz) and the bias changes by sigma_b / sqrt(rate_hz)
// per sample.
#pragma once

namespace gvins::vio {

struct ImuNoise {
  double gyroscope_noise_density = 1.6968e-4;     ///< rad/s/sqrt(Hz)
  double gyroscope_random_walk = 1.9393e-5;       ///< rad/s^2/sqrt(Hz)
  double accelerometer_noise_density = 2.0e-3;    ///< m/s^2/sqrt(Hz)
  double accelerometer_random_walk = 3.0e-3;      ///< m/s^3/sqrt(Hz)
  double rate_hz = 200.0;                         ///< nominal sample rate
  // The defaults are the EuRoC VI-sensor (ADIS16448) values of `mav0/imu0/sensor.yaml`.
};

}  // namespace gvins::vio
