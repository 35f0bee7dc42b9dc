// Parameterised flights and drives: a survey lawnmower, circles, a figure-eight, waypoints
// (multirotor, with vertical take-off and landing at the home point, the origin of W) and a
// ground-vehicle drive around rounded blocks with stops. Each is a Route (route.hpp) timed
// under acceleration limits and smoothed into a C^6 SplineTrajectory.
//
// Geometry (W = ENU, ground plane z = 0, home = (0, 0)):
//   lawnmower:    `rows` parallel rows `rowSpacing` apart joined by semicircular turns of
//                 radius rowSpacing/2, first row along `headingDeg`, then straight back home;
//                 the row length is solved so that the horizontal path is `length` long.
//   circle:       `laps` laps of a circle through home, tangent to `headingDeg`; radius
//                 length / (2 pi laps).
//   figure_eight: `laps` laps of the lemniscate of Gerono f = A sin(u), r = (A/2) sin(2u)
//                 (forward/right of the heading), crossing at home; A from the length.
//   waypoints:    straight legs through `waypoints` (x east, y north, z up, m), then home.
//   drive:        a ground vehicle at `restHeight` on laps around a rounded rectangle (2:1,
//                 corner radius `cornerRadius`) with a stop of `stopSeconds` after each lap
//                 and, when `cornerStopSeconds` > 0, before every corner (traffic lights).
//   walk:         the same route walked with a hand-held rig at `restHeight` (hand height),
//                 with the gait oscillation of `gait` (gait.hpp) added to the motion.
// `length` is the horizontal path length (climb and descent excluded).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "gvins/sim/gait.hpp"
#include "gvins/sim/route.hpp"
#include "gvins/sim/spline_trajectory.hpp"

namespace gvins::sim {

enum class FlightPattern { Lawnmower, Circle, FigureEight, Waypoints, Drive, Walk };
enum class YawMode { FollowPath, Fixed };

/// "lawnmower", "circle", "figure_eight", "waypoints", "drive", "walk".
const char* toString(FlightPattern p);
bool flightPatternFromString(const std::string& s, FlightPattern& out);

struct FlightSpec {
  FlightPattern pattern = FlightPattern::Lawnmower;
  double height = 40.0;     ///< m above the ground (z of the IMU while cruising)
  double length = 1000.0;   ///< m, horizontal path length
  double speed = 8.0;       ///< m/s, cruise speed
  double climbRate = 2.5;   ///< m/s, take-off and landing
  double headingDeg = 0.0;  ///< azimuth of the first leg, degrees clockwise from north
  int rows = 4;             ///< lawnmower
  double rowSpacing = 40.0; ///< lawnmower, m
  bool turnRight = true;    ///< lawnmower/circle/figure-eight: first turn to the right
  int laps = 2;             ///< circle, figure-eight, drive
  std::vector<Eigen::Vector3d> waypoints;  ///< waypoints pattern
  double cornerRadius = 12.0;  ///< drive, m
  double stopSeconds = 3.0;    ///< drive: stop after each lap
  double cornerStopSeconds = 0.0;  ///< drive, walk: stop before every corner (0: none)
  GaitConfig gait;             ///< walk
  double restHeight = 0.3;     ///< m, IMU height above the ground at rest (drive: while driving)
  bool takeoffLanding = true;  ///< false: start and end hovering at `height` above home
  double hoverStart = 5.0;     ///< s at rest before moving (>= 2)
  double hoverEnd = 3.0;       ///< s at rest at the end (>= 2)
  MotionLimits limits;
  YawMode yaw = YawMode::FollowPath;
  double fixedYawDeg = 0.0;    ///< YawMode::Fixed: body x azimuth, degrees clockwise from north
  double knotInterval = 0.2;   ///< s, position spline knot spacing
  double yawKnotInterval = 0.5;  ///< s, heading spline knot spacing
  double wobbleDeg = 0.0;      ///< 1-sigma attitude jitter (deg), 0 = none
  double wobbleInterval = 0.5; ///< s, knot spacing of the jitter
  double gravity = 9.81;       ///< m/s^2, for the thrust direction
  AttitudeConfig vehicleAttitude;  ///< ground-vehicle roll/pitch gains (drive)

  /// Throws std::invalid_argument naming the first out-of-range value.
  void validate() const;
};

/// The route of a flight (before timing).
Route buildRoute(const FlightSpec& spec);

/// The trajectory of a flight; `seed` drives only the wobble.
std::unique_ptr<SplineTrajectory> buildFlight(const FlightSpec& spec, std::uint64_t seed);

/// Smooths timed route samples into a trajectory (used by buildFlight; public for custom routes).
std::unique_ptr<SplineTrajectory> trajectoryFromSamples(const RouteSamples& samples, double yawKnotInterval,
                                                        AttitudeConfig attitude);

}  // namespace gvins::sim
