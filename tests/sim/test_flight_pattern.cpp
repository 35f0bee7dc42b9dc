// Flights and drives: geometry against the requested height/length/speed, rest at the ends,
// multirotor attitude along the specific force, ground-vehicle attitude, and the trajectory's
// derivatives (velocity, acceleration, angular velocity and acceleration) against finite
// differences of its own position and orientation.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "gvins/sim/flight_pattern.hpp"
#include "gvins/vio/so3.hpp"

namespace gvins::sim {
namespace {

using V3 = Eigen::Vector3d;

struct Stats {
  double hLength = 0, maxSpeed = 0, maxHeight = -1e9, maxAccel = 0, maxRate = 0, maxTilt = 0;
};

Stats measure(const Trajectory& tr, double step = 0.01) {
  Stats s;
  V3 prev = tr.position(0.0);
  for (double t = step; t <= tr.duration(); t += step) {
    const TrajectoryState x = tr.evaluate(t);
    s.hLength += (x.p_WB - prev).head<2>().norm();
    prev = x.p_WB;
    s.maxSpeed = std::max(s.maxSpeed, x.v_WB.head<2>().norm());
    s.maxHeight = std::max(s.maxHeight, x.p_WB.z());
    s.maxAccel = std::max(s.maxAccel, x.a_WB.norm());
    s.maxRate = std::max(s.maxRate, x.omega_B.norm());
    s.maxTilt = std::max(s.maxTilt, std::acos(std::clamp(x.R_WB(2, 2), -1.0, 1.0)));
  }
  return s;
}

void expectDerivativesConsistent(const Trajectory& tr) {
  const double h = 1e-4;
  for (double t = 0.37; t < tr.duration() - 0.1; t += tr.duration() / 97.0) {
    const TrajectoryState a = tr.evaluate(t - h), b = tr.evaluate(t), c = tr.evaluate(t + h);
    EXPECT_LT(((c.p_WB - a.p_WB) / (2 * h) - b.v_WB).norm(), 1e-6) << t;
    EXPECT_LT(((c.v_WB - a.v_WB) / (2 * h) - b.a_WB).norm(), 1e-6) << t;
    // omega_B: R(t+h) = R(t) Exp(omega h + alpha h^2/2 + ...), central difference of the logs.
    const V3 wFd = (vio::so3::log(b.R_WB.transpose() * c.R_WB) - vio::so3::log(b.R_WB.transpose() * a.R_WB)) / (2 * h);
    EXPECT_LT((wFd - b.omega_B).norm(), 1e-7) << t;
    EXPECT_LT(((c.omega_B - a.omega_B) / (2 * h) - b.alpha_B).norm(), 1e-5) << t;
    EXPECT_NEAR((b.R_WB.transpose() * b.R_WB - Eigen::Matrix3d::Identity()).norm(), 0.0, 1e-12);
  }
}

TEST(FlightPattern, LawnmowerMatchesHeightLengthSpeed) {
  FlightSpec spec;
  spec.height = 60.0;
  spec.length = 1000.0;
  spec.speed = 8.0;
  const auto tr = buildFlight(spec, 1);
  const Stats s = measure(*tr);
  // The smoothing rounds corners: the horizontal length is within 2 % of the request.
  EXPECT_NEAR(s.hLength, 1000.0, 20.0);
  EXPECT_NEAR(s.maxHeight, 60.0, 0.05);
  EXPECT_NEAR(s.maxSpeed, 8.0, 0.1);
  EXPECT_LT(s.maxAccel, 4.0);
  EXPECT_LT(s.maxTilt, 25.0 * std::numbers::pi / 180);
  // At rest on the ground, level, at both ends.
  for (double t : {0.0, 1.0, tr->duration() - 0.5, tr->duration()}) {
    const TrajectoryState x = tr->evaluate(t);
    EXPECT_LT(x.v_WB.norm(), 1e-12) << t;
    EXPECT_LT(x.omega_B.norm(), 1e-12) << t;
    EXPECT_NEAR(x.p_WB.z(), spec.restHeight, 1e-9);
    EXPECT_NEAR(x.R_WB(2, 2), 1.0, 1e-12);
  }
  EXPECT_LT(tr->position(tr->duration()).head<2>().norm(), 1e-9);  // lands at home
  expectDerivativesConsistent(*tr);
}

TEST(FlightPattern, MultirotorThrustAxisAlongSpecificForce) {
  FlightSpec spec;
  spec.pattern = FlightPattern::FigureEight;
  spec.length = 800.0;
  spec.speed = 10.0;
  spec.height = 30.0;
  spec.gravity = 9.79;
  const auto tr = buildFlight(spec, 2);
  for (double t = 0.0; t < tr->duration(); t += 0.77) {
    const TrajectoryState x = tr->evaluate(t);
    const V3 f = (x.a_WB + V3(0, 0, 9.79)).normalized();
    EXPECT_LT((x.R_WB.col(2) - f).norm(), 1e-12) << t;
    // Body x lies in the plane of the thrust axis and the heading direction x_c: y_B is
    // perpendicular to x_c = (cos psi, sin psi, 0).
    const double psi = tr->yawSpline().value(t)(0);
    EXPECT_NEAR(x.R_WB.col(1).dot(V3(std::cos(psi), std::sin(psi), 0.0)), 0.0, 1e-12);
  }
  expectDerivativesConsistent(*tr);
}

TEST(FlightPattern, CircleRadiusAndYawFollowsPath) {
  FlightSpec spec;
  spec.pattern = FlightPattern::Circle;
  spec.length = 2.0 * std::numbers::pi * 100.0 * 2;  // two laps of 100 m
  spec.laps = 2;
  spec.speed = 6.0;
  spec.headingDeg = 90.0;  // first leg east
  spec.takeoffLanding = false;
  spec.height = 50.0;
  const auto tr = buildFlight(spec, 3);
  // Centre to the right of an eastward start: (0, -100).
  const V3 centre(0, -100, 50);
  for (double t = 40.0; t < tr->duration() - 40.0; t += 1.3) {
    const TrajectoryState x = tr->evaluate(t);
    EXPECT_NEAR((x.p_WB - centre).norm(), 100.0, 0.05) << t;
    EXPECT_NEAR(x.v_WB.norm(), 6.0, 0.01);
    // Heading along the velocity (yaw spline lags a little behind a 0.06 rad/s turn).
    const V3 fwd = x.R_WB.col(0);
    EXPECT_LT(std::acos(fwd.head<2>().normalized().dot(x.v_WB.head<2>().normalized())), 0.05);
  }
  expectDerivativesConsistent(*tr);
}

TEST(FlightPattern, DriveIsAGroundVehicle) {
  FlightSpec spec;
  spec.pattern = FlightPattern::Drive;
  spec.length = 1200.0;
  spec.laps = 2;
  spec.speed = 10.0;
  spec.restHeight = 1.2;
  spec.height = 2.0;
  const auto tr = buildFlight(spec, 4);
  const Stats s = measure(*tr);
  EXPECT_NEAR(s.hLength, 1200.0, 25.0);
  EXPECT_NEAR(s.maxHeight, 1.2, 1e-9);
  EXPECT_NEAR(s.maxSpeed, 10.0, 0.1);
  // Roll and pitch are the suspension angles: 0.0087 rad per m/s^2.
  for (double t = 0.0; t < tr->duration(); t += 0.5) {
    const TrajectoryState x = tr->evaluate(t);
    EXPECT_NEAR(x.v_WB.z(), 0.0, 1e-12);
    const double psi = tr->yawSpline().value(t)(0);
    const double aLon = x.a_WB.x() * std::cos(psi) + x.a_WB.y() * std::sin(psi);
    const double aLat = -x.a_WB.x() * std::sin(psi) + x.a_WB.y() * std::cos(psi);
    const double pitch = -std::asin(std::clamp(x.R_WB(2, 0), -1.0, 1.0));
    const double roll = std::atan2(x.R_WB(2, 1), x.R_WB(2, 2));
    EXPECT_NEAR(pitch, -0.0087 * aLon, 1e-12);
    EXPECT_NEAR(roll, 0.0087 * aLat, 1e-12);
  }
  // Stops between laps: somewhere in the middle the car is at rest.
  double minMidSpeed = 1e9;
  for (double t = 0.3 * tr->duration(); t < 0.7 * tr->duration(); t += 0.05)
    minMidSpeed = std::min(minMidSpeed, tr->velocity(t).norm());
  EXPECT_LT(minMidSpeed, 1e-9);
  expectDerivativesConsistent(*tr);
}

TEST(FlightPattern, WobbleKeepsRestAndDerivatives) {
  FlightSpec spec;
  spec.length = 400.0;
  spec.rows = 2;
  spec.wobbleDeg = 1.0;
  const auto tr = buildFlight(spec, 5);
  EXPECT_LT(tr->evaluate(0.5).omega_B.norm(), 1e-15);
  const Stats s = measure(*tr);
  EXPECT_GT(s.maxRate, 0.05);  // the jitter shows in the rates
  expectDerivativesConsistent(*tr);
  // Same seed, same wobble; another seed, another one.
  const auto same = buildFlight(spec, 5), other = buildFlight(spec, 6);
  EXPECT_EQ((same->orientation(30.0) - tr->orientation(30.0)).norm(), 0.0);
  EXPECT_GT((other->orientation(30.0) - tr->orientation(30.0)).norm(), 1e-4);
}

TEST(FlightPattern, ShortLengthsAndBadValuesAreRejected) {
  FlightSpec spec;
  spec.length = 100.0;  // four rows 40 m apart need more
  EXPECT_THROW(buildFlight(spec, 1), std::invalid_argument);
  spec = FlightSpec{};
  spec.speed = -1.0;
  EXPECT_THROW(spec.validate(), std::invalid_argument);
  spec = FlightSpec{};
  spec.restHeight = 50.0;
  EXPECT_THROW(spec.validate(), std::invalid_argument);
  spec = FlightSpec{};
  spec.pattern = FlightPattern::Waypoints;
  EXPECT_THROW(spec.validate(), std::invalid_argument);
}

TEST(FlightPattern, WaypointsVisitsEveryWaypoint) {
  FlightSpec spec;
  spec.pattern = FlightPattern::Waypoints;
  spec.height = 30.0;
  spec.waypoints = {V3(100, 0, 30), V3(100, 80, 40), V3(-50, 60, 40)};
  const auto tr = buildFlight(spec, 7);
  for (const V3& w : spec.waypoints) {
    double best = 1e9;
    for (double t = 0; t < tr->duration(); t += 0.05) best = std::min(best, (tr->position(t) - w).norm());
    EXPECT_LT(best, 0.5);  // corners are taken slowly, the smoothing cuts them by centimetres
  }
}

}  // namespace
}  // namespace gvins::sim
