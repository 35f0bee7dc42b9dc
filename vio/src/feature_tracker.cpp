#include "gvins/vio/feature_tracker.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <utility>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
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
    if (keep[i]) {
      if (j != i) v[j] = std::move(v[i]);
      ++j;
    }
  }
  v.resize(j);
}
}  // namespace

ImagePyramid::ImagePyramid(const cv::Mat& gray, const KltParams& p) { build(gray, p); }

void ImagePyramid::build(const cv::Mat& gray, const KltParams& p) {
  if (gray.empty() || gray.type() != CV_8UC1) throw std::invalid_argument("ImagePyramid: 8-bit gray image expected");
  // cv::Mat::create (inside buildOpticalFlowPyramid) keeps a buffer of the right size even if it
  // is shared: drop the ones another ImagePyramid still uses, keep the rest.
  for (cv::Mat& m : levels_) {
    if (m.u && m.u->refcount > 1) m.release();
  }
  image_ = gray;
  cv::buildOpticalFlowPyramid(gray, levels_, cv::Size(p.window, p.window), p.levels, true);
}

void trackKlt(const ImagePyramid& from, const ImagePyramid& to, const std::vector<cv::Point2f>& pts,
              std::vector<cv::Point2f>& out, std::vector<unsigned char>& status, const KltParams& p,
              bool useGuess, const std::vector<unsigned char>* backward) {
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
  // No error output: OpenCV then skips the extra pass over each window at the image level.
  cv::calcOpticalFlowPyrLK(from.levels(), to.levels(), pts, out, st, cv::noArray(), win, p.levels, term,
                           cv::OPTFLOW_USE_INITIAL_FLOW);
  // Backward from the tracked positions, only for points that tracked forward into the border.
  // The backward pass starts where the inverse of the prediction puts it (start + (tracked -
  // predicted)), so it has to undo exactly what the forward pass added to the prediction:
  // starting it at the start point instead would let a track in a flat or saturated area pass
  // without moving.
  const float b = static_cast<float>(p.border);
  const float xMax = static_cast<float>(to.image().cols - 1) - b, yMax = static_cast<float>(to.image().rows - 1) - b;
  std::vector<std::size_t> idx;
  std::vector<cv::Point2f> fwd, back;
  idx.reserve(pts.size());
  fwd.reserve(pts.size());
  back.reserve(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const cv::Point2f& q = out[i];
    if (!st[i] || !(q.x >= b && q.y >= b && q.x <= xMax && q.y <= yMax)) continue;
    if (backward && !(*backward)[i]) {
      status[i] = 1;
      continue;
    }
    idx.push_back(i);
    fwd.push_back(q);
    back.push_back(pts[i] + (q - predicted[i]));
  }
  if (idx.empty()) return;
  std::vector<unsigned char> stBack;
  cv::calcOpticalFlowPyrLK(to.levels(), from.levels(), fwd, back, stBack, cv::noArray(), win, p.levels, term,
                           cv::OPTFLOW_USE_INITIAL_FLOW);
  const float maxFb2 = static_cast<float>(p.maxForwardBackward * p.maxForwardBackward);
  for (std::size_t k = 0; k < idx.size(); ++k) {
    if (!stBack[k]) continue;
    const cv::Point2f d = back[k] - pts[idx[k]];
    if (d.x * d.x + d.y * d.y > maxFb2) continue;
    status[idx[k]] = 1;
  }
}

FeatureTracker::FeatureTracker(const CameraModel& camera, const FeatureTrackerConfig& config)
    : cam_(camera), cfg_(config), detector_(config.grid) {}

void FeatureTracker::prepareTemplates(const cv::Mat& image) {
  if (!cfg_.alignTemplates) return;
  if (cfg_.patchSmoothing > 0.0) {
    cv::GaussianBlur(image, smooth_, cv::Size(0, 0), cfg_.patchSmoothing);
  } else {
    smooth_ = image;
  }
  smoothOf_ = image.data;
}

