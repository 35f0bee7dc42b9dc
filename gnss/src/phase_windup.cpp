#include "gvins/gnss/phase_windup.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

namespace gvins {

double phaseWindupCycles(const Eigen::Vector3d& satellite, const Eigen::Vector3d& receiver,
                         const Eigen::Matrix3d& satelliteAxes, const Eigen::Matrix3d& receiverAxes,
                         std::optional<double> previous) {
  const Eigen::Vector3d k = (receiver - satellite).normalized();
  const Eigen::Vector3d xs = satelliteAxes.col(0), ys = satelliteAxes.col(1);
  const Eigen::Vector3d xr = receiverAxes.col(0), yr = receiverAxes.col(1);
  const Eigen::Vector3d ds = xs - k * k.dot(xs) - k.cross(ys);
  const Eigen::Vector3d dr = xr - k * k.dot(xr) + k.cross(yr);
  const double c = std::clamp(ds.dot(dr) / (ds.norm() * dr.norm()), -1.0, 1.0);
  double w = std::acos(c) / (2.0 * std::acos(-1.0));
  if (k.dot(ds.cross(dr)) < 0.0) w = -w;
  return continueWindup(w, previous);
}

double continueWindup(double cycles, std::optional<double> previous) {
  return previous ? cycles + std::round(*previous - cycles) : cycles;
}

Eigen::Matrix3d levelAntennaAxes(double latitude, double longitude) {
  const double sl = std::sin(latitude), cl = std::cos(latitude), so = std::sin(longitude), co = std::cos(longitude);
  Eigen::Matrix3d a;
  a.col(0) = Eigen::Vector3d(-sl * co, -sl * so, cl);  // north
  a.col(1) = Eigen::Vector3d(so, -co, 0.0);            // west
  a.col(2) = Eigen::Vector3d(cl * co, cl * so, sl);    // up
  return a;
}

}  // namespace gvins
