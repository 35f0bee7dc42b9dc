// Rendered images of a short flight (written by generateDataset, read back from the PNG files)
// against the truth camera poses, with nothing of the simulator's own camera model: OpenCV's
// undistortion and projection of the sensor.yaml calibration only.
//
// 1. KLT: OpenCV's pyramidal Lucas-Kanade (cv::calcOpticalFlowPyrLK, corners from
//    cv::goodFeaturesToTrack, forward-backward check) keeps well over 100 features in every image,
//    and every tracked feature moves from image to image as the truth says (error of each
//    frame-to-frame step against the projection of the ground point under its previous pixel,
//    ray through cv::undistortPoints, cv::projectPoints).
// 2. The error of whole tracks against the ground point seen at detection grows with the track
//    age, about linearly (median below 0.05 px per image of age; measured 0.011-0.027): KLT's own
//    drift, not the images'. Measured (2026-12-01) on images rendered in memory (test 4 checks
//    the first two): hovering, tracks stay at 0.05 px RMS after 199 images; turning in place at
//    36 deg/s (the circle's yaw rate) they drift 0.76 px after 10 images, 2.7-2.9 px after 40, 11.6 px
//    after 199, while the same features matched from their detection image against the later
//    image warped back by the truth ground homography stay at 0.03-0.08 px RMS (up to 290 deg):
//    a translation-only 21x21 window on a patch that turns 1.8 deg per image settles off its
//    centre by a fraction of a pixel each step, always the same way. Flying straight at 6 m/s
//    without rotation, tracks drift 0.09 px after 10 images and 0.22 px after 40 with the default
//    vignetting (a brightness gradient KLT does not model) and 0.015 / 0.024 px without it.
//    The strict criterion "sub-pixel over the whole track" therefore holds only for young tracks
//    (the 1-19 image bin) and is not asserted for old ones.
// 3. Images far apart (up to 19 m and 174 deg) are the same ground: image a, undistorted and
//    warped into image b by the ground-plane homography of the truth poses, matches image b
//    patch by patch (phase correlation) to a tenth of a pixel; a 0.1 m pose error is detected.
// 4. The drift is the tracker's: a hover turning in place at 36 deg/s, rendered in memory with an
//    undistorted camera: chained KLT drifts by pixels, KLT from the detection image against each
//    later image warped back by the truth homography stays below 0.15 px at every age; hovering
//    without rotation, chained tracks do not drift.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <unistd.h>
#include <vector>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/core.hpp>
#include <opencv2/video/tracking.hpp>

#include <Eigen/Geometry>

#include "gvins/sim/camera_renderer.hpp"
#include "gvins/sim/dataset_generator.hpp"
#include "gvins/sim/scenario.hpp"
#include "gvins/vio/euroc_csv.hpp"
#include "gvins/vio/feature_tracker.hpp"
#include "gvins/vio/sensor_yaml.hpp"

