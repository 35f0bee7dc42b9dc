#include "gvins/sim/urban_structure.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "gvins/sim/random.hpp"

namespace gvins::sim {
namespace {

// Landmark ids (below 2^52, exact in a double): kind in bits 50-51, then
//   ground: tile (i, j) + 2^13 in 14 bits each (bits 36-49, 22-35), index in 22 bits;
//   facade: building in 26 bits (24-49), face in 2 bits (22-23), index in 22 bits;
//   pole:   pole in 34 bits (16-49), index in 16 bits.
constexpr std::uint64_t kKindGround = 1, kKindFacade = 2, kKindPole = 3;
constexpr std::int64_t kTileBias = std::int64_t{1} << 13;
constexpr int kMaxPerGroup = (1 << 22) - 1;
constexpr double kTwoPi = 6.283185307179586;

std::int64_t cellOf(double x, double cell) { return static_cast<std::int64_t>(std::floor(x / cell)); }

double cross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

/// Whether two buildings' footprints overlap (separating axis theorem on their four axes).
bool overlaps(const UrbanBuilding& a, const UrbanBuilding& b) {
  for (const Eigen::Vector2d& axis : {a.u, a.v, b.u, b.v}) {
    auto extent = [&](const UrbanBuilding& x) { return x.hu * std::abs(x.u.dot(axis)) + x.hv * std::abs(x.v.dot(axis)); };
    if (std::abs((a.c - b.c).dot(axis)) > extent(a) + extent(b)) return false;
  }
  return true;
}

/// Point and unit tangent at arclength s of a polyline with cumulative lengths S.
void pointAt(const std::vector<Eigen::Vector2d>& q, const std::vector<double>& S, double s, Eigen::Vector2d& p,
             Eigen::Vector2d& tangent) {
  const auto it = std::upper_bound(S.begin(), S.end(), s);
  std::size_t i = it == S.begin() ? 0 : static_cast<std::size_t>(it - S.begin()) - 1;
  i = std::min(i, q.size() - 2);
  const double len = S[i + 1] - S[i];
  const double f = len > 0.0 ? std::clamp((s - S[i]) / len, 0.0, 1.0) : 0.0;
  p = q[i] + f * (q[i + 1] - q[i]);
  tangent = len > 0.0 ? Eigen::Vector2d((q[i + 1] - q[i]) / len) : Eigen::Vector2d::UnitX();
}

}  // namespace

void UrbanConfig::validate() const {
  auto range = [](double lo, double hi, double min, double max, const char* what) {
    if (!(std::isfinite(lo) && std::isfinite(hi) && lo >= min && hi >= lo && hi <= max))
      throw std::invalid_argument(std::string("structure: ") + what + " must be an interval within [" +
                                  std::to_string(min) + ", " + std::to_string(max) + "]");
  };
  if (!(std::isfinite(streetHalfWidth) && streetHalfWidth >= 3.0 && streetHalfWidth <= 200.0))
    throw std::invalid_argument("structure: street_half_width_m must be in [3, 200] m");
  range(buildingLengthMin, buildingLengthMax, 2.0, 1000.0, "building_length_m");
  range(buildingDepthMin, buildingDepthMax, 2.0, 1000.0, "building_depth_m");
  range(buildingHeightMin, buildingHeightMax, 1.0, 1000.0, "building_height_m");
  range(gapMin, gapMax, 0.0, 1000.0, "gap_m");
  range(facadeDensity, facadeDensity, 0.0, 10.0, "facade_density_per_m2");
  range(groundDensity, groundDensity, 0.0, 10.0, "ground_density_per_m2");
  range(relief, relief, 0.0, 100.0, "relief_m");
  range(poleSpacing, poleSpacing, 0.0, 10000.0, "pole_spacing_m");
  if (poleSpacing > 0.0 && poleSpacing < 2.0) throw std::invalid_argument("structure: pole_spacing_m must be 0 or >= 2 m");
  range(tileSize, tileSize, 5.0, 1000.0, "tile_m");
  // Bounded work per tile: at most 1e5 points on a face or on a tile's ground.
  if (facadeDensity * buildingLengthMax * buildingHeightMax > 1e5 || facadeDensity * buildingDepthMax * buildingHeightMax > 1e5)
    throw std::invalid_argument("structure: facade_density_per_m2 x building size gives more than 1e5 points per facade");
  if (groundDensity * tileSize * tileSize > 1e5)
    throw std::invalid_argument("structure: ground_density_per_m2 x tile_m^2 gives more than 1e5 points per tile");
  if (maxCachedTiles < 16 || maxCachedTiles > 1000000) throw std::invalid_argument("structure: cache of 16 to 1e6 tiles");
}

Eigen::Vector2d UrbanBuilding::corner(int k) const {
  static constexpr double su[4] = {-1, 1, 1, -1}, sv[4] = {-1, -1, 1, 1};
  return c + su[k & 3] * hu * u + sv[k & 3] * hv * v;
}

Eigen::Vector2d UrbanBuilding::faceNormal(int k) const {
  switch (k & 3) {
    case 0: return -v;
    case 1: return u;
    case 2: return v;
    default: return -u;
  }
}

Eigen::AlignedBox2d UrbanBuilding::bounds() const {
  const Eigen::Vector2d e(hu * std::abs(u.x()) + hv * std::abs(v.x()), hu * std::abs(u.y()) + hv * std::abs(v.y()));
  return Eigen::AlignedBox2d(c - e, c + e);
}

double UrbanBuilding::distance(const Eigen::Vector2d& p) const {
  const double dx = std::abs((p - c).dot(u)) - hu, dy = std::abs((p - c).dot(v)) - hv;
  if (dx <= 0.0 && dy <= 0.0) return std::max(dx, dy);
  return std::hypot(std::max(dx, 0.0), std::max(dy, 0.0));
}

bool UrbanBuilding::segmentInterval(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double tMax, double& t0,
                                    double& t1) const {
  t0 = 0.0;
  t1 = tMax;
  const Eigen::Vector2d a2 = a.head<2>() - c, d2 = (b - a).head<2>();
  for (int k = 0; k < 2; ++k) {
    const Eigen::Vector2d& axis = k == 0 ? u : v;
    const double h = k == 0 ? hu : hv;
    const double p = a2.dot(axis), d = d2.dot(axis);
    if (std::abs(d) < 1e-12) {
      if (std::abs(p) >= h) return false;
      continue;
    }
    double ta = (-h - p) / d, tb = (h - p) / d;
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 >= t1) return false;
  }
  return true;
}

