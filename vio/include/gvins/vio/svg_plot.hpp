// A minimal line-plot writer producing standalone SVG 1.1 (no plotting dependency): axes with
// "nice" tick values (1, 2, 5 × 10^k), labelled series with a legend, optional equal aspect for
// top views. Non-finite points break a line.
#pragma once

#include <string>
#include <vector>

namespace gvins::vio {

class SvgPlot {
 public:
  SvgPlot(std::string title, std::string xLabel, std::string yLabel);
  /// `color` is any SVG colour ("#1f77b4", "red"); empty picks the next of a fixed palette.
  void addLine(std::string name, std::vector<double> x, std::vector<double> y, std::string color = "");
  /// Same units per pixel on both axes (top views of trajectories).
  void setEqualAspect(bool on) { equalAspect_ = on; }
  std::size_t seriesCount() const { return series_.size(); }
  /// The SVG document.
  std::string render(int width = 800, int height = 600) const;
  /// Writes render() to a file; throws std::runtime_error on failure.
  void save(const std::string& path, int width = 800, int height = 600) const;

 private:
  struct Series {
    std::string name, color;
    std::vector<double> x, y;
  };
  std::string title_, xLabel_, yLabel_;
  std::vector<Series> series_;
  bool equalAspect_ = false;
};

/// Tick values covering [lo, hi] with about `target` steps of 1, 2 or 5 × 10^k.
std::vector<double> niceTicks(double lo, double hi, int target = 6);

}  // namespace gvins::vio