namespace gvins::sim {
namespace {

namespace fs = std::filesystem;

struct Pose {
  Eigen::Matrix3d R_WC;
  Eigen::Vector3d p_WC;
};

std::map<std::int64_t, Pose> readPoses(const fs::path& p) {
  std::ifstream in(p);
  std::map<std::int64_t, Pose> out;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::stringstream ss(line);
    std::string cell;
    std::getline(ss, cell, ',');
    const std::int64_t t = std::stoll(cell);
    double v[7];
    for (double& x : v) {
      std::getline(ss, cell, ',');
      x = std::stod(cell);
    }
    out[t] = {Eigen::Quaterniond(v[3], v[4], v[5], v[6]).normalized().toRotationMatrix(), {v[0], v[1], v[2]}};
  }
  return out;
}

struct Track {
  cv::Point2f px;
  Eigen::Vector3d p_W;     ///< truth: the ground point seen at detection
  Eigen::Vector3d p_prev;  ///< truth: the ground point under the pixel of the previous image
  int age = 0;
};

struct Percentiles {
  double rms = 0, median = 0, p95 = 0, subPixelShare = 0;
};

Percentiles percentiles(std::vector<double> e) {
  Percentiles p;
  if (e.empty()) return p;
  double s2 = 0.0;
  for (double x : e) s2 += x * x;
  std::sort(e.begin(), e.end());
  p.rms = std::sqrt(s2 / static_cast<double>(e.size()));
  p.median = e[e.size() / 2];
  p.p95 = e[e.size() * 95 / 100];
  p.subPixelShare = static_cast<double>(std::lower_bound(e.begin(), e.end(), 1.0) - e.begin()) / static_cast<double>(e.size());
  return p;
}

struct KltResult {
  std::size_t images = 0, minTracked = 1u << 30, detected = 0, lost = 0;
  double meanTracked = 0.0;
  std::size_t minSubPixelStep = 1u << 30;   ///< per image: features whose last step is < 1 px off
  std::size_t minSubPixelTrack = 1u << 30;  ///< per image: features < 1 px off since detection
  std::vector<double> stepErrors, trackErrors;
  std::map<int, std::vector<double>> trackErrorsByAge;  ///< age bins of 20 images
};

class RenderedFlight : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // A short circle at 30 m and 6 m/s (about 92 px/s of image motion, yaw 36 deg/s) with the
    // default imaging model: motion blur, optical PSF, vignetting, gain jitter, shot and read noise.
    dir_ = new fs::path(fs::temp_directory_path() / ("gvins_sim_klt_" + std::to_string(::getpid())));
    fs::remove_all(*dir_);
    const Scenario sc = parseScenario(
        "name: klt_test\n"
        "trajectory: {pattern: circle, height_m: 30, length_m: 60, speed_mps: 6, laps: 1, takeoff_landing: false,\n"
        "             hover_start_s: 2, hover_end_s: 2, wobble_deg: 0.3}\n"
        "cameras: {list: [{}]}\n"
        "gnss: none\n",
        "klt_test.yaml");
    GenerationOptions opt;
    opt.seed = 21;
    opt.threads = 2;
    frames_ = generateDataset(sc, *dir_, opt).framesPerCamera;
  }
  static void TearDownTestSuite() {
    std::error_code ec;
    fs::remove_all(*dir_, ec);
    delete dir_;
    dir_ = nullptr;
    delete klt_;
    klt_ = nullptr;
  }
  void SetUp() override {
    ASSERT_GT(frames_, 200u);
    cam_ = *dir_ / "mav0" / "cam0";
    cal_ = vio::readCameraSensorYaml((cam_ / "sensor.yaml").string());
    frames = vio::readCameraCsv((cam_ / "data.csv").string());
    poses = readPoses(*dir_ / "truth" / "cam0_poses.csv");
    ASSERT_EQ(frames.size(), frames_);
    ASSERT_EQ(cal_.intrinsics.model, vio::DistortionModel::RadialTangential);  // OpenCV's (k1, k2, p1, p2)
    const auto& k = cal_.intrinsics;
    K = cv::Matx33d(k.fx, 0, k.cx, 0, k.fy, k.cy, 0, 0, 1);
    D = cv::Vec4d(k.distortion[0], k.distortion[1], k.distortion[2], k.distortion[3]);
  }
  cv::Mat image(const vio::CameraCsvEntry& f) const {
    return cv::imread((cam_ / "data" / f.filename).string(), cv::IMREAD_GRAYSCALE);
  }

  std::vector<cv::Point2d> project(const Pose& pose, const std::vector<Eigen::Vector3d>& pts) const {
    std::vector<cv::Point2d> px;
    if (pts.empty()) return px;
    const Eigen::Matrix3d R_CW = pose.R_WC.transpose();
    const Eigen::Vector3d t = -R_CW * pose.p_WC;
    cv::Mat R(3, 3, CV_64F), rvec, tvec(3, 1, CV_64F);
    for (int i = 0; i < 3; ++i) {
      tvec.at<double>(i) = t[i];
      for (int j = 0; j < 3; ++j) R.at<double>(i, j) = R_CW(i, j);
    }
    cv::Rodrigues(R, rvec);
    std::vector<cv::Point3d> obj;
    for (const Eigen::Vector3d& p : pts) obj.emplace_back(p.x(), p.y(), p.z());
    cv::projectPoints(obj, rvec, tvec, K, D, px);
    return px;
  }
  /// The ground point (z = 0) under a pixel.
  bool groundPoint(const Pose& pose, const cv::Point2f& p, Eigen::Vector3d& out) const {
    std::vector<cv::Point2f> in{p}, n;
    cv::undistortPoints(in, n, K, D);
    const Eigen::Vector3d d = pose.R_WC * Eigen::Vector3d(n[0].x, n[0].y, 1.0);
    if (d.z() > -1e-6) return false;
    out = pose.p_WC + (-pose.p_WC.z() / d.z()) * d;
    return true;
  }

  KltResult runKlt() const;
  /// runKlt() once for the test suite.
  const KltResult& klt() const {
    if (!klt_) klt_ = new KltResult(runKlt());
    return *klt_;
  }

  static fs::path* dir_;
  static std::size_t frames_;
  static KltResult* klt_;
  fs::path cam_;
  vio::CameraCalibration cal_;
  std::vector<vio::CameraCsvEntry> frames;
  std::map<std::int64_t, Pose> poses;
  cv::Matx33d K;
  cv::Vec4d D;
};

