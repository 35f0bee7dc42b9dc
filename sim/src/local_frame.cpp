#include "gvins/sim/local_frame.hpp"

#include <cmath>
#include <stdexcept>

#include "gvins/base/local_frame.hpp"

namespace gvins::sim {

Eigen::Vector3d LocalFrame::originEcef() const { return geodeticToEcef(origin); }

Eigen::Matrix3d LocalFrame::rotationEcefFromW() const {
  return ecefToEnuRotation(origin.lat, origin.lon).transpose();
}

Eigen::Vector3d LocalFrame::toEcef(const Eigen::Vector3d& p_W) const {
  return originEcef() + rotationEcefFromW() * p_W;
}

Eigen::Vector3d LocalFrame::fromEcef(const Eigen::Vector3d& p_E) const {
  return rotationEcefFromW().transpose() * (p_E - originEcef());
}

Geodetic LocalFrame::toGeodetic(const Eigen::Vector3d& p_W) const { return ecefToGeodetic(toEcef(p_W)); }

std::int64_t LocalFrame::startStampNs() const {
  const double fracNs = std::round(startTime.fraction() * 1e9);
  return startTime.wholeSeconds() * 1'000'000'000LL + static_cast<std::int64_t>(fracNs);
}

std::int64_t LocalFrame::stampNs(double t) const {
  if (!std::isfinite(t) || std::abs(t) > 1e9) throw std::invalid_argument("LocalFrame::stampNs: bad time");
  return startStampNs() + static_cast<std::int64_t>(std::llround(t * 1e9));
}

double LocalFrame::flightTimeOfStamp(std::int64_t stamp_ns) const {
  return static_cast<double>(stamp_ns - startStampNs()) * 1e-9;
}

}  // namespace gvins::sim
