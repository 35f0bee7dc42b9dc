#include "gvins/vio/feature_detector.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

namespace gvins::vio {

namespace {

// Spatial hash with cells of the minimum distance: a point conflicts only with points in the
// 3x3 neighbouring cells.
class Occupancy {
 public:
  Occupancy(int width, int height, double minDist)
      : cell_(std::max(1.0, minDist)), min2_(minDist * minDist),
        cols_(static_cast<int>(std::ceil(width / cell_)) + 1), rows_(static_cast<int>(std::ceil(height / cell_)) + 1),
        bins_(static_cast<std::size_t>(cols_ * rows_)) {}

  bool free(const cv::Point2f& p) const {
    const int cx = col(p.x), cy = row(p.y);
    for (int y = std::max(0, cy - 1); y <= std::min(rows_ - 1, cy + 1); ++y) {
      for (int x = std::max(0, cx - 1); x <= std::min(cols_ - 1, cx + 1); ++x) {
        for (const cv::Point2f& q : bins_[static_cast<std::size_t>(y * cols_ + x)]) {
          const float dx = p.x - q.x, dy = p.y - q.y;
          if (dx * dx + dy * dy < min2_) return false;
        }
      }
    }
    return true;
  }
  void add(const cv::Point2f& p) { bins_[static_cast<std::size_t>(row(p.y) * cols_ + col(p.x))].push_back(p); }

 private:
  int col(float x) const { return std::clamp(static_cast<int>(x / cell_), 0, cols_ - 1); }
  int row(float y) const { return std::clamp(static_cast<int>(y / cell_), 0, rows_ - 1); }
  double cell_, min2_;
  int cols_, rows_;
  std::vector<std::vector<cv::Point2f>> bins_;
};

struct Cell {
  cv::Rect rect;
  int existing = 0;
  std::vector<cv::Point2f> candidates;  // strongest first
  std::size_t next = 0;
  int added = 0;
  bool searched = false;
};

}  // namespace

GridDetector::GridDetector(const GridDetectorConfig& c) : cfg_(c) {
  if (c.maxFeatures < 1 || c.gridCols < 1 || c.gridRows < 1 || c.minDistance < 0.0 || c.border < 0 ||
      c.fastThreshold < 1 || c.fastMinThreshold < 1) {
    throw std::invalid_argument("GridDetector: invalid configuration");
  }
}

int GridDetector::detect(const cv::Mat& image, std::vector<cv::Point2f>& points) const {
  if (image.empty() || image.type() != CV_8UC1) throw std::invalid_argument("GridDetector: 8-bit gray image expected");
  const int total = static_cast<int>(points.size());
  if (total >= cfg_.maxFeatures) return 0;
  const int W = image.cols, H = image.rows, b = cfg_.border;
  if (W <= 2 * b + 8 || H <= 2 * b + 8) return 0;

  Occupancy occ(W, H, cfg_.minDistance);
  const int nCells = cfg_.gridCols * cfg_.gridRows;
  const int quota = (cfg_.maxFeatures + nCells - 1) / nCells;
  std::vector<Cell> cells(static_cast<std::size_t>(nCells));
  for (int r = 0; r < cfg_.gridRows; ++r) {
    for (int c = 0; c < cfg_.gridCols; ++c) {
      const int x0 = b + (W - 2 * b) * c / cfg_.gridCols, x1 = b + (W - 2 * b) * (c + 1) / cfg_.gridCols;
      const int y0 = b + (H - 2 * b) * r / cfg_.gridRows, y1 = b + (H - 2 * b) * (r + 1) / cfg_.gridRows;
      cells[static_cast<std::size_t>(r * cfg_.gridCols + c)].rect = cv::Rect(x0, y0, x1 - x0, y1 - y0);
    }
  }
  auto cellOf = [&](const cv::Point2f& p) -> Cell* {
    const int c = static_cast<int>((p.x - b) * cfg_.gridCols / (W - 2 * b));
    const int r = static_cast<int>((p.y - b) * cfg_.gridRows / (H - 2 * b));
    if (c < 0 || r < 0 || c >= cfg_.gridCols || r >= cfg_.gridRows) return nullptr;
    return &cells[static_cast<std::size_t>(r * cfg_.gridCols + c)];
  };
  for (const auto& p : points) {
    occ.add(p);
    if (Cell* cell = cellOf(p)) ++cell->existing;
  }

  // Candidates of a cell that still has room, computed when the round-robin first reaches it.
  const cv::Rect imageRect(0, 0, W, H);
  std::vector<cv::KeyPoint> kps;
  auto findCandidates = [&](Cell& cell) {
    cell.searched = true;
    const int need = quota - cell.existing;
    if (need <= 0) return;
    // FAST needs a 3-pixel ring: search a slightly larger window, keep corners inside the cell.
    const cv::Rect roi = (cell.rect + cv::Size(6, 6) - cv::Point(3, 3)) & imageRect;
    const cv::Mat sub = image(roi);
    if (cfg_.detector == CornerDetector::Fast) {
      for (int thr = cfg_.fastThreshold;; thr = std::max(cfg_.fastMinThreshold, thr / 2)) {
        kps.clear();
        cv::FAST(sub, kps, thr, true);
        cell.candidates.clear();
        std::sort(kps.begin(), kps.end(), [](const cv::KeyPoint& a, const cv::KeyPoint& c) { return a.response > c.response; });
        for (const auto& k : kps) {
          const cv::Point2f p(k.pt.x + static_cast<float>(roi.x), k.pt.y + static_cast<float>(roi.y));
          if (cell.rect.contains(cv::Point(static_cast<int>(p.x), static_cast<int>(p.y))) && occ.free(p)) {
            cell.candidates.push_back(p);
          }
        }
        // Enough candidates (allowing for mutual minimum-distance conflicts), or no lower threshold.
        if (static_cast<int>(cell.candidates.size()) >= 3 * need || thr == cfg_.fastMinThreshold) break;
      }
    } else {
      std::vector<cv::Point2f> corners;
      cv::goodFeaturesToTrack(sub, corners, 3 * need, cfg_.shiTomasiQuality, std::max(1.0, cfg_.minDistance));
      for (const auto& c : corners) {
        const cv::Point2f p(c.x + static_cast<float>(roi.x), c.y + static_cast<float>(roi.y));
        if (cell.rect.contains(cv::Point(static_cast<int>(p.x), static_cast<int>(p.y))) && occ.free(p)) {
          cell.candidates.push_back(p);
        }
      }
    }
  };

  // Round-robin over the cells in image order, strongest remaining candidate first: first up to
  // each cell's share, then (if the cap is not reached because some cells are textureless)
  // beyond it. A cell is searched when the round-robin first reaches it: when only a few
  // features are missing, only the first cells with room are.
  int added = 0;
  const int room = cfg_.maxFeatures - total;
  auto roundRobin = [&](int cellCap) {
    for (bool progress = true; progress && added < room;) {
      progress = false;
      for (Cell& cell : cells) {
        if (added >= room) break;
        if (cell.existing + cell.added >= cellCap) continue;
        if (!cell.searched) findCandidates(cell);
        while (cell.next < cell.candidates.size()) {
          const cv::Point2f p = cell.candidates[cell.next++];
          if (occ.free(p)) {
            occ.add(p);
            points.push_back(p);
            ++cell.added;
            ++added;
            progress = true;
            break;
          }
        }
      }
    }
  };
  roundRobin(quota);
  roundRobin(std::numeric_limits<int>::max());
  return added;
}

}  // namespace gvins::vio