UrbanStructure::UrbanStructure(const UrbanConfig& config, const std::vector<Eigen::Vector2d>& route, std::uint64_t seed)
    : cfg_(config), seed_(seed), route_(route) {
  cfg_.validate();
  if (route_.size() < 2) throw std::invalid_argument("structure: the route needs at least two points");
  for (const auto& q : route_)
    if (!q.allFinite() || std::abs(q.x()) > 3e5 || std::abs(q.y()) > 3e5)
      throw std::invalid_argument("structure: the route must stay within 300 km of the origin");
  for (std::size_t i = 0; i < route_.size(); ++i)
    routeGrid_[key(cellOf(route_[i].x(), routeCell_), cellOf(route_[i].y(), routeCell_))].push_back(static_cast<int>(i));
  Rng rng(seed_, nameHash("relief"));
  for (int k = 0; k < 4; ++k) reliefPhase_[k] = rng.uniform(0.0, kTwoPi);
  placeBuildings(route_);
}

double UrbanStructure::distanceToRoute(const Eigen::Vector2d& p, double cap) const {
  const std::int64_t r = static_cast<std::int64_t>(std::ceil(cap / routeCell_));
  const std::int64_t ci = cellOf(p.x(), routeCell_), cj = cellOf(p.y(), routeCell_);
  double best2 = cap * cap;
  for (std::int64_t j = cj - r; j <= cj + r; ++j)
    for (std::int64_t i = ci - r; i <= ci + r; ++i) {
      const auto it = routeGrid_.find(key(i, j));
      if (it == routeGrid_.end()) continue;
      for (const int k : it->second) best2 = std::min(best2, (route_[static_cast<std::size_t>(k)] - p).squaredNorm());
    }
  return std::sqrt(best2);
}

