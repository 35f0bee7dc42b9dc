// A trajectory from a septic B-spline position curve and a heading curve, with the attitude of
// a multirotor (thrust axis along the specific force, heading from the yaw curve; Mellinger &
// Kumar, "Minimum snap trajectory generation and control for quadrotors", ICRA 2011, sec. III:
// z_B = (a + g e_z)/|a + g e_z|, x_B in the plane of z_B and the heading) or of a ground
// vehicle (heading from the yaw curve, body roll and pitch proportional to the lateral and
// longitudinal acceleration, as a car on its suspension). An optional small smooth attitude
// perturbation ("wobble", a B-spline of random angles) mimics the attitude-control jitter of a
// real vehicle.
//
// Position is C^6, orientation C^4; angular velocity and acceleration are exact (second-order
// forward differentiation in time of the attitude construction, time_jet.hpp), so the IMU
// signals derived from this trajectory are the exact derivatives of its truth.
#pragma once

#include <optional>

#include "gvins/sim/trajectory.hpp"
#include "gvins/sim/uniform_bspline.hpp"

namespace gvins::sim {

enum class AttitudeModel { Multirotor, GroundVehicle };

struct AttitudeConfig {
  AttitudeModel model = AttitudeModel::Multirotor;
  /// Gravity magnitude (m/s^2) used to point the multirotor's thrust axis.
  double gravity = 9.81;
  /// Ground vehicle: body roll per lateral acceleration and pitch per longitudinal acceleration
  /// (rad per m/s^2); ~0.5 deg per m/s^2 for a passenger car.
  double rollPerLateralAccel = 0.0087;
  double pitchPerLongitudinalAccel = 0.0087;
  /// Optional perturbation angles (roll, pitch, yaw) in rad applied in the body frame:
  /// R = R_nominal Rz(yaw) Ry(pitch) Rx(roll).
  std::optional<UniformBSpline<3>> wobble;
};

class SplineTrajectory : public Trajectory {
 public:
  /// `position` of the IMU in W, `yaw` heading in rad (counter-clockwise from east, W's x axis),
  /// motion defined on [0, duration]. Throws std::invalid_argument for duration <= 0.
  SplineTrajectory(UniformBSpline<3> position, UniformBSpline<1> yaw, AttitudeConfig attitude, double duration);

  double duration() const override { return duration_; }
  TrajectoryState evaluate(double t) const override;

  const UniformBSpline<3>& positionSpline() const { return position_; }
  const UniformBSpline<1>& yawSpline() const { return yaw_; }
  const AttitudeConfig& attitudeConfig() const { return attitude_; }

 private:
  UniformBSpline<3> position_;
  UniformBSpline<1> yaw_;
  AttitudeConfig attitude_;
  double duration_;
};

}  // namespace gvins::sim