fs::path* RenderedFlight::dir_ = nullptr;
std::size_t RenderedFlight::frames_ = 0;
KltResult* RenderedFlight::klt_ = nullptr;

KltResult RenderedFlight::runKlt() const {
  KltResult res;
  const auto& k = cal_.intrinsics;
  std::vector<Track> tracks;
  cv::Mat prev;
  double sumTracked = 0.0;
  for (const auto& f : frames) {
    const cv::Mat img = image(f);
    if (img.empty() || img.cols != k.width) {
      ADD_FAILURE() << "unreadable image " << f.filename;
      return res;
    }
    const auto pose = poses.find(f.t_ns);
    if (pose == poses.end()) {
      ADD_FAILURE() << "no truth pose at " << f.t_ns;
      return res;
    }
    if (!prev.empty() && !tracks.empty()) {
      std::vector<cv::Point2f> p0, p1, back;
      for (const Track& t : tracks) p0.push_back(t.px);
      std::vector<unsigned char> st, stBack;
      std::vector<float> err;
      const cv::TermCriteria crit(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 30, 0.01);
      cv::calcOpticalFlowPyrLK(prev, img, p0, p1, st, err, cv::Size(21, 21), 3, crit);
      cv::calcOpticalFlowPyrLK(img, prev, p1, back, stBack, err, cv::Size(21, 21), 3, crit);
      std::vector<Track> kept;
      for (std::size_t i = 0; i < tracks.size(); ++i) {
        const bool inside = p1[i].x >= 10 && p1[i].y >= 10 && p1[i].x < k.width - 10 && p1[i].y < k.height - 10;
        if (!st[i] || !stBack[i] || !inside || cv::norm(back[i] - p0[i]) > 0.3) {
          ++res.lost;
          continue;
        }
        Track t = tracks[i];
        t.px = p1[i];
        ++t.age;
        kept.push_back(t);
      }
      tracks = std::move(kept);
      // Errors against the truth projections: of the last step and since detection.
      std::vector<Eigen::Vector3d> prevPts, detPts;
      for (const Track& t : tracks) {
        prevPts.push_back(t.p_prev);
        detPts.push_back(t.p_W);
      }
      const auto stepTruth = project(pose->second, prevPts);
      const auto trackTruth = project(pose->second, detPts);
      std::size_t subStep = 0, subTrack = 0;
      for (std::size_t i = 0; i < tracks.size(); ++i) {
        const double es = std::hypot(tracks[i].px.x - stepTruth[i].x, tracks[i].px.y - stepTruth[i].y);
        const double et = std::hypot(tracks[i].px.x - trackTruth[i].x, tracks[i].px.y - trackTruth[i].y);
        res.stepErrors.push_back(es);
        res.trackErrors.push_back(et);
        res.trackErrorsByAge[std::min(tracks[i].age / 20 * 20, 200)].push_back(et);
        subStep += es < 1.0;
        subTrack += et < 1.0;
      }
      res.minSubPixelStep = std::min(res.minSubPixelStep, subStep);
      res.minSubPixelTrack = std::min(res.minSubPixelTrack, subTrack);
      res.minTracked = std::min(res.minTracked, tracks.size());
      sumTracked += static_cast<double>(tracks.size());
      ++res.images;
    }
    // The ground point under each tracked pixel, for the next step.
    std::vector<Track> valid;
    for (Track& t : tracks)
      if (groundPoint(pose->second, t.px, t.p_prev)) valid.push_back(t);
    tracks = std::move(valid);
    // Top up to 200 features, 12 px apart from the tracked ones.
    if (tracks.size() < 200) {
      cv::Mat mask(img.size(), CV_8UC1, cv::Scalar(255));
      for (const Track& t : tracks) cv::circle(mask, t.px, 12, cv::Scalar(0), -1);
      std::vector<cv::Point2f> corners;
      cv::goodFeaturesToTrack(img, corners, static_cast<int>(250 - tracks.size()), 0.01, 12, mask, 5);
      for (const auto& c : corners) {
        if (c.x < 20 || c.y < 20 || c.x > k.width - 20 || c.y > k.height - 20) continue;
        Track t;
        t.px = c;
        if (!groundPoint(pose->second, c, t.p_W)) continue;
        t.p_prev = t.p_W;
        tracks.push_back(t);
        ++res.detected;
      }
    }
    prev = img;
  }
  res.meanTracked = sumTracked / static_cast<double>(std::max<std::size_t>(res.images, 1));
  const Percentiles s = percentiles(res.stepErrors), t = percentiles(res.trackErrors);
  std::printf("KLT over %zu images: %.1f tracked per image (min %zu), %zu detected, %zu lost\n", res.images,
              res.meanTracked, res.minTracked, res.detected, res.lost);
  std::printf("  frame-to-frame error: RMS %.3f px, median %.3f, 95 %% %.3f, %.2f %% below 1 px, min %zu per image below 1 px\n",
              s.rms, s.median, s.p95, 100.0 * s.subPixelShare, res.minSubPixelStep);
  std::printf("  error since detection: RMS %.3f px, median %.3f, 95 %% %.3f, %.2f %% below 1 px, min %zu per image below 1 px\n",
              t.rms, t.median, t.p95, 100.0 * t.subPixelShare, res.minSubPixelTrack);
  for (const auto& [age, e] : res.trackErrorsByAge) {
    const Percentiles a = percentiles(e);
    std::printf("    track age %3d-%3s images: %6zu errors, median %.3f px, 95 %% %.3f px\n", age == 0 ? 1 : age,
                age == 200 ? "" : std::to_string(age + 19).c_str(), e.size(), a.median, a.p95);
  }
  return res;
}

