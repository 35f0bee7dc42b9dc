// A trajectory from a GNSS reference track (positions of the antenna, e.g. an RTK solution in
// RTKLIB's .pos layout) and a real IMU log of the same rig, for a rig that has no attitude truth
// (a hand-held walk): gvins-sim drives its cameras along it and keeps the real IMU samples.
//
// Attitude. The orientation is the real gyro integrated from an initial attitude R0 with a gyro
// bias (constant, or piecewise linear in time), so the cameras turn exactly as the real gyro
// says up to that bias. R0, the gyro bias and a constant accelerometer bias b_a are the least-
// squares fit of the velocity increments: over windows [T, T + w] starting at each track epoch,
//     sum R_k (f_k - b_a) dt_k - g e_z w  =  v_ant(T + w) - v_ant(T) - (lever-arm rate terms),
// with v_ant the derivative of a smoothing spline of the track. Roll and pitch come from
// gravity, the yaw from the horizontal accelerations of the walk (the track's turns), so no
// assumption about the heading of the rig relative to the path is made. The yaw start value
// is the best of a 10-degree grid (Gauss-Newton from there).
//
// Position. A penalised septic B-spline of the IMU position fitted to both the track (the
// antenna minus R l, weighted by the .pos standard deviations, at least `trackSigmaFloor`) and
// to the IMU's accelerations R_k (f_k - b_a) - g e_z (weight 1 / accelSigma² per sample): the
// track fixes the low frequencies, the real accelerometer the high ones (steps, hand motion)
// that a 4 Hz track cannot hold, so the cameras move as the real IMU felt. W is the local ENU
// frame of `frame` with flat gravity g e_z (docs/dataset_format.md).
//
// Times: the track's GPST epochs and the IMU's stamps (GPST ns, e.g. written by gvins-imu from
// the RTKLIB time tags) are taken on one clock; flight time 0 is frame.startTime.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "gvins/gnss/position_solution.hpp"
#include "gvins/sim/local_frame.hpp"
#include "gvins/sim/recorded_trajectory.hpp"
#include "gvins/vio/euroc_csv.hpp"
#include "gvins/vio/imu_sample.hpp"

namespace gvins::sim {

struct TrackTrajectoryConfig {
  std::string posFile;             ///< reference track of the antenna (.pos, GPST)
  std::string imuCsv;              ///< the real IMU in imu0/data.csv form (GPST ns, rad/s, m/s²)
  int maxQuality = 2;              ///< track epochs of quality <= this are used (1 fixed, 2 float)
  double duration = 0.0;           ///< s after the start, 0 = to the end of the track or the IMU
  double attitudeWindow = 1.0;     ///< s, velocity-increment window of the attitude fit
  double gyroBiasInterval = 0.0;   ///< s between nodes of a piecewise-linear gyro bias, 0 = constant
  double knotInterval = 0.04;      ///< s, knots of the position spline
  double accelSigma = 0.5;         ///< m/s², per IMU sample in the position fit
  double trackSigmaFloor = 0.01;   ///< m, smallest standard deviation given to a track position
  double smoothing = 1.0;          ///< weight of the squared third differences of the controls
  std::string roverLog;            ///< the real rover's observations (RINEX or UBX), copied into gnss/
  std::string navigationFile;      ///< optional real navigation file, copied into gnss/
};

/// What the fit found (dataset.yaml repeats it).
struct TrackFitReport {
  std::size_t trackEpochs = 0;          ///< track epochs used
  std::size_t imuSamples = 0;           ///< IMU samples inside the span
  Eigen::Vector3d gyroBias = Eigen::Vector3d::Zero();   ///< rad/s (mean over the span)
  Eigen::Vector3d accelBias = Eigen::Vector3d::Zero();  ///< m/s²
  double initialYawDeg = 0.0;           ///< yaw of the body x axis at t = 0 (ENU: from east, counter-clockwise), deg
  double velocityResidualRms = 0.0;     ///< m/s, velocity increments of the attitude fit (per axis)
  double trackResidualRms = 0.0;        ///< m, fitted antenna against the track epochs used (3-D)
  double trackResidualMax = 0.0;        ///< m
  double accelResidualRms = 0.0;        ///< m/s², spline acceleration against the rotated IMU (per axis)
  Eigen::Vector3d forwardAxis = Eigen::Vector3d::UnitX();  ///< mean direction of travel in B while faster than 0.5 m/s
};

struct TrackImuFit {
  std::vector<vio::ImuSample> imu;            ///< real samples covering [0, duration] (GPST ns)
  std::vector<vio::GroundTruthSample> truth;  ///< the fitted IMU state every 5 ms from t = 0
  TrackFitReport report;
};

/// Fits from data in memory: the track (ECEF antenna positions, GPST) and the IMU samples
/// (GPST ns). `leverArm` is the antenna in B, `gravity` the magnitude of flat gravity in W.
/// Throws std::invalid_argument when the data do not cover the span or too few epochs remain.
TrackImuFit fitTrackImu(const std::vector<PositionSolution>& track, const std::vector<vio::ImuSample>& imu,
                        const TrackTrajectoryConfig& config, const LocalFrame& frame, const Eigen::Vector3d& leverArm,
                        double gravity);

/// The recorded-trajectory view of a fit (the spline of RecordedTrajectory through the fitted
/// states, the real IMU kept) together with the fit's report.
class TrackTrajectory : public RecordedTrajectory {
 public:
  /// Reads config.posFile and config.imuCsv (gvins::ParseError on malformed files) and fits.
  TrackTrajectory(const TrackTrajectoryConfig& config, const LocalFrame& frame, const Eigen::Vector3d& leverArm,
                  double gravity);
  TrackTrajectory(const TrackImuFit& fit, double duration);
  const TrackFitReport& report() const { return report_; }

 private:
  TrackFitReport report_;
};

}  // namespace gvins::sim
