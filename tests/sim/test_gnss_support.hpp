// Shared pieces of the GNSS simulator tests: a small analytic trajectory (a level circle flown
// with the nose along the track), the default place and time (the nagoya_static_2024 site on
// 2024-06-24 08:20 GPST) and the navigation file of that data set.
#pragma once

#include <cmath>
#include <filesystem>
#include <string>

#include <Eigen/Geometry>

#include "gvins/base/geodetic.hpp"
#include "gvins/ephemeris/rinex_nav.hpp"
#include "gvins/sim/local_frame.hpp"
#include "gvins/sim/trajectory.hpp"
#include "nagoya_recording.hpp"

namespace gvins::sim::testing {

inline std::filesystem::path dataDir() { return GVINS_TEST_DATA; }
inline std::filesystem::path navFile() { return dataDir() / "gnss" / "nagoya_static_2024" / "base.nav.gz"; }

inline const NavData& nagoyaNav() {
  static const NavData nav = readRinexNav(navFile().string());
  return nav;
}

/// 2024-06-24 08:20:00 GPST at the nagoya_static_2024 base antenna.
inline LocalFrame nagoyaFrame(double secondsAfter0820 = 0.0) {
  LocalFrame f;
  f.origin = geodeticFromDegrees(35.134707705, 136.977577939, 104.853);
  f.startTime = gvins::test::nagoyaTime(8, 20) + secondsAfter0820;
  return f;
}

/// A level circle of radius r (m) at height h above the origin, centred at (cx, cy), flown
/// counter-clockwise at speed v (m/s), body x along the velocity, z up; or a static point
/// when v = 0.
class CircleTrajectory final : public Trajectory {
 public:
  CircleTrajectory(double duration, double radius, double height, double speed, Eigen::Vector2d centre = {0.0, 0.0})
      : duration_(duration), r_(radius), h_(height), v_(speed), c_(centre) {}
  double duration() const override { return duration_; }
  TrajectoryState evaluate(double t) const override {
    t = std::clamp(t, 0.0, duration_);
    TrajectoryState s;
    s.t = t;
    const double w = r_ > 0.0 ? v_ / r_ : 0.0;
    const double a = w * t;
    s.p_WB = Eigen::Vector3d(c_.x() + r_ * std::cos(a), c_.y() + r_ * std::sin(a), h_);
    s.v_WB = Eigen::Vector3d(-r_ * w * std::sin(a), r_ * w * std::cos(a), 0.0);
    s.a_WB = Eigen::Vector3d(-r_ * w * w * std::cos(a), -r_ * w * w * std::sin(a), 0.0);
    s.R_WB = Eigen::AngleAxisd(a + 0.5 * M_PI, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    s.omega_B = Eigen::Vector3d(0.0, 0.0, w);
    return s;
  }

 private:
  double duration_, r_, h_, v_;
  Eigen::Vector2d c_;
};

}  // namespace gvins::sim::testing