TEST_F(RenderedFlight, KltKeepsOverAHundredFeaturesWithSubPixelFrameToFrameError) {
  const KltResult& r = klt();
  ASSERT_GT(r.stepErrors.size(), 10000u);
  const Percentiles s = percentiles(r.stepErrors);
  EXPECT_GE(r.minTracked, 100u);
  EXPECT_GE(r.minSubPixelStep, 100u);
  EXPECT_LT(s.rms, 0.2);
  EXPECT_LT(s.p95, 0.4);
  EXPECT_GT(s.subPixelShare, 0.999);
}

// Whole tracks against their detection-time ground point. Measured on this flight (2026-12-01):
// RMS 6.7 px, 48 % below 1 px overall; by age bin (images) the median is 0.20 px (1-19, 95 %
// 1.0 px), 0.56 (20-39), 0.46 (40-59), 0.52 (60-79), 1.0 (80-99), 1.8 (100-119), 2.7 (120-139),
// 3.5 (140-159), 4.3 (160-179), 5.1 (180-199), 7.6 (200 and more): 0.011-0.027 px per image of
// age, KLT's drift under the 36 deg/s yaw (header, item 2, and test 4). Asserted: young tracks
// are sub-pixel, and no age bin drifts faster than 0.05 px per image.
TEST_F(RenderedFlight, KltWholeTrackDriftIsSubPixelWhenYoungAndGrowsAtMostLinearly) {
  const KltResult& r = klt();
  ASSERT_GT(r.trackErrors.size(), 10000u);
  ASSERT_GE(r.trackErrorsByAge.size(), 10u);
  for (const auto& [age, e] : r.trackErrorsByAge) {
    const Percentiles a = percentiles(e);
    if (age == 0) {
      EXPECT_LT(a.median, 0.3) << "ages 1-19";
      EXPECT_LT(a.p95, 1.5) << "ages 1-19";
      EXPECT_GT(a.subPixelShare, 0.9) << "ages 1-19";
      continue;
    }
    // The bin's middle age (the last bin: its first age).
    const double mid = age == 200 ? 200.0 : age + 9.5;
    EXPECT_LT(a.median / mid, 0.05) << "ages " << age << "+: median " << a.median << " px";
  }
}

