// The 3-D structure of ground scenarios (urban_structure.hpp, urban_signal_path.hpp) against
// geometry worked out by hand:
// - the same route and seed give the same buildings and landmarks, another seed another world;
// - a forward camera in the street facing a building observes points of its street facade but
//   none of its back facade, although those project into the image within range (occlusion);
// - in a canyon of 20 m buildings 10 m either side of the antenna, a satellite across the street
//   at 10 deg elevation is blocked (its reflection off the opposite facade is blocked too), at
//   45 deg it arrives reflected off the opposite facade with the image-antenna extra path
//   2 d cos(el) = 14.142 m, at 70 deg (above the skyline) in line of sight;
// - multipath grows near facades.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include <Eigen/Geometry>

#include "gvins/sim/feature_simulator.hpp"
#include "gvins/sim/scenario.hpp"
#include "gvins/sim/urban_signal_path.hpp"
#include "gvins/sim/urban_structure.hpp"

namespace gvins::sim {
namespace {

std::vector<Eigen::Vector2d> straightRoute(double x0, double x1) {
  std::vector<Eigen::Vector2d> r;
  for (double x = x0; x <= x1 + 1e-9; x += 1.0) r.emplace_back(x, 0.0);
  return r;
}

/// Continuous facades: 30 m long, 15 m deep, 20 m high buildings without gaps, both sides,
/// street facades at y = +-10 m.
UrbanConfig canyon() {
  UrbanConfig c;
  c.streetHalfWidth = 10.0;
  c.buildingLengthMin = c.buildingLengthMax = 30.0;
  c.buildingDepthMin = c.buildingDepthMax = 15.0;
  c.buildingHeightMin = c.buildingHeightMax = 20.0;
  c.gapMin = c.gapMax = 0.0;
  c.poleSpacing = 0.0;
  c.relief = 0.0;
  return c;
}

/// A camera at rest at p, optical axis along `look` (horizontal), image x to the right.
class StaticTrajectory final : public Trajectory {
 public:
  StaticTrajectory(const Eigen::Vector3d& p, double yawRad) : p_(p), yaw_(yawRad) {}
  double duration() const override { return 10.0; }
  TrajectoryState evaluate(double t) const override {
    TrajectoryState s;
    s.t = t;
    s.p_WB = p_;
    s.R_WB = Eigen::AngleAxisd(yaw_, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    return s;
  }

 private:
  Eigen::Vector3d p_;
  double yaw_;
};

const UrbanBuilding* buildingAt(const UrbanStructure& w, const Eigen::Vector2d& p) {
  for (const UrbanBuilding& b : w.buildings())
    if (b.distance(p) < 0.0) return &b;
  return nullptr;
}

TEST(UrbanStructure, SameSeedSameWorld) {
  UrbanConfig c;  // defaults: random lengths, depths, heights, gaps, poles and relief
  std::vector<Eigen::Vector2d> route = straightRoute(-300.0, 300.0);
  for (double a = 0.0; a <= 3.14159; a += 0.01) route.emplace_back(300.0 + 40.0 * std::sin(a), 40.0 - 40.0 * std::cos(a));
  const UrbanStructure w1(c, route, 42), w2(c, route, 42), w3(c, route, 43);
  ASSERT_GT(w1.buildings().size(), 20u);
  ASSERT_EQ(w1.buildings().size(), w2.buildings().size());
  for (std::size_t i = 0; i < w1.buildings().size(); ++i) {
    EXPECT_EQ(w1.buildings()[i].c, w2.buildings()[i].c);
    EXPECT_EQ(w1.buildings()[i].height, w2.buildings()[i].height);
  }
  // Landmarks: the same ids and points whatever the order of the queries (lazy tiles).
  const Eigen::AlignedBox2d region(Eigen::Vector2d(-120.0, -60.0), Eigen::Vector2d(80.0, 60.0));
  std::vector<Landmark> a, b, other;
  w1.landmarks(region, a);
  w2.landmarks(Eigen::AlignedBox2d(Eigen::Vector2d(200.0, 0.0), Eigen::Vector2d(260.0, 20.0)), b);  // other tiles first
  b.clear();
  w2.landmarks(region, b);
  w3.landmarks(region, other);
  ASSERT_GT(a.size(), 500u);
  ASSERT_EQ(a.size(), b.size());
  std::set<std::uint64_t> ids;
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].id, b[i].id);
    EXPECT_EQ(a[i].p_W, b[i].p_W);
    ids.insert(a[i].id);
  }
  EXPECT_EQ(ids.size(), a.size()) << "landmark ids are unique";
  // Another seed: other buildings (heights) and other points.
  bool differs = w1.buildings().size() != w3.buildings().size();
  for (std::size_t i = 0; !differs && i < w1.buildings().size(); ++i) differs = w1.buildings()[i].height != w3.buildings()[i].height;
  EXPECT_TRUE(differs);
  EXPECT_TRUE(other.size() != a.size() || other.front().p_W != a.front().p_W);
  // Facades stand clear of the route: no route point within 0.85 street half-widths.
  for (const UrbanBuilding& bl : w1.buildings())
    for (const Eigen::Vector2d& q : route) ASSERT_GE(bl.distance(q), 0.85 * c.streetHalfWidth - 1e-9);
}

