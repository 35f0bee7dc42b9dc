// A procedural 3-D world along a route for ground vehicles and hand-held rigs: buildings
// (oriented boxes whose street-side facades stand `streetHalfWidth` from the route on both
// sides, with gaps for side streets), poles and trees on the pavement, and textured ground on a
// height field (relief away from the street). Everything follows from the route and the seed:
// the same route and seed give the same world.
//
// The buildings (a few per 100 m of route) are placed when the world is built; their landmarks
// (points on the facades, on the pole and tree columns, on the ground) are generated lazily per
// square tile of `tileSize` metres, deterministically from the seed and the tile, and cached
// (at most `maxCachedTiles` tiles in memory). Queries by a horizontal region touch only the
// tiles and building-grid cells it overlaps, so a camera frustum clipped at 100 m costs a few
// thousand points.
//
// The same boxes decide what a camera sees (a landmark behind a building is occluded:
// segmentBlocked) and what a GNSS antenna receives (urban_signal_path.hpp).
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "gvins/sim/feature_simulator.hpp"

namespace gvins::sim {

struct UrbanConfig {
  double streetHalfWidth = 9.0;    ///< m, route centre line to the street-side facades
  double buildingLengthMin = 12.0, buildingLengthMax = 40.0;  ///< m along the street
  double buildingDepthMin = 10.0, buildingDepthMax = 25.0;    ///< m away from the street
  double buildingHeightMin = 8.0, buildingHeightMax = 40.0;   ///< m
  double gapMin = 0.0, gapMax = 12.0;  ///< m between neighbouring buildings (side streets)
  double facadeDensity = 0.08;     ///< landmarks per m^2 of facade
  double groundDensity = 0.02;     ///< landmarks per m^2 of ground
  double relief = 1.0;             ///< m, amplitude of the height field beyond the street
  double poleSpacing = 20.0;       ///< m, mean spacing of poles and trees per side (0: none)
  double tileSize = 50.0;          ///< m, landmark tile side
  int maxCachedTiles = 512;

  /// Throws std::invalid_argument naming the first out-of-range value.
  void validate() const;
};

/// A building: a box standing on z = 0 with horizontal centre c, unit axes u (along the
/// street) and v (away from it), half extents hu, hv, height h.
struct UrbanBuilding {
  Eigen::Vector2d c = Eigen::Vector2d::Zero(), u = Eigen::Vector2d::UnitX(), v = Eigen::Vector2d::UnitY();
  double hu = 1.0, hv = 1.0, height = 10.0;
  /// Corner k (0..3) counter-clockwise-ordered footprint corners and the face k from corner k
  /// to corner k+1 (outward normal faceNormal(k)).
  Eigen::Vector2d corner(int k) const;
  Eigen::Vector2d faceNormal(int k) const;
  Eigen::AlignedBox2d bounds() const;
  /// Signed distance of a horizontal point from the footprint (negative inside).
  double distance(const Eigen::Vector2d& p) const;
  /// Parameter interval [t0, t1] (within [0, tMax]) where a + t (b - a) lies inside the box; false
  /// when it does not enter it.
  bool segmentInterval(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double tMax, double& t0, double& t1) const;
};

struct UrbanPole {
  Eigen::Vector2d p = Eigen::Vector2d::Zero();
  bool tree = false;
  double height = 6.0;  ///< pole top / tree crown centre, m
  double radius = 0.15; ///< pole radius / crown radius, m
};

class UrbanStructure {
 public:
  /// `route`: horizontal points of the path (W, m), about a metre apart. Throws
  /// std::invalid_argument for a bad config or fewer than two route points.
  UrbanStructure(const UrbanConfig& config, const std::vector<Eigen::Vector2d>& route, std::uint64_t seed);

  /// Appends the landmarks of every tile overlapping the region (a superset of the region's).
  void landmarks(const Eigen::AlignedBox2d& region, std::vector<Landmark>& out) const;
  /// Indices of the buildings whose footprint bounds overlap the region (each once).
  void buildingsIn(const Eigen::AlignedBox2d& region, std::vector<int>& out) const;
  /// Whether the segment from `a` to `b` (shortened by 5 cm at b, so that a point on a facade
  /// seen from the street is not hidden by its own building) passes through one of `candidates`.
  bool segmentBlocked(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const std::vector<int>& candidates) const;
  bool segmentBlocked(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const;
  /// Ground height at a horizontal point (0 in the street, relief beyond it).
  double groundHeight(const Eigen::Vector2d& p) const;
  /// Distance from the route (capped at `cap`).
  double distanceToRoute(const Eigen::Vector2d& p, double cap) const;

  const std::vector<UrbanBuilding>& buildings() const { return buildings_; }
  const std::vector<UrbanPole>& poles() const { return poles_; }
  const UrbanConfig& config() const { return cfg_; }
  std::size_t tilesGenerated() const { return tilesGenerated_; }

 private:
  using Key = std::int64_t;
  static Key key(std::int64_t i, std::int64_t j) { return (i << 32) ^ (j & 0xFFFFFFFFLL); }
  void placeBuildings(const std::vector<Eigen::Vector2d>& route);
  bool clearOfRoute(const UrbanBuilding& b) const;
  std::shared_ptr<const std::vector<Landmark>> tile(std::int64_t i, std::int64_t j) const;
  void generateTile(std::int64_t i, std::int64_t j, std::vector<Landmark>& out) const;

  UrbanConfig cfg_;
  std::uint64_t seed_;
  std::vector<Eigen::Vector2d> route_;
  double routeCell_ = 8.0;
  std::unordered_map<Key, std::vector<int>> routeGrid_;  // route point indices per cell
  std::vector<UrbanBuilding> buildings_;
  std::vector<UrbanPole> poles_;
  double gridCell_ = 32.0;
  std::unordered_map<Key, std::vector<int>> buildingGrid_;
  std::unordered_map<Key, std::vector<int>> poleTiles_;  // pole indices per landmark tile
  Eigen::Vector4d reliefPhase_ = Eigen::Vector4d::Zero();
  mutable std::mutex mutex_;
  mutable std::unordered_map<Key, std::shared_ptr<const std::vector<Landmark>>> cache_;
  mutable std::size_t tilesGenerated_ = 0;
};

/// Horizontal route points of a trajectory, one every ~1 m of travel (stops collapse).
std::vector<Eigen::Vector2d> horizontalRoute(const Trajectory& trajectory, double spacing = 1.0);

}  // namespace gvins::sim
