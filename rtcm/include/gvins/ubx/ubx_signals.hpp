// u-blox GNSS and signal identifiers (gnssId, svId, sigId of RXM-RAWX, RXM-SFRBX, NAV-SAT) to
// RINEX 3 satellites and observation codes. Tables from the u-blox ZED-F9P HPG 1.32 and X20 HPG
// 2.00 interface descriptions ("GNSS identifiers", "Signal identifiers") and RINEX 3.05 tables 4-10.
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>

#include "gvins/base/satellite.hpp"
#include "gvins/base/signal.hpp"

namespace gvins::ubx {

/// gnssId values: 0 GPS, 1 SBAS, 2 Galileo, 3 BeiDou, 4 IMES, 5 QZSS, 6 GLONASS, 7 NavIC.
std::optional<System> systemOfGnssId(std::uint8_t gnssId);

/// The RINEX satellite of a gnssId/svId pair (SBAS svId 120..158 -> S20..S58, QZSS svId 1..10 ->
/// J01..J10, GLONASS slot 1..27, 255 = unknown slot -> nullopt); nullopt for IMES, unknown
/// systems or numbers out of range.
std::optional<SatId> satelliteOf(std::uint8_t gnssId, std::uint8_t svId);

/// The RINEX 3 observation code of a gnssId/sigId pair; nullopt for reserved/unknown ids.
/// GPS: 0 L1C/A 1C, 3 L2 CL 2L, 4 L2 CM 2S, 6 L5 I 5I, 7 L5 Q 5Q. SBAS: 0 L1C/A 1C.
/// Galileo: 0 E1 C 1C, 1 E1 B 1B, 3 E5a I 5I, 4 E5a Q 5Q, 5 E5b I 7I, 6 E5b Q 7Q, 8 E6 B 6B,
/// 9 E6 C 6C, 10 E6 A 6A. BeiDou: 0/1 B1I D1/D2 2I, 2/3 B2I D1/D2 7I, 4/10 B3I D1/D2 6I, 5 B1C
/// pilot 1P, 6 B1C data 1D, 7 B2a pilot 5P, 8 B2a data 5D. QZSS: 0 L1C/A 1C, 1 L1S 1Z,
/// 4 L2 CM 2S, 5 L2 CL 2L, 8 L5 I 5I, 9 L5 Q 5Q. GLONASS: 0 L1 OF 1C, 2 L2 OF 2C.
/// NavIC: 0 L5 A 5A.
std::optional<ObsCode> obsCodeOf(std::uint8_t gnssId, std::uint8_t sigId);

/// A short u-blox style name of a signal ("GPS L1C/A", "BeiDou B2a pilot") for reports; "?" for
/// unknown ids.
std::string_view signalName(std::uint8_t gnssId, std::uint8_t sigId);

}  // namespace gvins::ubx