TEST_F(RenderedFlight, ImagesAgreeWithTheTruthPosesThroughTheGroundHomography) {
  // Undistorted images (cv::undistort, same K) map the ground plane z = 0 by
  // H = K [r1 r2 t] with R_CW = [r1 r2 r3], t = -R_CW p_WC (Hartley & Zisserman, sec. 8.1.1), so
  // image a warped by H_b H_a^-1 must be image b wherever both see the ground. Local shifts by
  // phase correlation (cv::phaseCorrelate) on 64x64 patches with a Hann window.
  auto planeH = [&](const Pose& P) {
    const Eigen::Matrix3d Rcw = P.R_WC.transpose();
    Eigen::Matrix3d M;
    M.col(0) = Rcw.col(0);
    M.col(1) = Rcw.col(1);
    M.col(2) = -Rcw * P.p_WC;
    Eigen::Matrix3d Ke;
    Ke << K(0, 0), 0, K(0, 2), 0, K(1, 1), K(1, 2), 0, 0, 1;
    return Eigen::Matrix3d(Ke * M);
  };
  auto undistorted = [&](std::size_t i) {
    cv::Mat u, f;
    cv::undistort(image(frames[i]), u, K, D);
    u.convertTo(f, CV_32F);
    return f;
  };
  struct Shifts {
    std::size_t patches = 0;
    double median = 0, max = 0;
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  };
  cv::Mat hann;
  cv::createHanningWindow(hann, cv::Size(64, 64), CV_32F);
  auto compare = [&](const cv::Mat& A, const Pose& Pa, const cv::Mat& B, const Pose& Pb) {
    const Eigen::Matrix3d H = planeH(Pb) * planeH(Pa).inverse();
    cv::Mat Hc(3, 3, CV_64F);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) Hc.at<double>(r, c) = H(r, c);
    cv::Mat W;
    cv::warpPerspective(A, W, Hc, B.size(), cv::INTER_CUBIC, cv::BORDER_CONSTANT, cv::Scalar(-1));
    std::vector<double> norms;
    Shifts s;
    for (int y = 60; y + 64 < B.rows - 60; y += 64)
      for (int x = 60; x + 64 < B.cols - 60; x += 64) {
        const cv::Rect r(x, y, 64, 64);
        double mn = 0.0;
        cv::minMaxLoc(W(r), &mn);
        if (mn < 0.0) continue;  // outside image a
        const cv::Point2d d = cv::phaseCorrelate(W(r), B(r), hann);
        s.mean += Eigen::Vector2d(d.x, d.y);
        norms.push_back(std::hypot(d.x, d.y));
      }
    s.patches = norms.size();
    if (norms.empty()) return s;
    s.mean /= static_cast<double>(norms.size());
    std::sort(norms.begin(), norms.end());
    s.median = norms[norms.size() / 2];
    s.max = norms.back();
    return s;
  };
  const std::size_t a = 40;  // end of the hover at the start
  const cv::Mat A = undistorted(a);
  const Pose& Pa = poses.at(frames[a].t_ns);
  int pairs = 0;
  double worstMedian = 0.0, worstMean = 0.0, worstMax = 0.0, maxAngle = 0.0, maxBaseline = 0.0;
  for (std::size_t b : {41, 45, 60, 80, 100, 150, 200, 250, 300, 350}) {
    ASSERT_LT(b, frames.size());
    const Pose& Pb = poses.at(frames[b].t_ns);
    const Shifts s = compare(A, Pa, undistorted(b), Pb);
    const double angle = Eigen::AngleAxisd(Pa.R_WC.transpose() * Pb.R_WC).angle() * 180.0 / M_PI;
    const double baseline = (Pb.p_WC - Pa.p_WC).norm();
    std::printf("image %zu -> %zu (%.0f deg, %.1f m): %zu patches, mean shift (%.3f, %.3f) px, median |shift| %.3f, max %.3f\n",
                a, b, angle, baseline, s.patches, s.mean.x(), s.mean.y(), s.median, s.max);
    if (s.patches < 10) continue;
    ++pairs;
    worstMedian = std::max(worstMedian, s.median);
    worstMean = std::max(worstMean, s.mean.norm());
    worstMax = std::max(worstMax, s.max);
    maxAngle = std::max(maxAngle, angle);
    maxBaseline = std::max(maxBaseline, baseline);
  }
  EXPECT_GE(pairs, 9);
  EXPECT_GT(maxAngle, 150.0);
  EXPECT_GT(maxBaseline, 15.0);
  EXPECT_LT(worstMedian, 0.2);
  EXPECT_LT(worstMean, 0.05);
  EXPECT_LT(worstMax, 0.6);
  // The check sees a 10 cm error of the truth position (about 1.5 px at 30 m).
  Pose shifted = poses.at(frames[100].t_ns);
  shifted.p_WC.x() += 0.1;
  const Shifts wrong = compare(A, Pa, undistorted(100), shifted);
  std::printf("with the position of image 100 moved by 0.1 m: median |shift| %.3f px\n", wrong.median);
  EXPECT_GT(wrong.median, 1.0);
}

