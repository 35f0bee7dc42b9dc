#include "gvins/vio/frontend.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <stdexcept>

#include <Eigen/LU>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

namespace gvins::vio {

namespace {
using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}
double threadCpuMs() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
}
Eigen::Matrix4d inverse(const Eigen::Matrix4d& T) {
  Eigen::Matrix4d I = Eigen::Matrix4d::Identity();
  I.topLeftCorner<3, 3>() = T.topLeftCorner<3, 3>().transpose();
  I.topRightCorner<3, 1>() = -T.topLeftCorner<3, 3>().transpose() * T.topRightCorner<3, 1>();
  return I;
}
void checkImage(const cv::Mat& img, const CameraModel& cam, const char* which) {
  const auto& k = cam.intrinsics();
  if (img.type() != CV_8UC1 || img.cols != k.width || img.rows != k.height) {
    throw std::invalid_argument(std::string("StereoFrontend: ") + which + " image must be 8-bit gray " +
                                std::to_string(k.width) + "x" + std::to_string(k.height));
  }
}
}  // namespace

struct StereoFrontend::Impl {
  static FrontendConfig shared(FrontendConfig c) {
    c.stereo.klt.window = c.tracker.klt.window;
    c.stereo.klt.levels = c.tracker.klt.levels;
    return c;
  }
  FrontendConfig cfg;
  FeatureTracker tracker;
  std::optional<CameraModel> cam1;
  std::optional<StereoMatcher> matcher;
  cv::Ptr<cv::CLAHE> clahe, claheRight;
  std::uint64_t frames = 0;
  // Last cam1 pixel of each stereo-matched feature, for the next prediction, by increasing id
  // (the tracker keeps its ids sorted: survivors in order, new ones appended).
  std::vector<std::pair<std::uint64_t, cv::Point2f>> lastStereo, nextStereo;
  double medianDepth;
  // Buffers reused frame after frame (no fresh pages per frame). Two cam0 slots: the tracker
  // still holds the previous frame's pyramid while this frame's is built.
  cv::Mat equalized[2], equalizedRight;
  ImagePyramid leftPyr[2], rightPyr;
  std::vector<std::size_t> idx;
  std::vector<cv::Point2f> leftPts, rightPts;
  std::vector<unsigned char> status;
  std::vector<double> depths;

  Impl(const FrontendConfig& c, const CameraCalibration& c0, const CameraCalibration* c1)
      : cfg(shared(c)), tracker(CameraModel(c0.intrinsics), cfg.tracker), medianDepth(c.stereo.defaultDepth) {
    if (c1) {
      cam1.emplace(c1->intrinsics);
      // x_c1 = T_C1B T_BC0 x_c0.
      matcher.emplace(tracker.camera(), *cam1, inverse(c1->T_BS) * c0.T_BS, cfg.stereo);
    }
    if (c.equalize == Equalization::Clahe) {
      clahe = cv::createCLAHE(3.0, cv::Size(8, 8));
      claheRight = cv::createCLAHE(3.0, cv::Size(8, 8));
    }
  }
};

StereoFrontend::StereoFrontend(const FrontendConfig& config, const CameraCalibration& cam0, const CameraCalibration* cam1)
    : impl_(std::make_unique<Impl>(config, cam0, cam1)) {}
StereoFrontend::~StereoFrontend() = default;
StereoFrontend::StereoFrontend(StereoFrontend&&) noexcept = default;
StereoFrontend& StereoFrontend::operator=(StereoFrontend&&) noexcept = default;

const CameraModel& StereoFrontend::camera(int i) const {
  if (i == 0) return impl_->tracker.camera();
  if (i == 1 && impl_->cam1) return *impl_->cam1;
  throw std::out_of_range("StereoFrontend::camera");
}

bool StereoFrontend::stereo() const { return impl_->matcher.has_value() && impl_->cfg.useStereo; }

