// Corner detection on a grid: the image is split into cells, each cell gets at most its share
// of the feature cap, and a new corner keeps a minimum distance from every existing and new
// feature. Cells are filled round-robin (strongest corner first) so that the cap spreads the
// features over the image; a cell is searched only when the round-robin reaches it (a frame that
// misses a few features searches a few cells). FAST (Rosten & Drummond 2006) with a per-cell
// threshold that is lowered in weakly textured cells, or Shi-Tomasi minimum-eigenvalue corners
// (Shi & Tomasi 1994).
#pragma once

#include <vector>

#include <opencv2/core/mat.hpp>
#include <opencv2/core/types.hpp>

namespace gvins::vio {

enum class CornerDetector { Fast, ShiTomasi };

struct GridDetectorConfig {
  int maxFeatures = 150;      ///< cap on features per frame (existing + new)
  int gridCols = 8;
  int gridRows = 5;
  double minDistance = 20.0;  ///< pixels between any two features
  int border = 10;            ///< no corners closer than this to the image edge
  CornerDetector detector = CornerDetector::Fast;
  int fastThreshold = 20;     ///< first FAST threshold per cell ...
  int fastMinThreshold = 5;   ///< ... halved down to this while a cell lacks corners
  double shiTomasiQuality = 0.01;
};

class GridDetector {
 public:
  explicit GridDetector(const GridDetectorConfig& config = {});

  /// Appends new corners to `points` (the existing entries are kept and respected) until
  /// config.maxFeatures; returns how many were added. `image` is 8-bit gray.
  int detect(const cv::Mat& image, std::vector<cv::Point2f>& points) const;

  const GridDetectorConfig& config() const { return cfg_; }

 private:
  GridDetectorConfig cfg_;
};

}  // namespace gvins::vio
