// Satellite antenna phase-centre offsets: from the centre of mass (SP3 positions) to the antenna
// phase centre that broadcast ephemerides and ranging refer to.
//
// Attitude: nominal yaw steering (Montenbruck et al. 2015, "GNSS satellite geometry and attitude
// models", Adv. Space Res. 56(6), 1015-1029): z towards the Earth's centre, y = z × e_sun
// normalised (the solar-panel axis), x = y × z (towards the Sun-lit half-plane). The noon/midnight
// turns and eclipse-season yaw manoeuvres of individual blocks are not modelled: they rotate the
// horizontal PCO (a few cm to ~0.3 m depending on the block) about z during minutes around the
// orbit's noon and midnight points, a centimetre-level range effect.
//
// The offset applied is that of the ionosphere-free combination of the system's reference
// frequencies of the IGS clock products (GPS/QZSS L1/L2, GLONASS G1/G2, Galileo E1/E5a, BeiDou
// B1I/B3I): a1·PCO(f1) + a2·PCO(f2), a1 = f1²/(f1² − f2²), a2 = 1 − a1. The clocks of such products
// are consistent with exactly that offset; other signals differ by the frequency dependence of the
// PCO (millimetres to centimetres).
#pragma once

#include <optional>

#include <Eigen/Core>

#include "gvins/base/gnss_time.hpp"
#include "gvins/base/satellite.hpp"
#include "gvins/ephemeris/antex.hpp"

namespace gvins {

/// Yaw-steering body axes as the columns (x, y, z) of a rotation body → ECEF, for a satellite at
/// `position` (ECEF, m) with the Sun at `sun` (ECEF, m).
Eigen::Matrix3d yawSteeringAxes(const Eigen::Vector3d& position, const Eigen::Vector3d& sun);

/// RINEX bands of the reference ionosphere-free pair of a system (see above), e.g. GPS {'1','2'}.
std::pair<char, char> referenceFrequencyPair(System system);

/// The body-frame PCO (m) of the reference ionosphere-free pair of an antenna entry; the PCO of a
/// single frequency of the system when the entry lacks one of the pair (the first listed);
/// nullopt when it has no frequency of the system.
std::optional<Eigen::Vector3d> ionosphereFreeOffset(const AntexAntenna& antenna, System system);

/// ECEF offset (m) centre of mass → antenna phase centre of `sat` at `t`, its centre of mass at
/// `position`; nullopt when `antex` has no valid entry for the satellite.
std::optional<Eigen::Vector3d> satelliteAntennaOffset(const AntexData& antex, SatId sat, const GpsTime& t,
                                                      const Eigen::Vector3d& position);

}  // namespace gvins
