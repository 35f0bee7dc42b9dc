#include "gvins/vio/svg_plot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <stdexcept>

namespace gvins::vio {

namespace {
const char* const kPalette[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b"};

std::string escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    switch (c) {
      case '&': o += "&amp;"; break;
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      case '"': o += "&quot;"; break;
      default: o += c;
    }
  }
  return o;
}

std::string num(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.2f", v);
  return b;
}

std::string tickLabel(double v, double step) {
  char b[32];
  const int dec = step >= 1.0 ? 0 : std::min(9, static_cast<int>(std::ceil(-std::log10(step) - 1e-9)));
  std::snprintf(b, sizeof b, "%.*f", dec, std::abs(v) < 1e-12 * step ? 0.0 : v);
  return b;
}
}  // namespace

std::vector<double> niceTicks(double lo, double hi, int target) {
  std::vector<double> t;
  if (!(std::isfinite(lo) && std::isfinite(hi)) || hi <= lo || target < 1) return t;
  const double raw = (hi - lo) / target;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  double step = mag;
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    step = m * mag;
    if (step >= raw) break;
  }
  const double first = std::ceil(lo / step - 1e-9) * step;
  for (int k = 0; k < 1000; ++k) {
    const double v = first + k * step;
    if (v > hi + 1e-9 * step) break;
    t.push_back(v);
  }
  return t;
}

SvgPlot::SvgPlot(std::string title, std::string xLabel, std::string yLabel)
    : title_(std::move(title)), xLabel_(std::move(xLabel)), yLabel_(std::move(yLabel)) {}

void SvgPlot::addLine(std::string name, std::vector<double> x, std::vector<double> y, std::string color) {
  if (x.size() != y.size()) throw std::invalid_argument("SvgPlot::addLine: x and y differ in length");
  if (color.empty()) color = kPalette[series_.size() % (sizeof kPalette / sizeof kPalette[0])];
  series_.push_back({std::move(name), std::move(color), std::move(x), std::move(y)});
}

std::string SvgPlot::render(int width, int height) const {
  constexpr double inf = std::numeric_limits<double>::infinity();
  double x0 = inf, x1 = -inf, y0 = inf, y1 = -inf;
  for (const Series& s : series_) {
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      x0 = std::min(x0, s.x[i]);
      x1 = std::max(x1, s.x[i]);
      y0 = std::min(y0, s.y[i]);
      y1 = std::max(y1, s.y[i]);
    }
  }
  if (!(x0 <= x1)) x0 = 0, x1 = 1, y0 = 0, y1 = 1;
  if (x1 - x0 < 1e-12) x0 -= 0.5, x1 += 0.5;
  if (y1 - y0 < 1e-12) y0 -= 0.5, y1 += 0.5;
  const double padX = 0.03 * (x1 - x0), padY = 0.05 * (y1 - y0);
  x0 -= padX, x1 += padX, y0 -= padY, y1 += padY;
  const double left = 80, right = 20, top = 40, bottom = 60;
  const double pw = width - left - right, ph = height - top - bottom;
  if (equalAspect_) {
    const double sx = (x1 - x0) / pw, sy = (y1 - y0) / ph;
    if (sx > sy) {
      const double c = 0.5 * (y0 + y1), h = 0.5 * sx * ph;
      y0 = c - h, y1 = c + h;
    } else {
      const double c = 0.5 * (x0 + x1), w = 0.5 * sy * pw;
      x0 = c - w, x1 = c + w;
    }
  }
  auto X = [&](double v) { return left + (v - x0) / (x1 - x0) * pw; };
  auto Y = [&](double v) { return top + (y1 - v) / (y1 - y0) * ph; };
  std::string o;
  o += "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\" version=\"1.1\" width=\"" +
       std::to_string(width) + "\" height=\"" + std::to_string(height) + "\" font-family=\"sans-serif\" font-size=\"12\">\n";
  o += "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  o += "<text x=\"" + num(width / 2.0) + "\" y=\"22\" text-anchor=\"middle\" font-size=\"15\">" + escape(title_) + "</text>\n";
  const std::vector<double> xt = niceTicks(x0, x1, 8), yt = niceTicks(y0, y1, 6);
  const double xs = xt.size() > 1 ? xt[1] - xt[0] : 1.0, ys = yt.size() > 1 ? yt[1] - yt[0] : 1.0;
  for (double v : xt) {
    o += "<line x1=\"" + num(X(v)) + "\" y1=\"" + num(top) + "\" x2=\"" + num(X(v)) + "\" y2=\"" + num(top + ph) +
         "\" stroke=\"#ddd\"/>\n";
    o += "<text x=\"" + num(X(v)) + "\" y=\"" + num(top + ph + 16) + "\" text-anchor=\"middle\">" + tickLabel(v, xs) + "</text>\n";
  }
  for (double v : yt) {
    o += "<line x1=\"" + num(left) + "\" y1=\"" + num(Y(v)) + "\" x2=\"" + num(left + pw) + "\" y2=\"" + num(Y(v)) +
         "\" stroke=\"#ddd\"/>\n";
    o += "<text x=\"" + num(left - 6) + "\" y=\"" + num(Y(v) + 4) + "\" text-anchor=\"end\">" + tickLabel(v, ys) + "</text>\n";
  }
  o += "<rect x=\"" + num(left) + "\" y=\"" + num(top) + "\" width=\"" + num(pw) + "\" height=\"" + num(ph) +
       "\" fill=\"none\" stroke=\"black\"/>\n";
  o += "<text x=\"" + num(left + pw / 2) + "\" y=\"" + num(height - 15.0) + "\" text-anchor=\"middle\">" + escape(xLabel_) + "</text>\n";
  o += "<text transform=\"translate(18," + num(top + ph / 2) + ") rotate(-90)\" text-anchor=\"middle\">" + escape(yLabel_) + "</text>\n";
  for (const Series& s : series_) {
    std::string d;
    bool pen = false;
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) {
        pen = false;
        continue;
      }
      d += (pen ? " L" : " M") + num(X(s.x[i])) + "," + num(Y(s.y[i]));
      pen = true;
    }
    if (!d.empty())
      o += "<path d=\"" + d.substr(1) + "\" fill=\"none\" stroke=\"" + escape(s.color) + "\" stroke-width=\"1.5\"/>\n";
  }
  for (std::size_t k = 0; k < series_.size(); ++k) {
    const double ly = top + 14 + 16.0 * static_cast<double>(k);
    o += "<line x1=\"" + num(left + 10) + "\" y1=\"" + num(ly - 4) + "\" x2=\"" + num(left + 30) + "\" y2=\"" + num(ly - 4) +
         "\" stroke=\"" + escape(series_[k].color) + "\" stroke-width=\"2\"/>\n";
    o += "<text x=\"" + num(left + 36) + "\" y=\"" + num(ly) + "\">" + escape(series_[k].name) + "</text>\n";
  }
  o += "</svg>\n";
  return o;
}

void SvgPlot::save(const std::string& path, int width, int height) const {
  std::ofstream f(path, std::ios::binary);
  if (!f) throw std::runtime_error("cannot create plot file " + path);
  f << render(width, height);
  f.close();
  if (!f) throw std::runtime_error("error writing plot file " + path);
}

}  // namespace gvins::vio