bool UrbanStructure::clearOfRoute(const UrbanBuilding& b) const {
  const double clear = 0.85 * cfg_.streetHalfWidth;
  const Eigen::AlignedBox2d box = b.bounds();
  for (std::int64_t j = cellOf(box.min().y() - clear, routeCell_); j <= cellOf(box.max().y() + clear, routeCell_); ++j)
    for (std::int64_t i = cellOf(box.min().x() - clear, routeCell_); i <= cellOf(box.max().x() + clear, routeCell_); ++i) {
      const auto it = routeGrid_.find(key(i, j));
      if (it == routeGrid_.end()) continue;
      for (const int k : it->second)
        if (b.distance(route_[static_cast<std::size_t>(k)]) < clear) return false;
    }
  return true;
}

void UrbanStructure::placeBuildings(const std::vector<Eigen::Vector2d>& q) {
  std::vector<double> S(q.size(), 0.0);
  for (std::size_t i = 1; i < q.size(); ++i) S[i] = S[i - 1] + (q[i] - q[i - 1]).norm();
  const double total = S.back();
  const double w = cfg_.streetHalfWidth;
  std::vector<int> candidates;
  for (const double side : {1.0, -1.0}) {
    Rng rng(seed_, nameHash(side > 0 ? "buildings left" : "buildings right"));
    double s = rng.uniform(0.0, cfg_.gapMax);
    while (s < total) {
      const double L = rng.uniform(cfg_.buildingLengthMin, cfg_.buildingLengthMax);
      const double gap = rng.uniform(cfg_.gapMin, cfg_.gapMax);
      const double D = rng.uniform(cfg_.buildingDepthMin, cfg_.buildingDepthMax);
      const double H = rng.uniform(cfg_.buildingHeightMin, cfg_.buildingHeightMax);
      const double s0 = s;
      s += L + gap;
      if (s0 + L > total) break;
      Eigen::Vector2d p0, p1, t0, t1;
      pointAt(q, S, s0, p0, t0);
      pointAt(q, S, s0 + L, p1, t1);
      const Eigen::Vector2d d = p1 - p0;
      if (d.norm() < 0.7 * L) continue;  // the route turns within the building's length
      UrbanBuilding b;
      b.u = d.normalized();
      b.v = side * Eigen::Vector2d(-b.u.y(), b.u.x());  // away from the street on this side
      if (cross2(b.u, b.v) < 0.0) b.u = -b.u;           // right-handed (u, v): corners counter-clockwise
      b.hu = 0.5 * d.norm();
      b.hv = 0.5 * D;
      b.height = H;
      b.c = 0.5 * (p0 + p1) + (w + 0.5 * D) * b.v;
      if (!clearOfRoute(b)) continue;
      // Not overlapping one already placed (candidates from the grid: footprints that overlap
      // have overlapping bounds).
      bool free = true;
      candidates.clear();
      buildingsIn(b.bounds(), candidates);
      for (const int k : candidates)
        if (overlaps(buildings_[static_cast<std::size_t>(k)], b)) {
          free = false;
          break;
        }
      if (!free) continue;
      const Eigen::AlignedBox2d box = b.bounds();
      for (std::int64_t j = cellOf(box.min().y(), gridCell_); j <= cellOf(box.max().y(), gridCell_); ++j)
        for (std::int64_t i = cellOf(box.min().x(), gridCell_); i <= cellOf(box.max().x(), gridCell_); ++i)
          buildingGrid_[key(i, j)].push_back(static_cast<int>(buildings_.size()));
      buildings_.push_back(b);
    }
  }
  if (!(cfg_.poleSpacing > 0.0)) return;
  // Poles and trees on the pavement, 1.5 m in front of the facades.
  const double off = w - 1.5;
  std::vector<int> near;
  for (const double side : {1.0, -1.0}) {
    Rng rng(seed_, nameHash(side > 0 ? "poles left" : "poles right"));
    for (double s = rng.uniform(0.0, cfg_.poleSpacing); s < total; s += cfg_.poleSpacing * rng.uniform(0.5, 1.5)) {
      UrbanPole pole;
      pole.tree = rng.uniform() < 0.4;
      pole.height = pole.tree ? rng.uniform(4.0, 6.0) : rng.uniform(5.0, 8.0);
      pole.radius = pole.tree ? rng.uniform(1.5, 3.0) : 0.15;
      Eigen::Vector2d p, t;
      pointAt(q, S, s, p, t);
      pole.p = p + side * off * Eigen::Vector2d(-t.y(), t.x());
      if (distanceToRoute(pole.p, off) < 0.7 * off) continue;
      near.clear();
      buildingsIn(Eigen::AlignedBox2d(pole.p, pole.p), near);
      bool inside = false;
      for (const int k : near) inside = inside || buildings_[static_cast<std::size_t>(k)].distance(pole.p) < 0.5;
      if (inside) continue;
      poleTiles_[key(cellOf(pole.p.x(), cfg_.tileSize), cellOf(pole.p.y(), cfg_.tileSize))].push_back(
          static_cast<int>(poles_.size()));
      poles_.push_back(pole);
    }
  }
}

