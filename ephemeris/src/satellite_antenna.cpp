#include "gvins/ephemeris/satellite_antenna.hpp"

#include <Eigen/Geometry>

#include "gvins/base/signal.hpp"
#include "gvins/ephemeris/sun_position.hpp"

namespace gvins {

Eigen::Matrix3d yawSteeringAxes(const Eigen::Vector3d& position, const Eigen::Vector3d& sun) {
  const Eigen::Vector3d ez = -position.normalized();
  const Eigen::Vector3d es = (sun - position).normalized();
  Eigen::Vector3d ey = ez.cross(es);
  const double n = ey.norm();
  // Sun exactly along the z axis (orbit noon/midnight with β = 0): the yaw is undefined there (real
  // satellites turn through it); any y ⟂ z keeps the frame right-handed.
  if (n < 1e-12) {
    ey = ez.cross(Eigen::Vector3d::UnitZ());
    if (ey.norm() < 1e-12) ey = ez.cross(Eigen::Vector3d::UnitX());
  }
  ey.normalize();
  const Eigen::Vector3d ex = ey.cross(ez);
  Eigen::Matrix3d R;
  R.col(0) = ex;
  R.col(1) = ey;
  R.col(2) = ez;
  return R;
}

std::pair<char, char> referenceFrequencyPair(System system) {
  switch (system) {
    case System::Galileo: return {'1', '5'};
    case System::BeiDou: return {'2', '6'};
    default: return {'1', '2'};  // GPS, QZSS, GLONASS (G1/G2), SBAS, NavIC
  }
}

std::optional<Eigen::Vector3d> ionosphereFreeOffset(const AntexAntenna& antenna, System system) {
  const auto [b1, b2] = referenceFrequencyPair(system);
  const AntexFrequency* p1 = antenna.frequency(system, b1);
  const AntexFrequency* p2 = antenna.frequency(system, b2);
  // GLONASS FDMA: the G1/G2 ratio is 9/7 on every channel, so channel 0 gives the coefficients.
  const auto f1 = carrierFrequency(system, b1, 0);
  const auto f2 = carrierFrequency(system, b2, 0);
  if (p1 && p2 && f1 && f2) {
    const double a1 = *f1 * *f1 / (*f1 * *f1 - *f2 * *f2);
    return a1 * p1->offset + (1.0 - a1) * p2->offset;
  }
  for (const AntexFrequency& f : antenna.frequencies) {
    if (f.system == system) return f.offset;
  }
  return std::nullopt;
}

std::optional<Eigen::Vector3d> satelliteAntennaOffset(const AntexData& antex, SatId sat, const GpsTime& t,
                                                      const Eigen::Vector3d& position) {
  const AntexAntenna* a = antex.satellite(sat, t);
  if (!a) return std::nullopt;
  const auto pco = ionosphereFreeOffset(*a, sat.system);
  if (!pco) return std::nullopt;
  return yawSteeringAxes(position, sunPositionEcef(t)) * *pco;
}

}  // namespace gvins
