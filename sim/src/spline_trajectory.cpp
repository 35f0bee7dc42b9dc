#include "gvins/sim/spline_trajectory.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "time_jet.hpp"

namespace gvins::sim {

using detail::Jet;
using detail::Jet3;
using detail::JetMat3;

SplineTrajectory::SplineTrajectory(UniformBSpline<3> position, UniformBSpline<1> yaw, AttitudeConfig attitude,
                                   double duration)
    : position_(std::move(position)), yaw_(std::move(yaw)), attitude_(std::move(attitude)), duration_(duration) {
  if (!(duration > 0.0) || !std::isfinite(duration))
    throw std::invalid_argument("SplineTrajectory: duration must be positive");
  if (!(attitude_.gravity > 0.0)) throw std::invalid_argument("SplineTrajectory: gravity must be positive");
}

TrajectoryState SplineTrajectory::evaluate(double tIn) const {
  const double t = std::clamp(tIn, 0.0, duration_);
  Eigen::Vector3d p[5];
  position_.evaluate(t, 4, p);
  Eigen::Matrix<double, 1, 1> y[3];
  yaw_.evaluate(t, 2, y);

  TrajectoryState s;
  s.t = t;
  s.p_WB = p[0];
  s.v_WB = p[1];
  s.a_WB = p[2];

  // Acceleration with its first two derivatives (jerk, snap) and the heading jet.
  Jet3 acc;
  acc.v = p[2];
  acc.d1 = p[3];
  acc.d2 = p[4];
  const Jet psi(y[0](0), y[1](0), y[2](0));

  JetMat3 R;
  if (attitude_.model == AttitudeModel::Multirotor) {
    Jet3 thrust = acc;
    thrust.v.z() += attitude_.gravity;
    const Jet3 zb = detail::normalized(thrust);
    const Jet3 xc = Jet3::from(detail::cos(psi), detail::sin(psi), Jet(0.0));
    const Jet3 yb = detail::normalized(detail::cross(zb, xc));
    const Jet3 xb = detail::cross(yb, zb);
    R = JetMat3::fromColumns(xb, yb, zb);
  } else {
    const Jet c = detail::cos(psi), sn = detail::sin(psi);
    const Jet aLon = acc[0] * c + acc[1] * sn;
    const Jet aLat = acc[1] * c - acc[0] * sn;
    // Nose up when accelerating (negative pitch about the left axis), roll outwards in turns.
    const Jet pitch = -attitude_.pitchPerLongitudinalAccel * aLon;
    const Jet roll = attitude_.rollPerLateralAccel * aLat;
    R = detail::rotZ(psi) * detail::rotY(pitch) * detail::rotX(roll);
  }
  if (attitude_.wobble) {
    Eigen::Vector3d w[3];
    attitude_.wobble->evaluate(t, 2, w);
    const Jet r(w[0].x(), w[1].x(), w[2].x()), pi(w[0].y(), w[1].y(), w[2].y()), ya(w[0].z(), w[1].z(), w[2].z());
    R = R * (detail::rotZ(ya) * detail::rotY(pi) * detail::rotX(r));
  }
  s.R_WB = R.v;
  detail::angularRates(R, s.omega_B, s.alpha_B);
  return s;
}

}  // namespace gvins::sim
