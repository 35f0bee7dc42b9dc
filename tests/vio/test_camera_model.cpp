// Camera model: analytic Jacobians vs. central finite differences, undistortion round trips,
// and agreement with OpenCV's independent implementations (cv::projectPoints for
// radial-tangential, cv::fisheye::projectPoints for equidistant).
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include <opencv2/calib3d.hpp>

#include "gvins/vio/camera_model.hpp"

using namespace gvins::vio;

namespace {

// EuRoC V1 cam0 (mav0/cam0/sensor.yaml).
CameraIntrinsics eurocCam0() {
  CameraIntrinsics k;
  k.width = 752;
  k.height = 480;
  k.fx = 458.654;
  k.fy = 457.296;
  k.cx = 367.215;
  k.cy = 248.375;
  k.model = DistortionModel::RadialTangential;
  k.distortion = {-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05};
  return k;
}

// A 512x512 fisheye of the kind calibrated with Kalibr's pinhole-equidistant model.
CameraIntrinsics fisheye() {
  CameraIntrinsics k;
  k.width = 512;
  k.height = 512;
  k.fx = 190.98;
  k.fy = 190.97;
  k.cx = 254.93;
  k.cy = 256.90;
  k.model = DistortionModel::Equidistant;
  k.distortion = {0.00348, 0.000715, -0.00205, 0.000203};
  return k;
}

std::vector<Eigen::Vector3d> randomPoints(int n, double maxTan, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-maxTan, maxTan), depth(0.5, 20.0);
  std::vector<Eigen::Vector3d> pts;
  for (int i = 0; i < n; ++i) {
    const double z = depth(rng);
    pts.emplace_back(u(rng) * z, u(rng) * z, z);
  }
  return pts;
}

void checkProjectJacobian(const CameraModel& cam, const std::vector<Eigen::Vector3d>& pts) {
  double worst = 0.0;
  for (const auto& P : pts) {
    Eigen::Matrix<double, 2, 3> J;
    const auto px = cam.project(P, &J);
    ASSERT_TRUE(px.has_value());
    Eigen::Matrix<double, 2, 3> Jn;
    for (int k = 0; k < 3; ++k) {
      const double e = 1e-6 * std::max(1.0, std::abs(P[k]));
      Eigen::Vector3d a = P, b = P;
      a[k] += e;
      b[k] -= e;
      Jn.col(k) = (*cam.project(a) - *cam.project(b)) / (2 * e);
    }
    worst = std::max(worst, (J - Jn).norm() / Jn.norm());
  }
  EXPECT_LT(worst, 1e-7);
}

}  // namespace

TEST(CameraModel, RadTanProjectJacobianMatchesFiniteDifferences) {
  checkProjectJacobian(CameraModel(eurocCam0()), randomPoints(500, 0.8, 1));
}

TEST(CameraModel, EquidistantProjectJacobianMatchesFiniteDifferences) {
  // Up to ~72 degrees off-axis (tan = 3), and a point exactly on the optical axis.
  auto pts = randomPoints(500, 2.2, 2);
  pts.emplace_back(0.0, 0.0, 2.0);
  pts.emplace_back(1e-12, -2e-12, 1.0);
  checkProjectJacobian(CameraModel(fisheye()), pts);
}

TEST(CameraModel, NoDistortionIsPinhole) {
  CameraIntrinsics k = eurocCam0();
  k.model = DistortionModel::None;
  const CameraModel cam(k);
  const auto px = cam.project({0.2, -0.1, 2.0});
  ASSERT_TRUE(px);
  EXPECT_NEAR(px->x(), k.fx * 0.1 + k.cx, 1e-12);
  EXPECT_NEAR(px->y(), k.fy * -0.05 + k.cy, 1e-12);
  EXPECT_NEAR((cam.undistort(*px) - Eigen::Vector2d(0.1, -0.05)).norm(), 0.0, 1e-15);
}

TEST(CameraModel, RadTanAgreesWithOpenCvProjectPoints) {
  const CameraIntrinsics k = eurocCam0();
  const CameraModel cam(k);
  const auto pts = randomPoints(300, 0.8, 3);
  std::vector<cv::Point3d> obj;
  for (const auto& p : pts) obj.emplace_back(p.x(), p.y(), p.z());
  const cv::Matx33d K(k.fx, 0, k.cx, 0, k.fy, k.cy, 0, 0, 1);
  const std::vector<double> dist(k.distortion.begin(), k.distortion.end());
  std::vector<cv::Point2d> img;
  cv::projectPoints(obj, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, dist, img);
  double worst = 0.0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const auto px = cam.project(pts[i]);
    ASSERT_TRUE(px);
    worst = std::max(worst, (*px - Eigen::Vector2d(img[i].x, img[i].y)).norm());
  }
  EXPECT_LT(worst, 1e-9);
}