/// Hovering at 30 m, turning about the vertical at a constant rate.
class TurnInPlace : public Trajectory {
 public:
  explicit TurnInPlace(double yawRate) : yawRate_(yawRate) {}
  double duration() const override { return 30.0; }
  TrajectoryState evaluate(double t) const override {
    TrajectoryState s;
    s.t = t;
    s.p_WB = Eigen::Vector3d(3.0, 1.0, 30.0);
    s.R_WB = Eigen::AngleAxisd(0.4 + yawRate_ * t, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    s.omega_B = Eigen::Vector3d(0.0, 0.0, yawRate_);
    return s;
  }

 private:
  double yawRate_;
};

struct DriftByAge {
  std::map<int, std::vector<double>> chained, warped;  ///< errors (px) by track age
};

/// KLT as in RenderedFlight::runKlt on `frames` images rendered in memory (default imaging, an
/// undistorted copy of the default camera). Chained: the track against the projection of its
/// detection-time ground point. Warped: KLT from the detection image to the image warped back
/// into it by the truth ground homography (every 20th image), against the detection pixel.
DriftByAge trackInMemory(const Trajectory& traj, int frames) {
  const Scenario sc = defaultScenario();
  vio::CameraCalibration cal = sc.cameras[0];
  cal.intrinsics.model = vio::DistortionModel::None;
  cal.intrinsics.distortion = {0.0, 0.0, 0.0, 0.0};
  GroundTextureConfig tc = sc.texture;
  const GroundTexture texture(tc);
  const CameraRenderer r(cal, sc.imaging, texture);
  const auto& k = cal.intrinsics;
  Eigen::Matrix3d Ke;
  Ke << k.fx, 0, k.cx, 0, k.fy, k.cy, 0, 0, 1;
  auto planeH = [&](const Pose& P) {
    const Eigen::Matrix3d Rcw = P.R_WC.transpose();
    Eigen::Matrix3d M;
    M << Rcw.col(0), Rcw.col(1), -Rcw * P.p_WC;
    return Eigen::Matrix3d(Ke * M);
  };
  auto project = [&](const Pose& P, const Eigen::Vector3d& X) {
    const Eigen::Vector3d q = Ke * (P.R_WC.transpose() * (X - P.p_WC));
    return cv::Point2f(static_cast<float>(q.x() / q.z()), static_cast<float>(q.y() / q.z()));
  };
  auto ground = [&](const Pose& P, const cv::Point2f& px, Eigen::Vector3d& X) {
    const Eigen::Vector3d d = P.R_WC * Eigen::Vector3d((px.x - k.cx) / k.fx, (px.y - k.cy) / k.fy, 1.0);
    if (d.z() > -1e-6) return false;
    X = P.p_WC + (-P.p_WC.z() / d.z()) * d;
    return true;
  };
  struct T {
    cv::Point2f px, px0;
    Eigen::Vector3d p_W;
    int age = 0, det = 0;
  };
  DriftByAge out;
  std::vector<T> tracks;
  std::vector<cv::Mat> images;
  std::vector<Pose> poses;
  const cv::TermCriteria crit(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 30, 0.01);
  for (int f = 0; f < frames; ++f) {
    const double t = 0.5 + 0.05 * f;
    Pose P;
    r.cameraPose(traj.evaluate(t), P.R_WC, P.p_WC);
    images.push_back(r.render(traj, t, 1.0, 1000 + static_cast<std::uint64_t>(f)));
    poses.push_back(P);
    const cv::Mat& img = images.back();
    if (f > 0 && !tracks.empty()) {
      std::vector<cv::Point2f> p0, p1, back;
      for (const T& tr : tracks) p0.push_back(tr.px);
      std::vector<unsigned char> st, stBack;
      std::vector<float> err;
      cv::calcOpticalFlowPyrLK(images[static_cast<std::size_t>(f - 1)], img, p0, p1, st, err, cv::Size(21, 21), 3, crit);
      cv::calcOpticalFlowPyrLK(img, images[static_cast<std::size_t>(f - 1)], p1, back, stBack, err, cv::Size(21, 21), 3, crit);
      std::vector<T> kept;
      for (std::size_t i = 0; i < tracks.size(); ++i) {
        const bool inside = p1[i].x >= 10 && p1[i].y >= 10 && p1[i].x < k.width - 10 && p1[i].y < k.height - 10;
        if (!st[i] || !stBack[i] || !inside || cv::norm(back[i] - p0[i]) > 0.3) continue;
        T tr = tracks[i];
        tr.px = p1[i];
        ++tr.age;
        const cv::Point2f truth = project(P, tr.p_W);
        out.chained[tr.age].push_back(std::hypot(tr.px.x - truth.x, tr.px.y - truth.y));
        kept.push_back(tr);
      }
      tracks = std::move(kept);
      if (f % 20 == 0) {
        std::map<int, std::vector<std::size_t>> byDetection;
        for (std::size_t i = 0; i < tracks.size(); ++i) byDetection[tracks[i].det].push_back(i);
        for (const auto& [d, idx] : byDetection) {
          const Eigen::Matrix3d H = planeH(P) * planeH(poses[static_cast<std::size_t>(d)]).inverse();
          cv::Mat Hc(3, 3, CV_64F);
          for (int a = 0; a < 3; ++a)
            for (int b = 0; b < 3; ++b) Hc.at<double>(a, b) = H(a, b);
          cv::Mat W;
          cv::warpPerspective(img, W, Hc, img.size(), cv::INTER_CUBIC | cv::WARP_INVERSE_MAP);
          std::vector<cv::Point2f> a, g;
          for (std::size_t i : idx) a.push_back(tracks[i].px0);
          g = a;
          std::vector<unsigned char> st2;
          std::vector<float> e2;
          cv::calcOpticalFlowPyrLK(images[static_cast<std::size_t>(d)], W, a, g, st2, e2, cv::Size(21, 21), 0, crit,
                                   cv::OPTFLOW_USE_INITIAL_FLOW);
          for (std::size_t q = 0; q < idx.size(); ++q)
            if (st2[q]) out.warped[f - d].push_back(std::hypot(g[q].x - a[q].x, g[q].y - a[q].y));
        }
      }
    }
    if (tracks.size() < 200) {
      cv::Mat mask(img.size(), CV_8UC1, cv::Scalar(255));
      for (const T& tr : tracks) cv::circle(mask, tr.px, 12, cv::Scalar(0), -1);
      std::vector<cv::Point2f> corners;
      cv::goodFeaturesToTrack(img, corners, static_cast<int>(250 - tracks.size()), 0.01, 12, mask, 5);
      for (const auto& c : corners) {
        if (c.x < 20 || c.y < 20 || c.x > k.width - 20 || c.y > k.height - 20) continue;
        T tr;
        tr.px = tr.px0 = c;
        tr.det = f;
        if (ground(P, c, tr.p_W)) tracks.push_back(tr);
      }
    }
  }
  return out;
}

double rmsOf(const std::vector<double>& e) {
  double s2 = 0.0;
  for (double x : e) s2 += x * x;
  return e.empty() ? 0.0 : std::sqrt(s2 / static_cast<double>(e.size()));
}

TEST(RenderedDrift, TurningDriftIsKltsWhileTheImagesMatchTheTruthHomography) {
  // 36 deg/s, 1.8 deg per image; 80 images turn 144 deg.
  const TurnInPlace turn(36.0 * M_PI / 180.0);
  const DriftByAge d = trackInMemory(turn, 81);
  for (int age : {10, 40, 80}) {
    ASSERT_GT(d.chained.count(age), 0u);
    std::printf("turning: chained age %d: %zu tracks, RMS %.3f px\n", age, d.chained.at(age).size(), rmsOf(d.chained.at(age)));
  }
  EXPECT_GT(rmsOf(d.chained.at(40)), 1.5);  // measured 2.9 px
  ASSERT_GE(d.warped.size(), 4u);
  for (const auto& [age, e] : d.warped) {
    std::printf("turning: warped age %d: %zu tracks, RMS %.3f px\n", age, e.size(), rmsOf(e));
    if (e.size() < 20) continue;
    EXPECT_LT(rmsOf(e), 0.15) << "age " << age;  // measured 0.03-0.08 px
  }
  EXPECT_GT(d.warped.rbegin()->first, 60);
  // Hovering without rotation: no drift (measured 0.05 px RMS after 199 images).
  const TurnInPlace hover(0.0);
  const DriftByAge h = trackInMemory(hover, 41);
  ASSERT_GT(h.chained.count(40), 0u);
  std::printf("hovering: chained age 40: %zu tracks, RMS %.3f px\n", h.chained.at(40).size(), rmsOf(h.chained.at(40)));
  EXPECT_LT(rmsOf(h.chained.at(40)), 0.1);
}

}  // namespace
}  // namespace gvins::sim

