#include "gvins/sim/urban_signal_path.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace gvins::sim {
namespace {

// Farther reflectors are ignored: their reflections arrive too weak to be tracked (a modelling
// choice; it bounds the NLOS extra path by 2 x 60 m).
constexpr double kMaxReflectorDistance = 60.0;

/// Whether the ray from p along u (upwards) enters one of the candidates below its roof; `skip`
/// is not tested (the reflecting building itself).
bool rayBlocked(const UrbanStructure& world, const Eigen::Vector3d& p, const Eigen::Vector3d& u,
                const std::vector<int>& candidates, int skip) {
  // A segment long enough to leave every candidate (1 km horizontally).
  const double horiz = std::hypot(u.x(), u.y());
  const double len = 1000.0 / std::max(horiz, 1e-3);
  const Eigen::Vector3d b = p + len * u;
  for (const int k : candidates) {
    if (k == skip) continue;
    const UrbanBuilding& bl = world.buildings()[static_cast<std::size_t>(k)];
    double t0, t1;
    if (!bl.segmentInterval(p, b, 1.0, t0, t1)) continue;
    if (p.z() + t0 * (b.z() - p.z()) < bl.height) return true;  // the ray rises: lowest at entry
  }
  return false;
}

}  // namespace

std::vector<int> buildingsNear(const UrbanStructure& world, const Eigen::Vector3d& p, double radius) {
  std::vector<int> out;
  const Eigen::Vector2d r(radius, radius);
  world.buildingsIn(Eigen::AlignedBox2d(p.head<2>() - r, p.head<2>() + r), out);
  return out;
}

UrbanSignalPath urbanSignalPath(const UrbanStructure& world, const Eigen::Vector3d& p, const Eigen::Vector3d& u,
                                const std::vector<int>& candidates) {
  UrbanSignalPath out;
  double dMin = std::numeric_limits<double>::infinity();
  for (const int k : candidates)
    dMin = std::min(dMin, std::max(world.buildings()[static_cast<std::size_t>(k)].distance(p.head<2>()), 0.0));
  out.multipathScale = 1.0 + 2.0 * std::exp(-dMin / 8.0);
  if (!rayBlocked(world, p, u, candidates, -1)) return out;
  // Non-line-of-sight: the shortest reflection off a face that faces the satellite.
  double best = std::numeric_limits<double>::infinity();
  for (const int k : candidates) {
    const UrbanBuilding& bl = world.buildings()[static_cast<std::size_t>(k)];
    for (int f = 0; f < 4; ++f) {
      const Eigen::Vector2d n2 = bl.faceNormal(f);
      const Eigen::Vector3d n(n2.x(), n2.y(), 0.0);
      const Eigen::Vector2d a = bl.corner(f), e = bl.corner(f + 1);
      const double d = (p.head<2>() - a).dot(n2);  // antenna in front of the face
      const double un = u.dot(n);
      if (!(d > 0.0) || d > kMaxReflectorDistance || !(un > 1e-3)) continue;
      // Reflection point: on the line from the image antenna p - 2 d n towards the satellite.
      const Eigen::Vector3d q = p - 2.0 * d * n + (d / un) * u;
      const double s = (q.head<2>() - a).dot(e - a) / (e - a).squaredNorm();
      if (s < 0.0 || s > 1.0 || q.z() < 0.0 || q.z() > bl.height) continue;
      const double extra = 2.0 * d * un;
      if (extra >= best) continue;
      if (rayBlocked(world, q, u, candidates, k)) continue;
      best = extra;
    }
  }
  if (std::isfinite(best)) {
    out.kind = UrbanSignalPath::Kind::Reflected;
    out.extraPath = best;
  } else {
    out.kind = UrbanSignalPath::Kind::Blocked;
  }
  return out;
}

}  // namespace gvins::sim
