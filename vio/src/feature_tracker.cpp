#include "gvins/vio/feature_tracker.hpp"

#include <chrono>
#include <cmath>
#include <stdexcept>

#include <opencv2/calib3d.hpp>
#include <opencv2/video/tracking.hpp>

namespace gvins::vio {

namespace {
using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

template <class T>
void compact(std::vector<T>& v, const std::vector<unsigned char>& keep) {
  std::size_t j = 0;
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (keep[i]) v[j++] = v[i];
  }
  v.resize(j);
}
}  // namespace

ImagePyramid::ImagePyramid(const cv::Mat& gray, const KltParams& p) : image_(gray) {
  if (gray.empty() || gray.type() != CV_8UC1) throw std::invalid_argument("ImagePyramid: 8-bit gray image expected");
  cv::buildOpticalFlowPyramid(gray, levels_, cv::Size(p.window, p.window), p.levels, true);
}

void trackKlt(const ImagePyramid& from, const ImagePyramid& to, const std::vector<cv::Point2f>& pts,
              std::vector<cv::Point2f>& out, std::vector<unsigned char>& status, const KltParams& p,
              bool useGuess) {
  status.assign(pts.size(), 0);
  if (pts.empty()) {
    out.clear();
    return;
  }
  if (!useGuess) out = pts;
  const std::vector<cv::Point2f> predicted = out;
  const cv::Size win(p.window, p.window);
  const cv::TermCriteria term(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, p.iterations, p.epsilon);
  std::vector<unsigned char> st;
  std::vector<float> err;
  cv::calcOpticalFlowPyrLK(from.levels(), to.levels(), pts, out, st, err, win, p.levels, term,
                           cv::OPTFLOW_USE_INITIAL_FLOW);
  // Backward from the tracked positions. The backward pass starts where the inverse of the
  // prediction puts it (start + (tracked - predicted)), so it has to undo exactly what the
  // forward pass added to the prediction: starting it at the start point instead would let a
  // track in a flat or saturated area pass without moving.
  std::vector<cv::Point2f> back(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) back[i] = pts[i] + (out[i] - predicted[i]);
  std::vector<unsigned char> stBack;
  cv::calcOpticalFlowPyrLK(to.levels(), from.levels(), out, back, stBack, err, win, p.levels, term,
                           cv::OPTFLOW_USE_INITIAL_FLOW);
  const float maxFb2 = static_cast<float>(p.maxForwardBackward * p.maxForwardBackward);
  const float b = static_cast<float>(p.border);
  const float xMax = static_cast<float>(to.image().cols - 1) - b, yMax = static_cast<float>(to.image().rows - 1) - b;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    if (!st[i] || !stBack[i]) continue;
    const cv::Point2f d = back[i] - pts[i];
    if (d.x * d.x + d.y * d.y > maxFb2) continue;
    const cv::Point2f& q = out[i];
    if (!(q.x >= b && q.y >= b && q.x <= xMax && q.y <= yMax)) continue;
    status[i] = 1;
  }
}

FeatureTracker::FeatureTracker(const CameraModel& camera, const FeatureTrackerConfig& config)
    : cam_(camera), cfg_(config), detector_(config.grid) {}

void FeatureTracker::process(const ImagePyramid& image, const Eigen::Matrix3d* R_cur_prev, FrontendTiming* timing) {
  FrontendTiming local;
  FrontendTiming& tm = timing ? *timing : local;
  if (!prev_.empty() && !pts_.empty()) {
    auto t0 = Clock::now();
    std::vector<cv::Point2f> cur(pts_.size());
    bool guess = false;
    if (R_cur_prev) {
      guess = true;
      for (std::size_t i = 0; i < pts_.size(); ++i) {
        const Eigen::Vector3d b = *R_cur_prev * cam_.bearing({pts_[i].x, pts_[i].y});
        const auto px = cam_.project(b);
        cur[i] = px ? cv::Point2f(static_cast<float>(px->x()), static_cast<float>(px->y())) : pts_[i];
      }
    }
    std::vector<unsigned char> status;
    trackKlt(prev_, image, pts_, cur, status, cfg_.klt, guess);
    tm.tracking += msSince(t0);

    t0 = Clock::now();
    std::vector<cv::Point2f> before = pts_;
    compact(before, status);
    compact(cur, status);
    compact(ids_, status);
    compact(lengths_, status);
    if (cfg_.ransac && cur.size() >= 8) {
      // Undistorted points on a virtual pinhole with the camera's focal length, so that the
      // threshold is in pixels.
      const double f = cam_.intrinsics().fx;
      std::vector<cv::Point2f> a(cur.size()), c(cur.size());
      for (std::size_t i = 0; i < cur.size(); ++i) {
        const Eigen::Vector2d na = cam_.undistort({before[i].x, before[i].y}) * f;
        const Eigen::Vector2d nc = cam_.undistort({cur[i].x, cur[i].y}) * f;
        a[i] = cv::Point2f(static_cast<float>(na.x()), static_cast<float>(na.y()));
        c[i] = cv::Point2f(static_cast<float>(nc.x()), static_cast<float>(nc.y()));
      }
      std::vector<unsigned char> inlier;
      const cv::Mat F = cv::findFundamentalMat(a, c, cv::FM_RANSAC, cfg_.ransacThreshold, cfg_.ransacConfidence, inlier);
      // A degenerate configuration (no motion, pure rotation, planar) may give no F: keep all.
      if (!F.empty() && inlier.size() == cur.size()) {
        compact(before, inlier);
        compact(cur, inlier);
        compact(ids_, inlier);
        compact(lengths_, inlier);
      }
    }
    for (int& l : lengths_) ++l;
    pts_ = std::move(cur);
    prevPts_ = std::move(before);
    tm.ransac += msSince(t0);
  } else {
    prevPts_ = pts_;
  }

  const auto t0 = Clock::now();
  const std::size_t before = pts_.size();
  detector_.detect(image.image(), pts_);
  for (std::size_t i = before; i < pts_.size(); ++i) {
    ids_.push_back(nextId_++);
    lengths_.push_back(1);
    prevPts_.push_back(pts_[i]);
  }
  tm.detection += msSince(t0);
  prev_ = image;
}

}  // namespace gvins::vio