namespace gvins::sim {
namespace {
/// Hovering at 30 m then climbing at `climb` m/s while turning about the vertical.
class TurnAndClimb : public Trajectory {
 public:
  TurnAndClimb(double yawRate, double climb) : yawRate_(yawRate), climb_(climb) {}
  double duration() const override { return 30.0; }
  TrajectoryState evaluate(double t) const override {
    TrajectoryState s;
    s.t = t;
    s.p_WB = Eigen::Vector3d(3.0, 1.0, 30.0 + climb_ * t);
    s.v_WB = Eigen::Vector3d(0.0, 0.0, climb_);
    s.R_WB = Eigen::AngleAxisd(0.4 + yawRate_ * t, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    s.omega_B = Eigen::Vector3d(0.0, 0.0, yawRate_);
    return s;
  }

 private:
  double yawRate_, climb_;
};

/// vio::FeatureTracker (the pipeline's tracker, gyro rotation hint from the truth poses) on
/// `frames` images rendered in memory with an undistorted camera: the error of every track
/// against the projection of the ground point under its detection pixel, by track age.
std::map<int, std::vector<double>> featureTrackerDrift(const Trajectory& traj, int frames, bool templates) {
  const Scenario sc = defaultScenario();
  vio::CameraCalibration cal = sc.cameras[0];
  cal.intrinsics.model = vio::DistortionModel::None;
  cal.intrinsics.distortion = {0.0, 0.0, 0.0, 0.0};
  const GroundTexture texture(sc.texture);
  const CameraRenderer r(cal, sc.imaging, texture);
  const auto& k = cal.intrinsics;
  vio::FeatureTrackerConfig cfg;
  cfg.alignTemplates = templates;
  cfg.maxTrackTravel = 0.0;  // no travel limit: the drift of old tracks is what is measured
  cfg.templateMaxTrackTravel = 0.0;
  vio::FeatureTracker tracker(vio::CameraModel(cal.intrinsics), cfg);
  std::map<std::uint64_t, Eigen::Vector3d> ground;
  std::map<int, std::vector<double>> byAge;
  Pose prev;
  for (int f = 0; f < frames; ++f) {
    const double t = 0.5 + 0.05 * f;
    Pose P;
    r.cameraPose(traj.evaluate(t), P.R_WC, P.p_WC);
    const vio::ImagePyramid pyr(r.render(traj, t, 1.0, 1000 + static_cast<std::uint64_t>(f)), cfg.klt);
    const Eigen::Matrix3d R_cur_prev = P.R_WC.transpose() * prev.R_WC;
    tracker.process(pyr, f > 0 ? &R_cur_prev : nullptr);
    prev = P;
    const auto& ids = tracker.ids();
    const auto& pts = tracker.points();
    for (std::size_t i = 0; i < ids.size(); ++i) {
      const int age = tracker.trackLengths()[i] - 1;
      if (age == 0) {
        const Eigen::Vector3d d = P.R_WC * Eigen::Vector3d((pts[i].x - k.cx) / k.fx, (pts[i].y - k.cy) / k.fy, 1.0);
        if (d.z() < -1e-6) ground[ids[i]] = P.p_WC + (-P.p_WC.z() / d.z()) * d;
        continue;
      }
      const auto g = ground.find(ids[i]);
      if (g == ground.end()) continue;
      const Eigen::Vector3d q = P.R_WC.transpose() * (g->second - P.p_WC);
      byAge[age].push_back(std::hypot(pts[i].x - (k.fx * q.x() / q.z() + k.cx), pts[i].y - (k.fy * q.y() / q.z() + k.cy)));
    }
  }
  return byAge;
}
}  // namespace

TEST(RenderedDrift, FeatureTrackerTemplatesRemoveTheChainedDrift) {
  // Turning at 36 deg/s (1.8 deg per image) while climbing 1 m/s (scale change 0.17 % per
  // image): plain chained KLT drifts by pixels, the template-aligned tracks stay sub-pixel at
  // every age.
  const TurnAndClimb motion(36.0 * M_PI / 180.0, 1.0);
  const auto plain = featureTrackerDrift(motion, 81, false);
  const auto aligned = featureTrackerDrift(motion, 81, true);
  for (int age : {1, 10, 40, 80}) {
    ASSERT_GT(plain.count(age), 0u);
    ASSERT_GT(aligned.count(age), 0u);
    std::printf("turn and climb, age %d: chained KLT %zu tracks RMS %.3f px; templates %zu tracks RMS %.3f px\n", age,
                plain.at(age).size(), rmsOf(plain.at(age)), aligned.at(age).size(), rmsOf(aligned.at(age)));
  }
  EXPECT_GT(rmsOf(plain.at(40)), 1.0);
  for (const auto& [age, e] : aligned) {
    if (e.size() < 20) continue;
    EXPECT_LT(rmsOf(e), 0.2) << "age " << age;
  }
  // Most tracks survive: the templates do not buy their accuracy by ending tracks.
  EXPECT_GT(aligned.at(40).size(), plain.at(40).size() * 8 / 10);
}

}  // namespace gvins::sim