void UrbanStructure::buildingsIn(const Eigen::AlignedBox2d& region, std::vector<int>& out) const {
  const std::size_t first = out.size();
  for (std::int64_t j = cellOf(region.min().y(), gridCell_); j <= cellOf(region.max().y(), gridCell_); ++j)
    for (std::int64_t i = cellOf(region.min().x(), gridCell_); i <= cellOf(region.max().x(), gridCell_); ++i) {
      const auto it = buildingGrid_.find(key(i, j));
      if (it == buildingGrid_.end()) continue;
      for (const int k : it->second)
        if (buildings_[static_cast<std::size_t>(k)].bounds().intersects(region)) out.push_back(k);
    }
  std::sort(out.begin() + static_cast<long>(first), out.end());
  out.erase(std::unique(out.begin() + static_cast<long>(first), out.end()), out.end());
}

bool UrbanStructure::segmentBlocked(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                    const std::vector<int>& candidates) const {
  const double len = (b - a).norm();
  if (!(len > 0.05)) return false;
  const double tMax = 1.0 - 0.05 / len;
  for (const int k : candidates) {
    const UrbanBuilding& bl = buildings_[static_cast<std::size_t>(k)];
    double t0, t1;
    if (!bl.segmentInterval(a, b, tMax, t0, t1)) continue;
    const double z0 = a.z() + t0 * (b.z() - a.z()), z1 = a.z() + t1 * (b.z() - a.z());
    if (std::min(z0, z1) < bl.height) return true;
  }
  return false;
}

