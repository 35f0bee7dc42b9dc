#include "gvins/ephemeris/orbit_comparison.hpp"

#include <cmath>

#include <Eigen/Geometry>

#include "gvins/base/constants.hpp"

namespace gvins {

OrbitDifference orbitDifference(const SatelliteState& state, const SatelliteState& reference) {
  const Eigen::Vector3d r = reference.position;
  const Eigen::Vector3d rHat = r.normalized();
  const Eigen::Vector3d cHat = r.cross(reference.velocity).normalized();
  const Eigen::Vector3d aHat = cHat.cross(rHat);
  const Eigen::Vector3d d = state.position - reference.position;
  OrbitDifference out;
  out.radial = rHat.dot(d);
  out.along = aHat.dot(d);
  out.cross = cHat.dot(d);
  out.clock = constants::kSpeedOfLight * (state.clockBias - reference.clockBias);
  return out;
}

SisreWeights sisreWeights(SatId sat) {
  switch (sat.system) {
    case System::Glonass: return {0.98, 1.0 / 45.0};
    case System::Galileo: return {0.98, 1.0 / 61.0};
    case System::BeiDou:
      return beidouOrbit(sat.prn) == BeiDouOrbit::Meo ? SisreWeights{0.98, 1.0 / 54.0} : SisreWeights{0.99, 1.0 / 126.0};
    case System::Qzss: return {0.99, 1.0 / 126.0};
    default: return {0.98, 1.0 / 49.0};
  }
}

double sisre(SatId sat, const OrbitDifference& d, double clockOffset) {
  const SisreWeights w = sisreWeights(sat);
  const double rc = w.radial * d.radial - (d.clock - clockOffset);
  return std::sqrt(rc * rc + w.alongCrossSquared * (d.along * d.along + d.cross * d.cross));
}

}  // namespace gvins
