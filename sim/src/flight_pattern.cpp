#include "gvins/sim/flight_pattern.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "gvins/sim/random.hpp"

namespace gvins::sim {
namespace {

constexpr double kPi = std::numbers::pi;

void require(bool ok, const char* what) {
  if (!ok) throw std::invalid_argument(std::string("FlightSpec: ") + what);
}

/// Solves f(x) = target for increasing f on [lo, hi] by bisection.
template <class F>
double bisect(F f, double target, double lo, double hi) {
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (f(mid) < target ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace

const char* toString(FlightPattern p) {
  switch (p) {
    case FlightPattern::Lawnmower: return "lawnmower";
    case FlightPattern::Circle: return "circle";
    case FlightPattern::FigureEight: return "figure_eight";
    case FlightPattern::Waypoints: return "waypoints";
    case FlightPattern::Drive: return "drive";
    case FlightPattern::Walk: return "walk";
  }
  return "?";
}

bool flightPatternFromString(const std::string& s, FlightPattern& out) {
  for (FlightPattern p : {FlightPattern::Lawnmower, FlightPattern::Circle, FlightPattern::FigureEight,
                          FlightPattern::Waypoints, FlightPattern::Drive, FlightPattern::Walk})
    if (s == toString(p)) {
      out = p;
      return true;
    }
  return false;
}

void FlightSpec::validate() const {
  require(std::isfinite(height) && height > 0.0 && height <= 10000.0, "height must be in (0, 10000] m");
  require(std::isfinite(length) && length > 0.0 && length <= 1e6, "length must be in (0, 1000 km]");
  require(std::isfinite(speed) && speed > 0.0 && speed <= 100.0, "speed must be in (0, 100] m/s");
  require(std::isfinite(climbRate) && climbRate > 0.0 && climbRate <= 20.0, "climb_rate must be in (0, 20] m/s");
  require(std::isfinite(headingDeg) && std::isfinite(fixedYawDeg), "heading/yaw must be finite");
  require(rows >= 1 && rows <= 1000, "rows must be in [1, 1000]");
  require(std::isfinite(rowSpacing) && rowSpacing > 0.0 && rowSpacing <= 10000.0, "row_spacing must be positive");
  require(laps >= 1 && laps <= 1000, "laps must be in [1, 1000]");
  require(std::isfinite(cornerRadius) && cornerRadius > 0.0, "corner_radius must be positive");
  require(std::isfinite(stopSeconds) && stopSeconds >= 0.0 && stopSeconds <= 3600.0, "stop_seconds out of range");
  require(std::isfinite(cornerStopSeconds) && cornerStopSeconds >= 0.0 && cornerStopSeconds <= 3600.0,
          "corner_stop_seconds out of range");
  if (pattern == FlightPattern::Walk) {
    gait.validate();
    // The gait (about speed / stepLength Hz) needs several spline knots per period.
    require(knotInterval <= gait.stepLength / speed / 8.0, "walk: knot_interval must be <= step length / speed / 8");
  }
  require(std::isfinite(restHeight) && restHeight >= 0.0 && restHeight < height, "rest_height must be in [0, height)");
  require(std::isfinite(hoverStart) && hoverStart >= 2.0 && hoverStart <= 3600.0, "hover_start must be in [2, 3600] s");
  require(std::isfinite(hoverEnd) && hoverEnd >= 2.0 && hoverEnd <= 3600.0, "hover_end must be in [2, 3600] s");
  require(std::isfinite(limits.lateralAccel) && limits.lateralAccel > 0.05 && limits.lateralAccel <= 50.0,
          "lateral_accel must be in (0.05, 50] m/s^2");
  require(std::isfinite(limits.longitudinalAccel) && limits.longitudinalAccel > 0.05 && limits.longitudinalAccel <= 50.0,
          "longitudinal_accel must be in (0.05, 50] m/s^2");
  require(std::isfinite(knotInterval) && knotInterval >= 0.01 && knotInterval <= 5.0, "knot_interval must be in [0.01, 5] s");
  require(std::isfinite(yawKnotInterval) && yawKnotInterval >= 0.01 && yawKnotInterval <= 10.0,
          "yaw_knot_interval must be in [0.01, 10] s");
  require(std::isfinite(wobbleDeg) && wobbleDeg >= 0.0 && wobbleDeg <= 10.0, "wobble must be in [0, 10] deg");
  require(std::isfinite(wobbleInterval) && wobbleInterval >= 0.05 && wobbleInterval <= 10.0,
          "wobble_interval must be in [0.05, 10] s");
  require(std::isfinite(gravity) && gravity > 1.0 && gravity < 30.0, "gravity out of range");
  if (pattern == FlightPattern::Waypoints) {
    require(!waypoints.empty(), "the waypoints pattern needs at least one waypoint");
    for (const auto& w : waypoints) require(w.allFinite() && w.z() > restHeight, "waypoints must be finite and above rest height");
  }
  // Rough duration cap (a day) so that nobody asks for billions of samples by accident.
  require(length / speed < 86400.0, "flight longer than a day");
}

Route buildRoute(const FlightSpec& s) {
  s.validate();
  const double th = kPi / 2.0 - s.headingDeg * kPi / 180.0;  // CCW from east
  const Eigen::Vector2d fwd(std::cos(th), std::sin(th));
  const Eigen::Vector2d right(fwd.y(), -fwd.x());
  const Eigen::Vector2d side = s.turnRight ? right : Eigen::Vector2d(-right);
  const double turnSign = s.turnRight ? -1.0 : 1.0;  // CCW-positive angle of a turn towards `side`
  auto at = [](const Eigen::Vector2d& xy, double z) { return Eigen::Vector3d(xy.x(), xy.y(), z); };

  if (s.pattern == FlightPattern::Drive || s.pattern == FlightPattern::Walk) {
    const double r = s.cornerRadius;
    // Perimeter of a rounded 2H x H rectangle: 6H - (8 - 2 pi) r.
    const double perLap = s.length / s.laps;
    const double H = (perLap + (8.0 - 2.0 * kPi) * r) / 6.0;
    if (!(H > 2.0 * r + 1.0))
      throw std::invalid_argument("FlightSpec: drive length too short for the corner radius");
    const double W = 2.0 * H;
    const double z = s.restHeight;
    auto P = [&](double f, double sd) { return Eigen::Vector2d(f * fwd + sd * side); };
    Route route(at(P(0, 0), z));
    auto corner = [&] {
      if (s.cornerStopSeconds > 0.0) route.stop(s.cornerStopSeconds);
    };
    for (int lap = 0; lap < s.laps; ++lap) {
      route.lineTo(at(P(W / 2 - r, 0), z), s.speed);
      corner();
      route.arcAround(P(W / 2 - r, r), turnSign * kPi / 2, s.speed);
      route.lineTo(at(P(W / 2, H - r), z), s.speed);
      corner();
      route.arcAround(P(W / 2 - r, H - r), turnSign * kPi / 2, s.speed);
      route.lineTo(at(P(-W / 2 + r, H), z), s.speed);
      corner();
      route.arcAround(P(-W / 2 + r, H - r), turnSign * kPi / 2, s.speed);
      route.lineTo(at(P(-W / 2, r), z), s.speed);
      corner();
      route.arcAround(P(-W / 2 + r, r), turnSign * kPi / 2, s.speed);
      route.lineTo(at(P(0, 0), z), s.speed);
      if (lap + 1 < s.laps && s.stopSeconds > 0.0) route.stop(s.stopSeconds);
    }
    return route;
  }

  const double h = s.height;
  const Eigen::Vector3d home = at(Eigen::Vector2d::Zero(), s.takeoffLanding ? s.restHeight : h);
  Route route(home);
  if (s.takeoffLanding) route.lineTo(at(Eigen::Vector2d::Zero(), h), s.climbRate);

  switch (s.pattern) {
    case FlightPattern::Lawnmower: {
      const double d = s.rowSpacing;
      auto endOf = [&](double L) {
        // End point of the last row, in (forward, side) coordinates.
        const bool odd = s.rows % 2 == 1;
        return Eigen::Vector2d(odd ? L : 0.0, (s.rows - 1) * d);
      };
      auto total = [&](double L) { return s.rows * L + (s.rows - 1) * kPi * d / 2.0 + endOf(L).norm(); };
      if (total(0.0) >= s.length)
        throw std::invalid_argument("FlightSpec: lawnmower length too short for rows x row_spacing");
      const double L = bisect(total, s.length, 0.0, s.length);
      if (L < 1.0) throw std::invalid_argument("FlightSpec: lawnmower rows shorter than 1 m");
      for (int r = 0; r < s.rows; ++r) {
        const Eigen::Vector2d dir = (r % 2 == 0) ? fwd : Eigen::Vector2d(-fwd);
        route.lineTo(at(route.current().head<2>() + dir * L, h), s.speed);
        if (r + 1 < s.rows) {
          const Eigen::Vector2d centre = route.current().head<2>() + side * (d / 2.0);
          route.arcAround(centre, (r % 2 == 0 ? 1.0 : -1.0) * turnSign * kPi, s.speed);
        }
      }
      route.lineTo(at(Eigen::Vector2d::Zero(), h), s.speed);
      break;
    }
    case FlightPattern::Circle: {
      const double R = s.length / (2.0 * kPi * s.laps);
      route.arcAround(side * R, turnSign * 2.0 * kPi * s.laps, s.speed);
      break;
    }
    case FlightPattern::FigureEight: {
      // Lemniscate of Gerono: (forward, side) = A (sin u, sin(2u)/2); length per lap for A = 1.
      auto shape = [&](double u) { return Eigen::Vector2d(std::sin(u), 0.5 * std::sin(2.0 * u)); };
      double len1 = 0.0;
      const int m = 20000;
      for (int i = 1; i <= m; ++i) len1 += (shape(2 * kPi * i / m) - shape(2 * kPi * (i - 1) / m)).norm();
      const double A = s.length / (s.laps * len1);
      const int samples = static_cast<int>(std::ceil(s.length / 0.25));
      route.curve(
          [&](double u) {
            const Eigen::Vector2d q = A * shape(u);
            return at(q.x() * fwd + q.y() * side, h);
          },
          0.0, 2.0 * kPi * s.laps, samples, s.speed);
      break;
    }
    case FlightPattern::Waypoints: {
      if (s.takeoffLanding && std::abs(s.waypoints.front().z() - h) > 1e-9)
        route.lineTo(at(Eigen::Vector2d::Zero(), s.waypoints.front().z()), s.climbRate);
      for (const auto& w : s.waypoints) route.lineTo(w, s.speed);
      route.lineTo(at(Eigen::Vector2d::Zero(), route.current().z()), s.speed);
      if (!s.takeoffLanding && std::abs(route.current().z() - h) > 1e-9)
        route.lineTo(at(Eigen::Vector2d::Zero(), h), s.climbRate);
      break;
    }
    case FlightPattern::Drive:
    case FlightPattern::Walk: break;  // handled above
  }
  if (s.takeoffLanding) route.lineTo(at(Eigen::Vector2d::Zero(), s.restHeight), s.climbRate);
  return route;
}

std::unique_ptr<SplineTrajectory> trajectoryFromSamples(const RouteSamples& samples, double yawKnotInterval,
                                                        AttitudeConfig attitude) {
  if (samples.position.size() < 2) throw std::invalid_argument("trajectoryFromSamples: too few samples");
  const double duration = samples.duration();
  UniformBSpline<3> pos(0.0, samples.dt, samples.position);
  // Heading controls at the coarser yaw spacing, linearly interpolated from the samples.
  std::vector<Eigen::Matrix<double, 1, 1>> yc;
  const auto ny = static_cast<std::size_t>(std::ceil(duration / yawKnotInterval)) + 1;
  for (std::size_t j = 0; j < ny; ++j) {
    const double x = std::min(static_cast<double>(j) * yawKnotInterval / samples.dt,
                              static_cast<double>(samples.heading.size() - 1));
    const auto i = static_cast<std::size_t>(std::floor(x));
    const std::size_t i1 = std::min(i + 1, samples.heading.size() - 1);
    const double f = x - static_cast<double>(i);
    Eigen::Matrix<double, 1, 1> v;
    v(0) = (1.0 - f) * samples.heading[i] + f * samples.heading[i1];
    yc.push_back(v);
  }
  UniformBSpline<1> yaw(0.0, yawKnotInterval, std::move(yc));
  return std::make_unique<SplineTrajectory>(std::move(pos), std::move(yaw), std::move(attitude), duration);
}

std::unique_ptr<SplineTrajectory> buildFlight(const FlightSpec& spec, std::uint64_t seed) {
  const Route route = buildRoute(spec);
  RouteSamples samples = sampleRoute(route, spec.limits, spec.knotInterval, spec.hoverStart, spec.hoverEnd);
  if (spec.yaw == YawMode::Fixed)
    std::fill(samples.heading.begin(), samples.heading.end(), kPi / 2.0 - spec.fixedYawDeg * kPi / 180.0);
  AttitudeConfig att;
  if (spec.pattern == FlightPattern::Drive) {
    att = spec.vehicleAttitude;
    att.model = AttitudeModel::GroundVehicle;
  } else if (spec.pattern == FlightPattern::Walk) {
    att.model = AttitudeModel::GroundVehicle;  // level, heading along the path
    att.rollPerLateralAccel = 0.0;
    att.pitchPerLongitudinalAccel = 0.0;
  } else {
    att.model = AttitudeModel::Multirotor;
  }
  att.gravity = spec.gravity;
  const double duration = samples.duration();
  if (spec.pattern == FlightPattern::Walk) {
    // Gait: bob and sway in the positions, hand angles (plus the random wobble, interpolated
    // from its coarser knots) as the attitude perturbation on the samples' grid.
    const GaitPhase phase = gaitPhase(spec.gait, samples);
    std::vector<Eigen::Vector3d> c = gaitAngles(spec.gait, phase);
    if (spec.wobbleDeg > 0.0) {
      Rng rng(seed, nameHash("attitude wobble"));
      const double sigma = spec.wobbleDeg * kPi / 180.0;
      std::vector<Eigen::Vector3d> w;
      const auto n = static_cast<std::size_t>(std::ceil(duration / spec.wobbleInterval)) + 2;
      for (std::size_t j = 0; j < n; ++j) w.emplace_back(rng.normal(sigma), rng.normal(sigma), rng.normal(sigma));
      for (std::size_t k = 0; k < c.size(); ++k) {
        const double x = static_cast<double>(k) * samples.dt / spec.wobbleInterval;
        const auto j = static_cast<std::size_t>(std::floor(x));
        c[k] += phase.weight[k] * ((static_cast<double>(j + 1) - x) * w[j] + (x - static_cast<double>(j)) * w[j + 1]);
      }
    }
    att.wobble = UniformBSpline<3>(0.0, samples.dt, std::move(c));
    addGaitMotion(spec.gait, phase, samples);
    return trajectoryFromSamples(samples, spec.yawKnotInterval, std::move(att));
  }
  if (spec.wobbleDeg > 0.0) {
    Rng rng(seed, nameHash("attitude wobble"));
    const double sigma = spec.wobbleDeg * kPi / 180.0;
    std::vector<Eigen::Vector3d> c;
    const auto n = static_cast<std::size_t>(std::ceil(duration / spec.wobbleInterval)) + 1;
    for (std::size_t j = 0; j < n; ++j) {
      const double t = static_cast<double>(j) * spec.wobbleInterval;
      Eigen::Vector3d a(rng.normal(sigma), rng.normal(sigma), rng.normal(sigma));
      // No jitter while at rest on the ground before take-off and after landing.
      if (t <= spec.hoverStart || t >= duration - spec.hoverEnd) a.setZero();
      c.push_back(a);
    }
    att.wobble = UniformBSpline<3>(0.0, spec.wobbleInterval, std::move(c));
  }
  return trajectoryFromSamples(samples, spec.yawKnotInterval, std::move(att));
}

}  // namespace gvins::sim