bool UrbanStructure::segmentBlocked(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const {
  std::vector<int> near;
  Eigen::AlignedBox2d box(a.head<2>());
  box.extend(Eigen::Vector2d(b.head<2>()));
  buildingsIn(box, near);
  return segmentBlocked(a, b, near);
}

double UrbanStructure::groundHeight(const Eigen::Vector2d& p) const {
  if (!(cfg_.relief > 0.0)) return 0.0;
  const double w = cfg_.streetHalfWidth;
  const double f = std::clamp((distanceToRoute(p, w + 10.0) - w) / 10.0, 0.0, 1.0);
  if (f <= 0.0) return 0.0;
  // A smooth field in [0, 1]: a few long-wave sinusoids with phases from the seed.
  const Eigen::Vector4d& ph = reliefPhase_;
  const double n = 0.5 * std::sin(0.031 * p.x() + ph[0]) * std::cos(0.027 * p.y() + ph[1]) +
                   0.25 * std::sin(0.07 * (p.x() + p.y()) + ph[2]) + 0.25 * std::cos(0.09 * (p.x() - p.y()) + ph[3]);
  return cfg_.relief * f * (0.5 + 0.5 * n);
}

void UrbanStructure::generateTile(std::int64_t i, std::int64_t j, std::vector<Landmark>& out) const {
  const double T = cfg_.tileSize;
  const Eigen::AlignedBox2d tileBox(Eigen::Vector2d(static_cast<double>(i) * T, static_cast<double>(j) * T),
                                    Eigen::Vector2d(static_cast<double>(i + 1) * T, static_cast<double>(j + 1) * T));
  auto inTile = [&](const Eigen::Vector2d& p) {
    return p.x() >= tileBox.min().x() && p.x() < tileBox.max().x() && p.y() >= tileBox.min().y() && p.y() < tileBox.max().y();
  };
  std::vector<int> near;
  buildingsIn(tileBox, near);
  // Ground texture: uniform over the tile, none inside buildings.
  if (cfg_.groundDensity > 0.0) {
    std::uint64_t st = hash4(seed_ ^ nameHash("urban ground"), i, j, 0x47);
    const int n = std::min(kMaxPerGroup, static_cast<int>(std::floor(cfg_.groundDensity * T * T + unitFromBits(splitmix64(st)))));
    for (int k = 0; k < n; ++k) {
      const Eigen::Vector2d p(tileBox.min().x() + T * unitFromBits(splitmix64(st)),
                              tileBox.min().y() + T * unitFromBits(splitmix64(st)));
      const double priority = unitFromBits(splitmix64(st));
      bool inside = false;
      for (const int b : near) inside = inside || buildings_[static_cast<std::size_t>(b)].distance(p) < 0.0;
      if (inside) continue;
      Landmark l;
      l.p_W = Eigen::Vector3d(p.x(), p.y(), groundHeight(p));
      l.priority = priority;
      l.id = (kKindGround << 50) | (static_cast<std::uint64_t>(i + kTileBias) << 36) |
             (static_cast<std::uint64_t>(j + kTileBias) << 22) | static_cast<std::uint64_t>(k);
      out.push_back(l);
    }
  }
  // Facades: every face of every building touching the tile; the points in the tile are kept.
  for (const int b : near) {
    const UrbanBuilding& bl = buildings_[static_cast<std::size_t>(b)];
    for (int f = 0; f < 4; ++f) {
      const Eigen::Vector2d a = bl.corner(f), e = bl.corner(f + 1);
      const double len = (e - a).norm();
      std::uint64_t st = hash4(seed_ ^ nameHash("urban facade"), b, f, 0x46);
      const int n = std::min(kMaxPerGroup, static_cast<int>(std::floor(cfg_.facadeDensity * len * bl.height +
                                                                         unitFromBits(splitmix64(st)))));
      for (int k = 0; k < n; ++k) {
        const double s = unitFromBits(splitmix64(st)), z = 0.3 + (bl.height - 0.3) * unitFromBits(splitmix64(st));
        const double priority = unitFromBits(splitmix64(st));
        const Eigen::Vector2d p = a + s * (e - a);
        if (!inTile(p)) continue;
        Landmark l;
        l.p_W = Eigen::Vector3d(p.x(), p.y(), z);
        l.priority = priority;
        l.id = (kKindFacade << 50) | (static_cast<std::uint64_t>(b) << 24) | (static_cast<std::uint64_t>(f) << 22) |
               static_cast<std::uint64_t>(k);
        out.push_back(l);
      }
    }
  }
  // Poles (points every ~0.6 m up the column) and trees (trunk and a spherical crown).
  const auto it = poleTiles_.find(key(i, j));
  if (it == poleTiles_.end()) return;
  for (const int pi : it->second) {
    const UrbanPole& pole = poles_[static_cast<std::size_t>(pi)];
    std::uint64_t st = hash4(seed_ ^ nameHash("urban pole"), pi, 0, 0x50);
    const int n = pole.tree ? 30 : static_cast<int>(pole.height / 0.6);
    for (int k = 0; k < n; ++k) {
      const double u1 = unitFromBits(splitmix64(st)), u2 = unitFromBits(splitmix64(st)), u3 = unitFromBits(splitmix64(st));
      Eigen::Vector3d p;
      if (!pole.tree) {
        p = Eigen::Vector3d(pole.p.x() + pole.radius * std::cos(kTwoPi * u1), pole.p.y() + pole.radius * std::sin(kTwoPi * u1),
                            (k + u2) * 0.6);
      } else if (k < 5) {  // trunk
        p = Eigen::Vector3d(pole.p.x() + 0.2 * std::cos(kTwoPi * u1), pole.p.y() + 0.2 * std::sin(kTwoPi * u1),
                            (k + u2) * (pole.height - pole.radius) / 5.0);
      } else {  // crown: uniform directions, radius r u^(1/3) (uniform in the ball)
        const double cz = 2.0 * u2 - 1.0, sz = std::sqrt(std::max(0.0, 1.0 - cz * cz));
        const double r = pole.radius * std::cbrt(u3);
        p = Eigen::Vector3d(pole.p.x() + r * sz * std::cos(kTwoPi * u1), pole.p.y() + r * sz * std::sin(kTwoPi * u1),
                            pole.height + r * cz);
      }
      Landmark l;
      l.p_W = p;
      l.priority = unitFromBits(splitmix64(st));
      l.id = (kKindPole << 50) | (static_cast<std::uint64_t>(pi) << 16) | static_cast<std::uint64_t>(k);
      out.push_back(l);
    }
  }
}

std::shared_ptr<const std::vector<Landmark>> UrbanStructure::tile(std::int64_t i, std::int64_t j) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = cache_.find(key(i, j));
  if (it != cache_.end()) return it->second;
  auto v = std::make_shared<std::vector<Landmark>>();
  generateTile(i, j, *v);
  ++tilesGenerated_;
  if (cache_.size() >= static_cast<std::size_t>(cfg_.maxCachedTiles)) cache_.clear();  // bounded memory
  cache_.emplace(key(i, j), v);
  return v;
}

