// MSM signal identifiers (the 32 bits of the signal mask, DF395) and their RINEX 3 observation
// codes, and MSM satellite identifiers (the 64 bits of the satellite mask, DF394) and satellites.
// Tables: RTCM 10403.3 tables 3.5-91 (GPS), 3.5-96 (GLONASS), 3.5-99 (Galileo), 3.5-102 (SBAS),
// 3.5-105 (QZSS), 3.5-108 (BeiDou, with the BDS-3 B1C/B2a/B2b IDs of amendment 1).
#pragma once

#include <optional>

#include "gvins/base/satellite.hpp"
#include "gvins/base/signal.hpp"

namespace gvins::rtcm {

/// RINEX code of MSM signal ID 1..32 of a system; std::nullopt for reserved IDs.
std::optional<ObsCode> msmSignalCode(System system, int signalId);
/// Inverse: the MSM signal ID (1..32) of a RINEX code, or std::nullopt if MSM cannot carry it.
std::optional<int> msmSignalId(System system, ObsCode code);

/// Satellite of MSM satellite ID 1..64 (GPS G01-G32, GLONASS slots, Galileo E01-E36, SBAS
/// PRN 120+ID-1 -> S20..., QZSS PRN 193+ID-1 -> J01..., BeiDou C01-C63); std::nullopt if the
/// ID is outside what gvins::SatId can represent.
std::optional<SatId> msmSatellite(System system, int satId);
/// Inverse: MSM satellite ID (1..64) of a satellite.
int msmSatelliteId(SatId sat);

}  // namespace gvins::rtcm