void FeatureTracker::process(const ImagePyramid& image, const Eigen::Matrix3d* R_cur_prev, FrontendTiming* timing) {
  FrontendTiming local;
  FrontendTiming& tm = timing ? *timing : local;
  if (cfg_.alignTemplates && smoothOf_ != image.image().data) {
    const auto ts = Clock::now();
    prepareTemplates(image.image());
    tm.tracking += msSince(ts);
  }
  smoothOf_ = nullptr;
  if (!prev_.empty() && !pts_.empty()) {
    // 1. KLT from the previous image.
    auto t0 = Clock::now();
    std::vector<cv::Point2f> cur;
    std::vector<unsigned char> status;
    trackAll(image, R_cur_prev, cur, status);
    tm.tracking += msSince(t0);

    t0 = Clock::now();
    std::vector<cv::Point2f> before = pts_;
    keepTracks(before, cur, status);
    // 2. Template refinement, 3. RANSAC on the epipolar geometry, 4. track length and travel.
    if (cfg_.alignTemplates) {
      const auto ta = Clock::now();
      keepTracks(before, cur, alignTemplates(before, cur, R_cur_prev));
      tm.tracking += msSince(ta);
    }
    if (cfg_.ransac && cur.size() >= 8) {
      std::vector<unsigned char> inlier;
      if (epipolarInliers(before, cur, inlier)) keepTracks(before, cur, inlier);
    }
    for (int& l : lengths_) ++l;
    for (std::size_t i = 0; i < cur.size(); ++i) {
      const float dx = cur[i].x - before[i].x, dy = cur[i].y - before[i].y;
      travel_[i] += std::sqrt(dx * dx + dy * dy);
    }
    if (cfg_.maxTrackLength > 0 || cfg_.maxTrackTravel > 0.0 || cfg_.templateMaxTrackTravel > 0.0) {
      std::vector<unsigned char> keep(lengths_.size());
      bool any = false;
      for (std::size_t i = 0; i < keep.size(); ++i) {
        const double maxTravel = templates_[i].empty() ? cfg_.maxTrackTravel : cfg_.templateMaxTrackTravel;
        keep[i] = (cfg_.maxTrackLength <= 0 || lengths_[i] <= cfg_.maxTrackLength) &&
                  (maxTravel <= 0.0 || lengths_[i] < cfg_.travelMinTrackLength || travel_[i] <= maxTravel);
        any |= !keep[i];
      }
      if (any) keepTracks(before, cur, keep);
    }
    pts_ = std::move(cur);
    prevPts_ = std::move(before);
    tm.ransac += msSince(t0);
  } else {
    prevPts_ = pts_;
  }

  // 5. New features in the empty cells.
  const auto t0 = Clock::now();
  const std::size_t before = pts_.size();
  detector_.detect(image.image(), pts_);
  for (std::size_t i = before; i < pts_.size(); ++i) {
    ids_.push_back(nextId_++);
    lengths_.push_back(1);
    travel_.push_back(0.0f);
    prevPts_.push_back(pts_[i]);
    templates_.emplace_back();
    warps_.emplace_back();
    if (cfg_.alignTemplates) templates_.back().extract(smooth_, pts_[i], cfg_.patch);  // stays empty if it fails
    warps_.back().t = Eigen::Vector2f(pts_[i].x, pts_[i].y);
  }
  tm.detection += msSince(t0);
  prev_ = image;
}

void FeatureTracker::keepTracks(std::vector<cv::Point2f>& before, std::vector<cv::Point2f>& cur,
                                const std::vector<unsigned char>& keep) {
  compact(before, keep);
  compact(cur, keep);
  compact(ids_, keep);
  compact(lengths_, keep);
  compact(travel_, keep);
  compact(templates_, keep);
  compact(warps_, keep);
}

unsigned char FeatureTracker::needsBackwardCheck(std::size_t i) const {
  return !(cfg_.alignTemplates && cfg_.templatesReplaceBackwardCheck && !templates_[i].empty());
}

void FeatureTracker::trackAll(const ImagePyramid& image, const Eigen::Matrix3d* R_cur_prev,
                              std::vector<cv::Point2f>& cur, std::vector<unsigned char>& status) const {
  const std::size_t n = pts_.size();
  // Unpredicted start: the rotation-predicted pixel with a gyro rotation, else the previous
  // position (trackKlt's default).
  std::vector<cv::Point2f> start = pts_;
  if (R_cur_prev) {
    for (std::size_t i = 0; i < n; ++i) {
      const Eigen::Vector3d b = *R_cur_prev * cam_.bearing({pts_[i].x, pts_[i].y});
      const auto px = cam_.project(b);
      if (px) start[i] = cv::Point2f(static_cast<float>(px->x()), static_cast<float>(px->y()));
    }
  }
  cur = start;
  status.assign(n, 0);
  // First pass: the tracks with a prediction through the shallow pyramid.
  if (cfg_.predictedLevels >= 0 && cfg_.predictedLevels < cfg_.klt.levels) {
    trackPredicted(image, R_cur_prev, start, cur, status);
  }
  // The others (no prediction, or failed above) from the unpredicted start through the whole
  // pyramid. Tracks refined against their template later are verified there (correlation and
  // correction limits); the KLT backward pass is only for the others.
  std::vector<std::size_t> idx;
  std::vector<cv::Point2f> from, to;
  std::vector<unsigned char> backward;
  for (std::size_t i = 0; i < n; ++i) {
    if (status[i]) continue;
    idx.push_back(i);
    from.push_back(pts_[i]);
    to.push_back(start[i]);
    backward.push_back(needsBackwardCheck(i));
  }
  if (!idx.empty()) {
    std::vector<unsigned char> st;
    trackKlt(prev_, image, from, to, st, cfg_.klt, R_cur_prev != nullptr, &backward);
    for (std::size_t k = 0; k < idx.size(); ++k) {
      cur[idx[k]] = to[k];
      status[idx[k]] = st[k];
    }
  }
}

