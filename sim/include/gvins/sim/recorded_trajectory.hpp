// A trajectory driven by a real recording: the real IMU log (kept sample for sample, with its
// real noise and biases) and the real ground truth, smoothed by a penalised least-squares
// septic B-spline (a P-spline: Eilers & Marx, "Flexible smoothing with B-splines and
// penalties", Statistical Science 1996) so that velocity, acceleration, angular velocity and
// angular acceleration exist. The orientation is a B-spline of the (sign-continuous)
// quaternion components, normalised, differentiated exactly.
//
// Input: EuRoC/ASL files (imu0 data.csv and state_groundtruth_estimate0 data.csv, read with
// vio's readers: every malformed line is a gvins::ParseError). The ground-truth body frame must
// be the IMU frame (true for EuRoC). The recording's world frame is taken as W (it must be
// gravity-aligned, z up, as EuRoC's Vicon frame is); flight time 0 is the first ground-truth
// stamp plus `startOffset`.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "gvins/sim/trajectory.hpp"
#include "gvins/sim/uniform_bspline.hpp"
#include "gvins/vio/euroc_csv.hpp"
#include "gvins/vio/imu_sample.hpp"

namespace gvins::sim {

struct RecordedTrajectoryConfig {
  std::string imuCsv;          ///< e.g. .../v102_imu_groundtruth/imu0.csv
  std::string groundTruthCsv;  ///< e.g. .../state_groundtruth_estimate0.csv (17 columns)
  double startOffset = 0.0;    ///< s after the first ground-truth stamp
  double duration = 0.0;       ///< s, 0 = to the end of the ground truth
  double knotInterval = 0.04;  ///< s, spline knot spacing
  double smoothing = 1.0;      ///< weight of the squared third differences of the controls
};

class RecordedTrajectory : public Trajectory {
 public:
  /// Reads and fits. Throws gvins::ParseError for malformed files and std::invalid_argument
  /// when the ground truth does not cover the requested span or lacks velocity/bias columns.
  explicit RecordedTrajectory(const RecordedTrajectoryConfig& config);
  /// From samples already in memory (stamps in the recording's ns).
  RecordedTrajectory(const std::vector<vio::ImuSample>& imu, const std::vector<vio::GroundTruthSample>& truth,
                     const RecordedTrajectoryConfig& config);

  double duration() const override { return duration_; }
  TrajectoryState evaluate(double t) const override;

  /// Recording stamp (ns) of flight time 0.
  std::int64_t startStamp() const { return start_ns_; }
  /// Real IMU samples inside the flight (stamps still in the recording's ns), starting at or
  /// before t = 0 and ending at or after t = duration when the log allows.
  const std::vector<vio::ImuSample>& imuSamples() const { return imu_; }
  /// Ground-truth biases (gyro, accel) interpolated at flight time t.
  void biases(double t, Eigen::Vector3d& bg, Eigen::Vector3d& ba) const;
  /// RMS and maximum of the fit residuals at the ground-truth samples (m, rad).
  double positionRms() const { return posRms_; }
  double positionMax() const { return posMax_; }
  double rotationRms() const { return rotRms_; }

 private:
  void fit(const std::vector<vio::GroundTruthSample>& truth, const RecordedTrajectoryConfig& config);
  UniformBSpline<3> pos_;
  UniformBSpline<4> quat_;
  std::vector<vio::ImuSample> imu_;
  std::vector<double> biasT_;
  std::vector<Eigen::Vector3d> biasG_, biasA_;
  std::int64_t start_ns_ = 0;
  double duration_ = 0.0;
  double posRms_ = 0.0, posMax_ = 0.0, rotRms_ = 0.0;
};

}  // namespace gvins::sim
