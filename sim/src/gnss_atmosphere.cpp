#include "gvins/sim/gnss_atmosphere.hpp"

#include <algorithm>
#include <cmath>

#include "gvins/base/constants.hpp"
#include "gvins/gnss/klobuchar.hpp"
#include "gvins/gnss/troposphere.hpp"
#include "gvins/sim/gnss_random.hpp"

namespace gvins::sim {

namespace {
constexpr double kEarthRadius = 6371e3;  // mean radius for single-layer geometry, m
// Water-vapour scale height used to carry the zenith wet residual to the receiver's height, m
// (water vapour density falls off with a scale height of about 2 km).
constexpr double kWetScaleHeight = 2000.0;
}  // namespace

double ionosphereMetersPerTecu(double frequency) { return 40.3e16 / (frequency * frequency); }

GnssAtmosphere::GnssAtmosphere(const GnssSimConfig& config, const std::optional<KlobucharParameters>& klobuchar,
                               const Geodetic& origin, const GpsTime& start, std::uint64_t seed)
    : tropo_(config.troposphere), iono_(config.ionosphere), origin_(origin), start_(start) {
  if (klobuchar) {
    klobuchar_ = *klobuchar;
  } else {
    klobuchar_.alpha = {1.8626e-08, 2.2352e-08, -1.1921e-07, -5.9605e-08};
    klobuchar_.beta = {1.2902e+05, 1.6384e+05, -1.9661e+05, -2.6214e+05};
  }
  originEcef_ = geodeticToEcef(origin);
  enuFromEcef_ = ecefToEnuRotation(origin.lat, origin.lon);
  GnssRandom rng(streamSeed(seed, {0xA7, 1}));
  // Scale errors, bounded so that no delay changes sign.
  eh_ = std::clamp(rng.normal(tropo_.hydrostaticScaleSigma), -0.5, 0.5);
  ew_ = std::clamp(rng.normal(tropo_.wetScaleSigma), -0.9, 3.0);
  ei_ = std::clamp(rng.normal(iono_.modelScaleSigma), -0.8, 3.0);
  for (std::size_t i = 0; i < tropo_.residual.size(); ++i)
    tropoFields_.emplace_back(tropo_.residual[i], streamSeed(seed, {0xA7, 2, i}));
  for (std::size_t i = 0; i < iono_.residual.size(); ++i)
    ionoFields_.emplace_back(iono_.residual[i], streamSeed(seed, {0xA7, 3, i}));
}

GnssAtmosphereDelays GnssAtmosphere::delays(const Geodetic& rx, const Eigen::Vector3d& rxEcef, const AzEl& azel,
                                            const GpsTime& t) const {
  GnssAtmosphereDelays d;
  const double ts = t - start_;
  const double sinEl = std::sin(azel.elevation), cosEl = std::cos(azel.elevation);

  // Troposphere.
  const TroposphereDelay m = slantTroposphereDelay(rx, azel.elevation, t, tropo_.relativeHumidity);
  d.troposphereModel = m.slant;
  double zwdResidual = 0.0;
  if (!tropoFields_.empty() && m.slant > 0.0) {
    const Eigen::Vector3d enu = enuFromEcef_ * (rxEcef - originEcef_);
    const double reach = tropo_.layerHeight * cosEl / std::max(sinEl, 0.05);
    const Eigen::Vector2d p(enu.x() + reach * std::sin(azel.azimuth), enu.y() + reach * std::cos(azel.azimuth));
    for (const GnssRandomField& f : tropoFields_) zwdResidual += f.value(p, ts);
    zwdResidual *= std::exp(-(rx.height - origin_.height) / kWetScaleHeight);
  }
  if (m.slant > 0.0) {
    const double zwd = std::max(m.zenithWet * (1.0 + ew_) + zwdResidual, 0.0);
    d.troposphere = m.zenithHydrostatic * (1.0 + eh_) * m.mapHydrostatic + zwd * m.mapWet;
  }

  // Ionosphere.
  d.ionosphereModelL1 = klobucharDelayL1(klobuchar_, rx, azel, t);
  const double R = kEarthRadius, H = iono_.shellHeight;
  const double sinZ = R * cosEl / (R + H);
  const double obliquity = 1.0 / std::sqrt(1.0 - sinZ * sinZ);
  double vtec = 0.0;
  if (!ionoFields_.empty()) {
    // Pierce point on the shell (spherical Earth), then local plane coordinates at shell radius.
    const double psi = constants::kPi / 2.0 - azel.elevation - std::asin(sinZ);
    const double sinLat = std::sin(rx.lat) * std::cos(psi) + std::cos(rx.lat) * std::sin(psi) * std::cos(azel.azimuth);
    const double latI = std::asin(std::clamp(sinLat, -1.0, 1.0));
    const double lonI = rx.lon + std::asin(std::clamp(std::sin(psi) * std::sin(azel.azimuth) / std::cos(latI), -1.0, 1.0));
    double dLon = lonI - origin_.lon;
    dLon = std::remainder(dLon, 2.0 * constants::kPi);
    const Eigen::Vector2d p((R + H) * dLon * std::cos(origin_.lat), (R + H) * (latI - origin_.lat));
    for (const GnssRandomField& f : ionoFields_) vtec += f.value(p, ts);
  }
  d.ionosphereL1 = std::max(d.ionosphereModelL1 * (1.0 + ei_) + obliquity * ionosphereMetersPerTecu(kGnssSimL1Frequency) * vtec,
                            0.05 * d.ionosphereModelL1);
  return d;
}

}  // namespace gvins::sim