void UrbanStructure::landmarks(const Eigen::AlignedBox2d& region, std::vector<Landmark>& out) const {
  if (region.isEmpty() || !region.min().allFinite() || !region.max().allFinite()) return;
  const double T = cfg_.tileSize;
  const std::int64_t i0 = cellOf(region.min().x(), T), i1 = cellOf(region.max().x(), T);
  const std::int64_t j0 = cellOf(region.min().y(), T), j1 = cellOf(region.max().y(), T);
  if ((i1 - i0 + 1) * (j1 - j0 + 1) > 4096) throw std::invalid_argument("structure: landmark query region too large");
  for (const std::int64_t v : {i0, i1, j0, j1})
    if (v <= -kTileBias || v >= kTileBias - 1) throw std::invalid_argument("structure: query too far from the origin");
  for (std::int64_t j = j0; j <= j1; ++j)
    for (std::int64_t i = i0; i <= i1; ++i) {
      const auto t = tile(i, j);
      out.insert(out.end(), t->begin(), t->end());
    }
}

std::vector<Eigen::Vector2d> horizontalRoute(const Trajectory& trajectory, double spacing) {
  std::vector<Eigen::Vector2d> out;
  const double T = trajectory.duration();
  const int n = static_cast<int>(std::ceil(T / 0.05));
  for (int k = 0; k <= n; ++k) {
    const Eigen::Vector2d p = trajectory.evaluate(std::min(T, k * 0.05)).p_WB.head<2>();
    if (out.empty() || (p - out.back()).norm() >= spacing || (k == n && (p - out.back()).norm() > 1e-6)) out.push_back(p);
  }
  if (out.size() < 2) out.push_back(out.back() + Eigen::Vector2d(spacing, 0.0));
  return out;
}

}  // namespace gvins::sim
