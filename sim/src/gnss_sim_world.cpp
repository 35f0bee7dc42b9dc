#include "gvins/sim/gnss_sim_world.hpp"

#include <cmath>
#include <stdexcept>

#include "gvins/base/constants.hpp"

namespace gvins::sim {

Eigen::Vector3d gnssBasePosition(const GnssBaseConfig& base, const Geodetic& origin) {
  if (base.positionLlh) {
    const Eigen::Vector3d& l = *base.positionLlh;
    return geodeticToEcef(geodeticFromDegrees(l.x(), l.y(), l.z()));
  }
  // Direct problem on the sphere of the origin's Gaussian mean radius sqrt(M N).
  const double a = constants::kWgs84A, e2 = constants::kWgs84E2;
  const double s = std::sin(origin.lat);
  const double w = std::sqrt(1.0 - e2 * s * s);
  const double N = a / w, M = a * (1.0 - e2) / (w * w * w);
  const double R = std::sqrt(M * N);
  const double d = base.distance / R, az = base.azimuthDeg * constants::kDegToRad;
  const double lat2 = std::asin(std::sin(origin.lat) * std::cos(d) + std::cos(origin.lat) * std::sin(d) * std::cos(az));
  const double lon2 = origin.lon + std::atan2(std::sin(az) * std::sin(d) * std::cos(origin.lat),
                                              std::cos(d) - std::sin(origin.lat) * std::sin(lat2));
  return geodeticToEcef(Geodetic{lat2, lon2, origin.height + base.height});
}

namespace {
EphemerisStore makeStore(const NavData& nav) {
  EphemerisStore s;
  s.add(nav);
  return s;
}
}  // namespace

GnssSimWorld::GnssSimWorld(const GnssSimConfig& config, const NavData& nav, const Geodetic& origin,
                           const GpsTime& start, double duration, std::uint64_t seed)
    : config_(config),
      nav_(nav),
      store_(makeStore(nav_)),
      origin_(origin),
      start_(start),
      duration_(duration),
      seed_(seed),
      constellation_(store_, config_, start, start + duration, seed),
      atmosphere_(config_, store_.ionosphere().gps, origin, start, seed),
      basePosition_(gnssBasePosition(config_.base, origin)) {
  if (!(duration >= 0.0) || !std::isfinite(duration)) throw std::invalid_argument("GnssSimWorld: bad duration");
}

}  // namespace gvins::sim