void FeatureTracker::trackPredicted(const ImagePyramid& image, const Eigen::Matrix3d* R_cur_prev,
                                    const std::vector<cv::Point2f>& start, std::vector<cv::Point2f>& cur,
                                    std::vector<unsigned char>& status) const {
  const std::size_t n = pts_.size();
  std::vector<std::size_t> idx;
  std::vector<cv::Point2f> from, to, predicted;
  std::vector<unsigned char> backward;
  // With a rotation every track has its prediction. Without, tracks continue their last
  // image step (constant image motion); new ones take the median step of those when there
  // are enough of them, else they have no prediction.
  cv::Point2f median(0.f, 0.f);
  bool haveMedian = R_cur_prev != nullptr;
  if (!R_cur_prev) {
    std::vector<float> dx, dy;
    dx.reserve(n);
    dy.reserve(n);
    for (std::size_t i = 0; i < n; ++i) {
      if (lengths_[i] < 2) continue;
      dx.push_back(pts_[i].x - prevPts_[i].x);
      dy.push_back(pts_[i].y - prevPts_[i].y);
    }
    constexpr std::size_t kMinForMedian = 8;
    if (dx.size() >= kMinForMedian) {
      const auto mid = static_cast<std::ptrdiff_t>(dx.size() / 2);
      std::nth_element(dx.begin(), dx.begin() + mid, dx.end());
      std::nth_element(dy.begin(), dy.begin() + mid, dy.end());
      median = {dx[static_cast<std::size_t>(mid)], dy[static_cast<std::size_t>(mid)]};
      haveMedian = true;
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (R_cur_prev) {
      to.push_back(start[i]);
    } else if (lengths_[i] >= 2) {
      to.push_back(pts_[i] + (pts_[i] - prevPts_[i]));
    } else if (haveMedian) {
      to.push_back(pts_[i] + median);
    } else {
      continue;
    }
    idx.push_back(i);
    from.push_back(pts_[i]);
    backward.push_back(needsBackwardCheck(i));
  }
  if (idx.empty()) return;
  predicted = to;
  KltParams p = cfg_.klt;
  p.levels = cfg_.predictedLevels;
  std::vector<unsigned char> st;
  trackKlt(prev_, image, from, to, st, p, true, &backward);
  // A shallow pyramid can settle on a wrong but forward-backward consistent match far from
  // its start: only small corrections of the prediction are accepted.
  const float maxCorr2 = static_cast<float>(cfg_.predictedMaxCorrection * cfg_.predictedMaxCorrection);
  for (std::size_t k = 0; k < idx.size(); ++k) {
    const cv::Point2f d = to[k] - predicted[k];
    if (!st[k] || d.x * d.x + d.y * d.y > maxCorr2) continue;
    cur[idx[k]] = to[k];
    status[idx[k]] = 1;
  }
}

std::vector<unsigned char> FeatureTracker::alignTemplates(const std::vector<cv::Point2f>& before,
                                                          std::vector<cv::Point2f>& cur,
                                                          const Eigen::Matrix3d* R_cur_prev) {
  const float maxCorr2 = static_cast<float>(cfg_.templateMaxCorrection * cfg_.templateMaxCorrection);
  std::vector<unsigned char> aligned(cur.size(), 1);
  for (std::size_t i = 0; i < cur.size(); ++i) {
    if (templates_[i].empty()) continue;
    AffineWarp w = warps_[i];
    if (R_cur_prev) {
      // The rotation's local image Jacobian at the previous position turns the patch shape.
      const auto moved = [&](float du, float dv) -> std::optional<Eigen::Vector2d> {
        const Eigen::Vector3d b = *R_cur_prev * cam_.bearing({before[i].x + du, before[i].y + dv});
        return cam_.project(b);
      };
      const auto px = moved(1.f, 0.f), mx = moved(-1.f, 0.f), py = moved(0.f, 1.f), my = moved(0.f, -1.f);
      if (px && mx && py && my) {
        Eigen::Matrix2f J;
        J.col(0) = (0.5 * (*px - *mx)).cast<float>();
        J.col(1) = (0.5 * (*py - *my)).cast<float>();
        w.A = J * w.A;
      }
    }
    w.t = Eigen::Vector2f(cur[i].x, cur[i].y);
    const PatchAlignResult r = templates_[i].align(smooth_, w, cfg_.patch);
    const float dx = w.t.x() - cur[i].x, dy = w.t.y() - cur[i].y;
    if (!r.ok || dx * dx + dy * dy > maxCorr2) {
      aligned[i] = 0;
      continue;
    }
    cur[i] = cv::Point2f(w.t.x(), w.t.y());
    warps_[i] = w;
  }
  return aligned;
}

bool FeatureTracker::epipolarInliers(const std::vector<cv::Point2f>& before, const std::vector<cv::Point2f>& cur,
                                     std::vector<unsigned char>& inlier) const {
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
  const cv::Mat F = cv::findFundamentalMat(a, c, cv::FM_RANSAC, cfg_.ransacThreshold, cfg_.ransacConfidence, inlier);
  // A degenerate configuration (no motion, pure rotation, planar) may give no F: keep all.
  return !F.empty() && inlier.size() == cur.size();
}

}  // namespace gvins::vio
