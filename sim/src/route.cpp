#include "gvins/sim/route.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

namespace gvins::sim {

Route::Route(const Eigen::Vector3d& start, double maxSpacing) : maxSpacing_(maxSpacing) {
  if (!start.allFinite()) throw std::invalid_argument("Route: non-finite start");
  if (!(maxSpacing > 0.0)) throw std::invalid_argument("Route: spacing must be positive");
  pts_.push_back({start, 0.0, 0.0});
}

void Route::lineTo(const Eigen::Vector3d& p, double speed) {
  if (!p.allFinite() || !(speed > 0.0)) throw std::invalid_argument("Route::lineTo: bad point or speed");
  const Eigen::Vector3d a = current();
  const double len = (p - a).norm();
  if (len < 1e-9) return;
  const int n = std::max(1, static_cast<int>(std::ceil(len / maxSpacing_)));
  for (int i = 1; i <= n; ++i) pts_.push_back({a + (p - a) * (static_cast<double>(i) / n), speed, 0.0});
}

void Route::arcAround(const Eigen::Vector2d& centre, double angle, double speed) {
  const Eigen::Vector3d a = current();
  const Eigen::Vector2d r0 = a.head<2>() - centre;
  const double radius = r0.norm();
  if (!(radius > 1e-6) || !std::isfinite(angle)) throw std::invalid_argument("Route::arcAround: bad arc");
  const double a0 = std::atan2(r0.y(), r0.x());
  const int n = std::max(1, static_cast<int>(std::ceil(std::abs(angle) * radius / maxSpacing_)));
  curve(
      [&](double u) {
        return Eigen::Vector3d(centre.x() + radius * std::cos(a0 + u), centre.y() + radius * std::sin(a0 + u), a.z());
      },
      0.0, angle, n, speed);
}

void Route::curve(const std::function<Eigen::Vector3d(double)>& f, double u0, double u1, int samples, double speed) {
  if (samples < 1 || !(speed > 0.0)) throw std::invalid_argument("Route::curve: bad sampling or speed");
  for (int i = 1; i <= samples; ++i) {
    const Eigen::Vector3d p = f(u0 + (u1 - u0) * static_cast<double>(i) / samples);
    if ((p - current()).norm() > maxSpacing_ * 1.0001)
      lineTo(p, speed);  // subdivide a coarse step
    else if ((p - current()).norm() > 1e-9)
      pts_.push_back({p, speed, 0.0});
  }
}

void Route::stop(double seconds) {
  if (!(seconds >= 0.0)) throw std::invalid_argument("Route::stop: negative time");
  pts_.back().dwell += seconds;
  if (seconds == 0.0) pts_.back().dwell += 1e-3;  // still come to rest
}

double Route::length() const {
  double s = 0.0;
  for (std::size_t i = 1; i < pts_.size(); ++i) s += (pts_[i].p - pts_[i - 1].p).norm();
  return s;
}

double Route::horizontalLength() const {
  double s = 0.0;
  for (std::size_t i = 1; i < pts_.size(); ++i) s += (pts_[i].p - pts_[i - 1].p).head<2>().norm();
  return s;
}

RouteSamples sampleRoute(const Route& route, const MotionLimits& limits, double dt, double hoverStart,
                         double hoverEnd) {
  const auto& P = route.points();
  const std::size_t n = P.size();
  if (n < 2) throw std::invalid_argument("sampleRoute: a route needs at least two points");
  if (!(limits.lateralAccel > 0.0) || !(limits.longitudinalAccel > 0.0) || !(dt > 0.0) || !(hoverStart >= 0.0) ||
      !(hoverEnd >= 0.0))
    throw std::invalid_argument("sampleRoute: limits, time step and hover times must be positive");

  // Point speed limits.
  std::vector<double> v(n, 0.0), ds(n, 0.0);
  for (std::size_t i = 1; i < n; ++i) ds[i] = (P[i].p - P[i - 1].p).norm();
  for (std::size_t i = 1; i + 1 < n; ++i) {
    double lim = std::min(P[i].speed, P[i + 1].speed);
    const Eigen::Vector3d a = P[i].p - P[i - 1].p, b = P[i + 1].p - P[i].p;
    const double chord = (P[i + 1].p - P[i - 1].p).norm();
    const double sinAngle = a.cross(b).norm() / (a.norm() * b.norm());
    const double cosAngle = a.dot(b) / (a.norm() * b.norm());
    if (cosAngle < -0.99)
      lim = 0.0;  // reversal
    else if (sinAngle > 1e-12 && chord > 1e-12) {
      // Circle through three points: kappa = 2 sin(turn angle) / chord.
      const double kappa = 2.0 * sinAngle / chord;
      lim = std::min(lim, std::sqrt(limits.lateralAccel / kappa));
      // A sharp vertex (polyline corner) turns the velocity by 2 v sin(angle/2) at one point;
      // the smoothing spreads that over ~0.5 s, so keep 2 v sin(angle/2) / 0.5 s within the
      // lateral limit (smooth arcs turn by tiny angles per point and are not affected).
      const double turn = std::atan2(sinAngle, cosAngle);
      lim = std::min(lim, 0.25 * limits.lateralAccel / std::max(2.0 * std::sin(0.5 * turn), 1e-12));
    }
    if (P[i].dwell > 0.0) lim = 0.0;
    v[i] = lim;
  }
  v[0] = v[n - 1] = 0.0;
  for (std::size_t i = 1; i < n; ++i)
    v[i] = std::min(v[i], std::sqrt(v[i - 1] * v[i - 1] + 2.0 * limits.longitudinalAccel * ds[i]));
  for (std::size_t i = n - 1; i-- > 0;)
    v[i] = std::min(v[i], std::sqrt(v[i + 1] * v[i + 1] + 2.0 * limits.longitudinalAccel * ds[i + 1]));

  // Arrival times (constant acceleration on each segment), with dwells.
  std::vector<double> tArrive(n, 0.0), tLeave(n, 0.0);
  tArrive[0] = hoverStart;
  tLeave[0] = hoverStart + P[0].dwell;
  for (std::size_t i = 1; i < n; ++i) {
    const double vm = 0.5 * (v[i - 1] + v[i]);
    if (!(vm > 0.0)) throw std::invalid_argument("sampleRoute: zero speed on a segment");
    tArrive[i] = tLeave[i - 1] + ds[i] / vm;
    tLeave[i] = tArrive[i] + P[i].dwell;
  }
  const double total = tLeave[n - 1] + hoverEnd;

  // Heading of each segment's horizontal direction. A vertical segment holds the heading of
  // the horizontal motion before it or, if there is none (take-off), after it.
  std::vector<double> segHeading(n, std::numeric_limits<double>::quiet_NaN());
  for (std::size_t i = 1; i < n; ++i) {
    const Eigen::Vector2d d = (P[i].p - P[i - 1].p).head<2>();
    if (d.norm() > 1e-3 * std::max(ds[i], 1e-9)) segHeading[i] = std::atan2(d.y(), d.x());
  }
  double firstHeading = 0.0;
  for (std::size_t i = 1; i < n; ++i)
    if (!std::isnan(segHeading[i])) {
      firstHeading = segHeading[i];
      break;
    }
  double prevHeading = firstHeading;
  for (std::size_t i = 1; i < n; ++i) {
    if (std::isnan(segHeading[i])) segHeading[i] = prevHeading;
    prevHeading = segHeading[i];
  }

  RouteSamples out;
  out.dt = dt;
  const auto steps = static_cast<std::size_t>(std::ceil(total / dt - 1e-9));
  out.position.reserve(steps + 1);
  out.heading.reserve(steps + 1);
  std::size_t seg = 1;
  double lastHeading = segHeading[1];
  for (std::size_t k = 0; k <= steps; ++k) {
    const double t = static_cast<double>(k) * dt;
    Eigen::Vector3d p;
    double h;
    if (t <= tLeave[0]) {
      p = P[0].p;
      h = segHeading[1];
    } else if (t >= tArrive[n - 1]) {
      p = P[n - 1].p;
      h = segHeading[n - 1];
    } else {
      while (seg < n - 1 && t >= tArrive[seg]) ++seg;
      // Now t < tArrive[seg]; at rest at point seg-1 until tLeave[seg-1].
      if (t <= tLeave[seg - 1]) {
        p = P[seg - 1].p;
        h = segHeading[seg];
      } else {
        const double T = tArrive[seg] - tLeave[seg - 1];
        const double tau = t - tLeave[seg - 1];
        const double s = v[seg - 1] * tau + 0.5 * (v[seg] - v[seg - 1]) / T * tau * tau;
        p = P[seg - 1].p + (P[seg].p - P[seg - 1].p) * std::clamp(s / ds[seg], 0.0, 1.0);
        h = segHeading[seg];
      }
    }
    // Unwrap against the previous sample.
    h += 2.0 * std::numbers::pi * std::round((lastHeading - h) / (2.0 * std::numbers::pi));
    lastHeading = h;
    out.position.push_back(p);
    out.heading.push_back(h);
  }
  return out;
}

}  // namespace gvins::sim
