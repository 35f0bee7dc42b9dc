// Differences between two satellite states (e.g. broadcast against precise products) in the
// satellite's radial / along-track / cross-track frame, and the signal-in-space range error
// (SISRE) they cause for users on the Earth.
//
// SISRE after Montenbruck, Steigenberger & Hauschild (2018), "Multi-GNSS signal-in-space range
// error assessment - Methodology and results", Adv. Space Res. 61(12), eq. (5) and Table 2:
// SISRE = sqrt((w_R·ΔR − c·Δt)² + w_AC²·(ΔA² + ΔC²)), with the global-average weights of each
// orbit type (GPS 0.98 / 1/49, GLONASS 0.98 / 1/45, Galileo 0.98 / 1/61, BeiDou MEO 0.98 / 1/54,
// BeiDou IGSO/GEO and QZSS 0.99 / 1/126).
#pragma once

#include "gvins/base/satellite.hpp"
#include "gvins/ephemeris/satellite_state.hpp"

namespace gvins {

/// state − reference, m: position in the reference's radial (along r), cross-track (along
/// r × v) and along-track (completing the triad) directions; clock as range (c·Δt).
struct OrbitDifference {
  double radial = 0.0, along = 0.0, cross = 0.0;
  double clock = 0.0;  ///< c·(clockBias − reference clockBias), m
};

OrbitDifference orbitDifference(const SatelliteState& state, const SatelliteState& reference);

struct SisreWeights {
  double radial = 0.98;            ///< w_R
  double alongCrossSquared = 1.0 / 49.0;  ///< w_AC²
};
/// Global-average weights of the satellite's orbit type (see the file comment).
SisreWeights sisreWeights(SatId sat);

/// SISRE of a difference, m. `clockOffset` (m) is subtracted from the clock difference first
/// (e.g. the mean over a constellation's satellites, the datum difference between two clock
/// products that every user absorbs in the receiver clock).
double sisre(SatId sat, const OrbitDifference& d, double clockOffset = 0.0);

}  // namespace gvins
