#include "gvins/gnss/zero_difference.hpp"

#include <cmath>

#include "gvins/base/constants.hpp"
#include "gvins/gnss/sagnac.hpp"

namespace gvins {

std::optional<TransmitState> satelliteAtTransmit(const EphemerisStore& nav, SatId sat, const GpsTime& receiveTime,
                                                 double pseudorange, const EphemerisSelection& policy,
                                                 EphemerisCache* cache) {
  if (!(pseudorange > 1e6 && pseudorange < 1e8) || !sat.valid()) return std::nullopt;
  GpsTime ttx = receiveTime - pseudorange / constants::kSpeedOfLight;
  // One record selection per satellite for the state, the health and the group delays.
  TransmitState out;
  if (sat.system == System::Glonass) out.glonass = cache ? cache->glonass(sat, ttx) : nav.selectGlonass(sat, ttx, policy);
  else out.kepler = cache ? cache->kepler(sat, ttx) : nav.selectKepler(sat, ttx, policy);
  if (!out.glonass && !out.kepler) return std::nullopt;
  auto evaluate = [&](const GpsTime& t) {
    return out.glonass ? glonassSatelliteState(*out.glonass, t) : keplerSatelliteState(*out.kepler, t);
  };
  std::optional<SatelliteState> st = evaluate(ttx);
  // Move the state by -dt_s (|dt_s| < 1 ms): a first-order step is exact to < 1e-6 m, since the
  // orbital acceleration (< 1 m/s^2) contributes a*dt^2/2.
  const double dts = st->clockBias;
  ttx -= dts;
  st->position -= st->velocity * dts;
  st->clockBias -= st->clockDrift * dts;
  if (std::abs(dts) > 0.01) st = evaluate(ttx);
  if (st && nav.precise()) {
    if (auto p = nav.preciseState(sat, ttx)) {
      p->healthy = st->healthy;
      st = p;
    }
  }
  if (st && !st->precise && !nav.ssr().empty()) {
    if (auto c = nav.ssrState(sat, ttx, policy)) {
      c->healthy = st->healthy;
      st = c;
    } else if (nav.ssr().coversSystem(sat.system, ttx)) {
      return std::nullopt;
    }
  }
  if (!st || (!st->healthy && !policy.allowUnhealthy) || !st->position.allFinite() || st->position.norm() < 1e7) {
    return std::nullopt;
  }
  out.transmitTime = ttx;
  out.state = *st;
  return out;
}

double transmitGroupDelay(const EphemerisStore& nav, const TransmitState& tx, SatId sat, ObsCode code) {
  if (const auto osb = nav.preciseCodeBias(tx.state, sat, code, tx.transmitTime)) return *osb;
  if (tx.glonass) return broadcastGroupDelay(*tx.glonass, code);
  if (tx.kepler) return broadcastGroupDelay(*tx.kepler, code, nav.cnavGroupDelays(sat, tx.transmitTime));
  return 0.0;
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
