#include "gvins/gnss/zero_difference.hpp"

#include <cmath>

#include "gvins/base/constants.hpp"
#include "gvins/gnss/sagnac.hpp"

namespace gvins {

std::optional<TransmitState> satelliteAtTransmit(const EphemerisStore& nav, SatId sat, const GpsTime& receiveTime,
                                                 double pseudorange, const EphemerisSelection& policy) {
  if (!(pseudorange > 1e6 && pseudorange < 1e8)) return std::nullopt;
  GpsTime ttx = receiveTime - pseudorange / constants::kSpeedOfLight;
  auto st = nav.satelliteState(sat, ttx, policy);
  if (!st) return std::nullopt;
  // Move by −dt_s to first order (|dt_s| < 1 ms; the orbital acceleration adds < 1 µm), or
  // evaluate again for an implausibly large clock.
  const double dts = st->clockBias;
  ttx -= dts;
  if (std::abs(dts) > 0.01) {
    st = nav.satelliteState(sat, ttx, policy);
    if (!st) return std::nullopt;
  } else {
    st->position -= st->velocity * dts;
    st->clockBias -= st->clockDrift * dts;
  }
  if ((!st->healthy && !policy.allowUnhealthy) || !st->position.allFinite() || st->position.norm() < 1e7) {
    return std::nullopt;
  }
  return TransmitState{ttx, *st};
}

double geometricRange(const Eigen::Vector3d& satellite, const Eigen::Vector3d& receiver, Eigen::Vector3d* gradient) {
  const Eigen::Vector3d d = satellite - receiver;
  const double r = d.norm();
  if (gradient) {
    const double w = constants::kWgs84OmegaE / constants::kSpeedOfLight;
    *gradient = -d / r + Eigen::Vector3d(-w * satellite.y(), w * satellite.x(), 0.0);
  }
  return r + sagnacRangeCorrection(satellite, receiver);
}

}  // namespace gvins