TEST(UrbanStructure, LandmarkBehindAFacadeIsNotObserved) {
  const UrbanStructure world(canyon(), straightRoute(-200.0, 200.0), 7);
  const UrbanBuilding* left = buildingAt(world, {-5.0, 15.0});
  ASSERT_NE(left, nullptr);
  // Camera 1.5 m above the street centre, looking north (+y) at the left building.
  vio::CameraCalibration cam = downwardCamera("cam0", Eigen::Vector3d::Zero());
  cam.T_BS.topLeftCorner<3, 3>() = cameraMountRotation(false, Eigen::Vector3d::Zero());
  const double x0 = left->c.x();
  const StaticTrajectory traj({x0, 0.0, 1.5}, 0.5 * M_PI);  // body x (forward) north
  FeatureSimConfig fc;
  fc.maxPerImage = 100000;
  fc.pixelNoise = 0.0;
  fc.maxRange = 150.0;
  const FeatureSimulator fsim(cam, fc, world, 0.0);
  const auto obs = fsim.observe(traj, 0.0, 1);
  // Points of the street facade (y = 10) and of the back facade (y = 25) of that building.
  int front = 0, back = 0;
  for (const FeatureObservation& o : obs) {
    if (left->distance(o.p_W.head<2>()) > 1e-6) continue;
    if (std::abs(o.p_W.y() - 10.0) < 1e-6) ++front;
    if (std::abs(o.p_W.y() - 25.0) < 1e-6) ++back;
  }
  EXPECT_GT(front, 5);
  EXPECT_EQ(back, 0);
  // The back facade's points are in the image and in range: hidden only by the building.
  std::vector<Landmark> all;
  world.landmarks(Eigen::AlignedBox2d(Eigen::Vector2d(x0 - 15.0, 20.0), Eigen::Vector2d(x0 + 15.0, 30.0)), all);
  int backInView = 0;
  for (const Landmark& l : all) {
    if (std::abs(l.p_W.y() - 25.0) > 1e-6 || left->distance(l.p_W.head<2>()) > 1e-6) continue;
    Eigen::Vector2d px;
    if (fsim.project(traj, 0.0, l.p_W, px) && fsim.model().inImage(px, fc.border)) {
      ++backInView;
      EXPECT_TRUE(world.segmentBlocked({x0, 0.0, 1.5}, l.p_W));
    }
  }
  EXPECT_GT(backInView, 10);
  for (const FeatureObservation& o : obs) EXPECT_FALSE(world.segmentBlocked({x0, 0.0, 1.5}, o.p_W));
}

TEST(UrbanSignalPath, BlockedReflectedAndLineOfSightInACanyon) {
  const UrbanStructure world(canyon(), straightRoute(-200.0, 200.0), 7);
  const Eigen::Vector3d p(-5.0, 0.0, 1.5);
  ASSERT_NE(buildingAt(world, {-5.0, 15.0}), nullptr);
  ASSERT_NE(buildingAt(world, {-5.0, -15.0}), nullptr);
  const std::vector<int> near = buildingsNear(world, p);
  auto sat = [](double elDeg) {
    const double e = elDeg * M_PI / 180.0;
    return Eigen::Vector3d(0.0, std::cos(e), std::sin(e));  // north, across the street
  };
  // 10 deg: the direct ray meets the north facade 3.26 m up; the reflection point on the south
  // facade (3.26 m up) sees the satellite only through the north building (6.79 m < 20 m).
  EXPECT_EQ(urbanSignalPath(world, p, sat(10.0), near).kind, UrbanSignalPath::Kind::Blocked);
  // 45 deg: direct ray at 11.5 m on the north facade (blocked); reflection point 11.5 m up the
  // south facade, its ray clears the north roof at 31.5 m: extra path 2 * 10 * cos(45 deg).
  const UrbanSignalPath r = urbanSignalPath(world, p, sat(45.0), near);
  EXPECT_EQ(r.kind, UrbanSignalPath::Kind::Reflected);
  EXPECT_NEAR(r.extraPath, 2.0 * 10.0 * std::cos(M_PI / 4.0), 1e-9);
  // 70 deg: 1.5 + 10 tan(70 deg) = 29.0 m above the 20 m roof: line of sight.
  EXPECT_EQ(urbanSignalPath(world, p, sat(70.0), near).kind, UrbanSignalPath::Kind::LineOfSight);
  // Along the street (east) at 10 deg: nothing in the way.
  const Eigen::Vector3d east(std::cos(0.1745), 0.0, std::sin(0.1745));
  EXPECT_EQ(urbanSignalPath(world, p, east, near).kind, UrbanSignalPath::Kind::LineOfSight);
  // Multipath scale 1 + 2 exp(-d/8): 10 m from the facades vs. far from any.
  EXPECT_NEAR(urbanSignalPath(world, p, sat(70.0), near).multipathScale, 1.0 + 2.0 * std::exp(-10.0 / 8.0), 1e-9);
  EXPECT_NEAR(urbanSignalPath(world, {-5.0, 0.0, 1.5}, sat(70.0), {}).multipathScale, 1.0, 1e-12);
}

}  // namespace
}  // namespace gvins::sim