TEST(CameraModel, EquidistantAgreesWithOpenCvFisheye) {
  const CameraIntrinsics k = fisheye();
  const CameraModel cam(k);
  const auto pts = randomPoints(300, 2.2, 4);
  std::vector<cv::Point3d> obj;
  for (const auto& p : pts) obj.emplace_back(p.x(), p.y(), p.z());
  const cv::Matx33d K(k.fx, 0, k.cx, 0, k.fy, k.cy, 0, 0, 1);
  const cv::Vec4d D(k.distortion[0], k.distortion[1], k.distortion[2], k.distortion[3]);
  std::vector<cv::Point2d> img;
  cv::fisheye::projectPoints(obj, img, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, D);
  double worst = 0.0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const auto px = cam.project(pts[i]);
    ASSERT_TRUE(px);
    worst = std::max(worst, (*px - Eigen::Vector2d(img[i].x, img[i].y)).norm());
  }
  EXPECT_LT(worst, 1e-8);
}

// Every pixel of a dense grid over the image: undistort then re-project returns the pixel, and the
// undistortion Jacobian matches finite differences. For the fisheye only pixels up to 80 degrees
// off-axis (its image corners lie beyond 90 degrees, where a z > 0 pinhole ray does not exist).
void checkUndistortGrid(const CameraModel& cam, double maxRadiusPx = 1e9) {
  const auto& k = cam.intrinsics();
  double worstPx = 0.0, worstJ = 0.0;
  int n = 0;
  for (double y = 0; y <= k.height - 1; y += 7.9) {
    for (double x = 0; x <= k.width - 1; x += 7.9) {
      const Eigen::Vector2d px(x, y);
      if (std::hypot(x - k.cx, y - k.cy) > maxRadiusPx) continue;
      Eigen::Matrix2d J;
      const Eigen::Vector2d u = cam.undistort(px, &J);
      worstPx = std::max(worstPx, (cam.distortAndProject(u) - px).norm());
      Eigen::Matrix2d Jn;
      for (int c = 0; c < 2; ++c) {
        Eigen::Vector2d a = px, b = px;
        a[c] += 1e-3;
        b[c] -= 1e-3;
        Jn.col(c) = (cam.undistort(a) - cam.undistort(b)) / 2e-3;
      }
      worstJ = std::max(worstJ, (J - Jn).norm() / Jn.norm());
      ++n;
    }
  }
  EXPECT_GT(n, 2000);
  EXPECT_LT(worstPx, 1e-7);  // pixels; i.e. < 1e-9 in normalised units
  EXPECT_LT(worstJ, 1e-6);
}

TEST(CameraModel, RadTanUndistortRoundTripOverWholeImage) { checkUndistortGrid(CameraModel(eurocCam0())); }
TEST(CameraModel, EquidistantUndistortRoundTripOverWholeImage) {
  const CameraModel cam(fisheye());
  // Pixel radius of a ray 80 degrees off-axis.
  const double r80 = (*cam.project({std::tan(80.0 * M_PI / 180.0), 0.0, 1.0})).x() - cam.intrinsics().cx;
  EXPECT_GT(r80, 200.0);
  checkUndistortGrid(cam, r80);
}

TEST(CameraModel, RadTanUndistortAgreesWithOpenCvUndistortPoints) {
  const CameraIntrinsics k = eurocCam0();
  const CameraModel cam(k);
  std::vector<cv::Point2d> px;
  for (double y = 0; y < k.height; y += 40) {
    for (double x = 0; x < k.width; x += 40) px.emplace_back(x, y);
  }
  const cv::Matx33d K(k.fx, 0, k.cx, 0, k.fy, k.cy, 0, 0, 1);
  const std::vector<double> dist(k.distortion.begin(), k.distortion.end());
  std::vector<cv::Point2d> und;
  // OpenCV's default is 5 fixed-point iterations; ask for a converged answer.
  cv::undistortPoints(px, und, K, dist, cv::noArray(), cv::noArray(),
                          cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 200, 1e-14));
  double worst = 0.0;
  for (std::size_t i = 0; i < px.size(); ++i) {
    const Eigen::Vector2d u = cam.undistort({px[i].x, px[i].y});
    worst = std::max(worst, (u - Eigen::Vector2d(und[i].x, und[i].y)).norm());
  }
  EXPECT_LT(worst, 1e-8);
}

TEST(CameraModel, BehindCameraAndImageBounds) {
  const CameraModel cam(eurocCam0());
  EXPECT_FALSE(cam.project({0.1, 0.1, -1.0}).has_value());
  EXPECT_FALSE(cam.project({0.1, 0.1, 0.0}).has_value());
  EXPECT_TRUE(cam.inImage({0.0, 0.0}));
  EXPECT_TRUE(cam.inImage({751.0, 479.0}));
  EXPECT_FALSE(cam.inImage({751.5, 10.0}));
  EXPECT_FALSE(cam.inImage({5.0, 5.0}, 10.0));
  EXPECT_FALSE(cam.inImage({10.0, -0.1}));
  const Eigen::Vector3d b = cam.bearing({367.215, 248.375});
  EXPECT_NEAR(b.z(), 1.0, 1e-12);
}

TEST(CameraModel, RejectsInvalidIntrinsics) {
  CameraIntrinsics k = eurocCam0();
  k.fx = 0.0;
  EXPECT_THROW(CameraModel{k}, std::invalid_argument);
  k = eurocCam0();
  k.distortion[1] = std::nan("");
  EXPECT_THROW(CameraModel{k}, std::invalid_argument);
}
