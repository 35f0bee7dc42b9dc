// A route: the geometric path of a flight or drive as a dense polyline with a cruise speed per
// segment and stops, and its time parameterisation under acceleration limits. The samples it
// produces at a fixed time step are the control points of the smooth trajectory
// (flight_pattern.hpp builds routes for survey patterns and turns them into trajectories).
//
// Speed profile: the classic two-pass limit (forward: v_i^2 <= v_{i-1}^2 + 2 a_lon ds, backward
// likewise) under the point limits min(cruise, sqrt(a_lat / kappa)), kappa the curvature of the
// circle through three consecutive points; at rest at both ends and at every stop.
#pragma once

#include <functional>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace gvins::sim {

struct RoutePoint {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  double speed = 0.0;  ///< cruise speed (m/s) of the segment that ends here
  double dwell = 0.0;  ///< seconds at rest at this point (0: pass through)
};

class Route {
 public:
  /// A route starting at `start`; segments are subdivided so that points are at most
  /// `maxSpacing` metres apart.
  explicit Route(const Eigen::Vector3d& start, double maxSpacing = 0.5);

  /// Straight segment to p at the given cruise speed.
  void lineTo(const Eigen::Vector3d& p, double speed);
  /// Horizontal arc around `centre` (z of the current point kept) by `angle` radians
  /// (positive: counter-clockwise seen from above).
  void arcAround(const Eigen::Vector2d& centre, double angle, double speed);
  /// A parametric curve f(u), u in [u0, u1] (f(u0) should be the current point), sampled at
  /// `samples` + 1 points.
  void curve(const std::function<Eigen::Vector3d(double)>& f, double u0, double u1, int samples, double speed);
  /// Come to rest at the current point and stay there for `seconds`.
  void stop(double seconds);

  const std::vector<RoutePoint>& points() const { return pts_; }
  const Eigen::Vector3d& current() const { return pts_.back().p; }
  /// Total length (m) and horizontal length (m).
  double length() const;
  double horizontalLength() const;

 private:
  std::vector<RoutePoint> pts_;
  double maxSpacing_;
};

struct MotionLimits {
  double lateralAccel = 2.5;       ///< m/s^2, centripetal limit in turns
  double longitudinalAccel = 1.5;  ///< m/s^2, along the path (also vertical)
};

/// Samples of a timed route at a fixed time step.
struct RouteSamples {
  double dt = 0.2;
  std::vector<Eigen::Vector3d> position;  ///< positions at k dt
  std::vector<double> heading;            ///< rad, counter-clockwise from x (unwrapped)
  double duration() const { return position.empty() ? 0.0 : dt * static_cast<double>(position.size() - 1); }
};

/// Time-parameterises the route (at rest `hoverStart` s before and `hoverEnd` s after) and
/// samples it every dt. The heading is that of the horizontal direction of travel; on vertical
/// or stationary parts it holds the next (before the first horizontal motion) or the previous
/// heading. Throws std::invalid_argument for a route with fewer than 2 points, non-positive
/// speeds or limits.
RouteSamples sampleRoute(const Route& route, const MotionLimits& limits, double dt, double hoverStart,
                         double hoverEnd);

}  // namespace gvins::sim
