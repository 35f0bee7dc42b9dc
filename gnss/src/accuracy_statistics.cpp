#include "gvins/gnss/accuracy_statistics.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "gvins/base/geodetic.hpp"
#include "gvins/base/local_frame.hpp"

namespace gvins {

namespace {
constexpr double kMin = 1e-6;
constexpr double kMax = 1e7;
constexpr double kStep = 1e-3;  // relative bin width (log1p)
const double kLogStep = std::log1p(kStep);
const int kBins = static_cast<int>(std::ceil(std::log(kMax / kMin) / kLogStep)) + 2;
}  // namespace

QuantileHistogram::QuantileHistogram() : bins_(static_cast<std::size_t>(kBins), 0) {}

void QuantileHistogram::add(double v) {
  if (!std::isfinite(v)) v = kMax;
  int b = 0;
  if (v > kMin) b = std::min(kBins - 1, 1 + static_cast<int>(std::log(v / kMin) / kLogStep));
  ++bins_[static_cast<std::size_t>(b)];
  ++count_;
}

double QuantileHistogram::quantile(double q) const {
  if (count_ == 0) return 0.0;
  const auto target = static_cast<std::int64_t>(std::ceil(std::clamp(q, 0.0, 1.0) * static_cast<double>(count_)));
  std::int64_t acc = 0;
  for (int b = 0; b < kBins; ++b) {
    acc += bins_[static_cast<std::size_t>(b)];
    if (acc >= std::max<std::int64_t>(target, 1)) return b == 0 ? kMin : kMin * std::exp(b * kLogStep);
  }
  return kMax;
}

void AccuracyStatistics::Accumulator::add(const Eigen::Vector3d& enu) {
  ++n;
  sum += enu;
  sumSq += enu.cwiseProduct(enu);
  const double hz = std::hypot(enu.x(), enu.y());
  const double vt = std::abs(enu.z());
  maxH = std::max(maxH, hz);
  maxV = std::max(maxV, vt);
  h.add(hz);
  v.add(vt);
}

AccuracySummary AccuracyStatistics::Accumulator::summary() const {
  AccuracySummary s;
  s.count = n;
  if (n == 0) return s;
  const double dn = static_cast<double>(n);
  for (int i = 0; i < 3; ++i) {
    s.enu[i].mean = sum[i] / dn;
    s.enu[i].rms = std::sqrt(sumSq[i] / dn);
    s.enu[i].stddev = std::sqrt(std::max(sumSq[i] / dn - s.enu[i].mean * s.enu[i].mean, 0.0));
  }
  s.horizontalRms = std::sqrt((sumSq[0] + sumSq[1]) / dn);
  s.verticalRms = std::sqrt(sumSq[2] / dn);
  s.rms3d = std::sqrt(sumSq.sum() / dn);
  s.horizontal95 = h.quantile(0.95);
  s.vertical95 = v.quantile(0.95);
  s.horizontalMax = maxH;
  s.verticalMax = maxV;
  return s;
}

AccuracyStatistics::AccuracyStatistics(const Eigen::Vector3d& truth, const Eigen::Vector3d& truthVel)
    : truth_(truth), truthVel_(truthVel) {
  const Geodetic g = ecefToGeodetic(truth);
  rot_ = ecefToEnuRotation(g.lat, g.lon);
}

Eigen::Vector3d AccuracyStatistics::enuError(const Eigen::Vector3d& ecef) const { return rot_ * (ecef - truth_); }

void AccuracyStatistics::addPosition(const Eigen::Vector3d& ecef) { pos_.add(enuError(ecef)); }
void AccuracyStatistics::addVelocity(const Eigen::Vector3d& v) { vel_.add(rot_ * (v - truthVel_)); }

AccuracySummary AccuracyStatistics::position() const { return pos_.summary(); }
AccuracySummary AccuracyStatistics::velocity() const { return vel_.summary(); }

std::string formatAccuracyTable(const AccuracySummary& s, const std::string& title, const std::string& unit) {
  char b[256];
  std::string out;
  std::snprintf(b, sizeof b, "%s (%lld epochs, %s)\n", title.c_str(), static_cast<long long>(s.count), unit.c_str());
  out += b;
  std::snprintf(b, sizeof b, "  %-10s %10s %10s %10s %10s %10s\n", "", "east", "north", "up", "horizontal", "vertical");
  out += b;
  std::snprintf(b, sizeof b, "  %-10s %10.3f %10.3f %10.3f %10s %10s\n", "mean", s.enu[0].mean, s.enu[1].mean,
                s.enu[2].mean, "", "");
  out += b;
  std::snprintf(b, sizeof b, "  %-10s %10.3f %10.3f %10.3f %10s %10s\n", "std", s.enu[0].stddev, s.enu[1].stddev,
                s.enu[2].stddev, "", "");
  out += b;
  std::snprintf(b, sizeof b, "  %-10s %10.3f %10.3f %10.3f %10.3f %10.3f\n", "rms", s.enu[0].rms, s.enu[1].rms,
                s.enu[2].rms, s.horizontalRms, s.verticalRms);
  out += b;
  std::snprintf(b, sizeof b, "  %-10s %10s %10s %10s %10.3f %10.3f\n", "95%", "", "", "", s.horizontal95, s.vertical95);
  out += b;
  std::snprintf(b, sizeof b, "  %-10s %10s %10s %10s %10.3f %10.3f\n", "max", "", "", "", s.horizontalMax, s.verticalMax);
  out += b;
  return out;
}

std::string AccuracyStatistics::table() const {
  std::string t = formatAccuracyTable(position(), "position error vs truth", "m");
  if (vel_.n > 0) t += formatAccuracyTable(velocity(), "velocity error vs truth", "m/s");
  return t;
}

}  // namespace gvins