FeatureFrame StereoFrontend::process(std::int64_t t_ns, const cv::Mat& leftIn, const cv::Mat& rightIn,
                                     const Eigen::Matrix3d* R_cur_prev) {
  Impl& s = *impl_;
  const auto tStart = Clock::now();
  const double cpuStart = threadCpuMs();
  FeatureFrame out;
  out.t_ns = t_ns;
  out.index = s.frames++;
  const CameraModel& cam0 = s.tracker.camera();
  checkImage(leftIn, cam0, "cam0");
  const bool doStereo = stereo() && !rightIn.empty();
  if (doStereo) checkImage(rightIn, *s.cam1, "cam1");

  auto t0 = Clock::now();
  const std::size_t slot = out.index % 2;
  ImagePyramid& leftPyr = s.leftPyr[slot];
  // Equalisation and pyramid of each image, and the left image's smoothing for the templates:
  // the two images are independent, so they are prepared in parallel (OpenCV's thread pool).
  // cv::CLAHE keeps state per object: one per image side.
  auto prepare = [&](const cv::Mat& in, cv::Mat& eq, const cv::Ptr<cv::CLAHE>& clahe, ImagePyramid& pyr) {
    cv::Mat img = in;
    if (s.cfg.equalize == Equalization::Clahe) {
      clahe->apply(in, eq);
      img = eq;
    } else if (s.cfg.equalize == Equalization::Histogram) {
      cv::equalizeHist(in, eq);
      img = eq;
    }
    pyr.build(img, s.cfg.tracker.klt);
  };
  auto prepareLeft = [&] {
    prepare(leftIn, s.equalized[slot], s.clahe, leftPyr);
    s.tracker.prepareTemplates(leftPyr.image());
  };
  if (doStereo) {
    cv::parallel_for_(cv::Range(0, 2), [&](const cv::Range& r) {
      for (int i = r.start; i < r.end; ++i) {
        if (i == 0) {
          prepareLeft();
        } else {
          prepare(rightIn, s.equalizedRight, s.claheRight, s.rightPyr);
        }
      }
    });
  } else {
    prepareLeft();
  }
  out.timing.pyramid = msSince(t0);

  s.tracker.process(leftPyr, R_cur_prev, &out.timing);
  const auto& pts = s.tracker.points();
  const auto& prevPts = s.tracker.previousPoints();
  const auto& ids = s.tracker.ids();
  const auto& lengths = s.tracker.trackLengths();

  out.features.resize(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) {
    FeatureObservation& f = out.features[i];
    f.id = ids[i];
    f.trackLength = lengths[i];
    f.pixel0 = {pts[i].x, pts[i].y};
    f.normalized0 = cam0.undistort(f.pixel0);
  }

  if (doStereo) {
    t0 = Clock::now();
    // Features matched last frame start from that match moved by the left motion; new ones from
    // the median stereo depth. Features whose match failed before (occluded in cam1, out of its
    // view) are retried only every kRetry-th frame: failing matches cost the most (every pyramid
    // level runs to the iteration limit).
    constexpr std::uint64_t kRetry = 3;
    s.idx.clear();
    s.leftPts.clear();
    s.rightPts.clear();
    std::size_t j = 0;  // merge walk: ids and lastStereo both increase
    for (std::size_t i = 0; i < pts.size(); ++i) {
      while (j < s.lastStereo.size() && s.lastStereo[j].first < ids[i]) ++j;
      const bool prior = j < s.lastStereo.size() && s.lastStereo[j].first == ids[i] && lengths[i] > 1;
      if (!prior && lengths[i] > 1 && (out.index + ids[i]) % kRetry != 0) continue;
      s.idx.push_back(i);
      s.leftPts.push_back(pts[i]);
      s.rightPts.push_back(prior ? s.lastStereo[j].second + (pts[i] - prevPts[i]) : cv::Point2f(std::nanf(""), 0.f));
    }
    s.matcher->match(leftPyr, s.rightPyr, s.leftPts, s.rightPts, s.status, s.medianDepth);
    s.nextStereo.clear();
    s.depths.clear();
    for (std::size_t k = 0; k < s.idx.size(); ++k) {
      if (!s.status[k]) continue;
      const std::size_t i = s.idx[k];
      FeatureObservation& f = out.features[i];
      f.stereo = true;
      f.pixel1 = {s.rightPts[k].x, s.rightPts[k].y};
      f.normalized1 = s.cam1->undistort(f.pixel1);
      s.nextStereo.emplace_back(ids[i], s.rightPts[k]);
      if (const auto z = s.matcher->depth(f.normalized0, f.normalized1)) s.depths.push_back(*z);
    }
    std::swap(s.lastStereo, s.nextStereo);
    if (!s.depths.empty()) {
      auto& d = s.depths;
      std::nth_element(d.begin(), d.begin() + static_cast<long>(d.size() / 2), d.end());
      s.medianDepth = d[d.size() / 2];
    }
    out.timing.stereo = msSince(t0);
  }
  out.timing.total = msSince(tStart);
  out.timing.cpu = threadCpuMs() - cpuStart;
  return out;
}

}  // namespace gvins::vio
