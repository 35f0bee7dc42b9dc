// CameraRenderer: the AVX2 kernel of the per-pixel loop gives the same pixels, bit for bit, as
// the scalar loop (same float operations in the same order, no FMA), for nadir and oblique views,
// rays that miss the ground (sky) or go beyond the range, every mip level from the finest
// (clamped at a low height) to the coarse ones, motion blur and a rolling shutter.
#include <gtest/gtest.h>

#include <cstring>
#include <memory>

#include <Eigen/Geometry>

#include "gvins/sim/camera_renderer.hpp"
#include "gvins/sim/dataset_generator.hpp"
#include "gvins/sim/scenario.hpp"

namespace gvins::sim {
namespace {

bool sameBits(const cv::Mat& a, const cv::Mat& b) {
  if (a.size() != b.size() || a.type() != b.type() || !a.isContinuous() || !b.isContinuous()) return false;
  return std::memcmp(a.data, b.data, a.total() * a.elemSize()) == 0;
}

TEST(CameraRenderer, VectorizedKernelGivesTheScalarPixelsBitForBit) {
  const Scenario sc = defaultScenario();
  const auto traj = buildTrajectory(sc, 1);
  GroundTextureConfig tc = sc.texture;
  const GroundTexture texture(tc);
  ImagingConfig rolling = sc.imaging;
  rolling.lineTime = 3e-5;
  ImagingConfig shortRange = sc.imaging;
  shortRange.maxRange = 45.0;  // cuts the view inside the image
  int compared = 0;
  for (const ImagingConfig* img : {&sc.imaging, static_cast<const ImagingConfig*>(&rolling), static_cast<const ImagingConfig*>(&shortRange)}) {
    CameraRenderer fast(sc.cameras[0], *img, texture), scalar(sc.cameras[0], *img, texture);
    scalar.setVectorized(false);
    for (double t : {1.0, 30.0, 61.3, 100.0}) {
      EXPECT_TRUE(sameBits(fast.render(*traj, t, 1.02, 5), scalar.render(*traj, t, 1.02, 5))) << "t " << t;
      ++compared;
    }
    // Fixed poses: nadir at 0.3 m (finest level, clamped), 40 m and 400 m; tilted 70 and 95 deg
    // (horizon and sky in the image).
    for (double height : {0.3, 40.0, 400.0})
      for (double tiltDeg : {0.0, 30.0, 70.0, 95.0}) {
        const Eigen::Matrix3d R_WC =
            (Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()) *
             Eigen::AngleAxisd(tiltDeg * M_PI / 180.0, Eigen::Vector3d::UnitX()))
                .toRotationMatrix();
        const Eigen::Vector3d p(12.3, -4.7, height);
        EXPECT_TRUE(sameBits(fast.renderRadiance(R_WC, p), scalar.renderRadiance(R_WC, p)))
            << "height " << height << " tilt " << tiltDeg;
        ++compared;
      }
  }
  EXPECT_EQ(compared, 48);
}

}  // namespace
}  // namespace gvins::sim
