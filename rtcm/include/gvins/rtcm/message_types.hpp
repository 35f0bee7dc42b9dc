// RTCM 3 message numbers: descriptions (RTCM 10403.3, table 3.5-1 and later amendments) and
// the classification of the Multiple Signal Messages (MSM, section 3.5.12).
#pragma once

#include <optional>
#include <string_view>

#include "gvins/base/satellite.hpp"

namespace gvins::rtcm {

/// Short English description of a message number ("GPS MSM7", "Station ARP (1005)", ...);
/// "unknown" for numbers the standard does not define, "proprietary" for 4001-4095.
std::string_view messageDescription(int type);

/// Whether this decoder decodes the message (others are counted and skipped).
bool isDecodedType(int type);

/// MSM classification of a message number: 107x GPS, 108x GLONASS, 109x Galileo, 110x SBAS,
/// 111x QZSS, 112x BeiDou, 113x NavIC, x = 1..7 the MSM type.
struct MsmKind {
  System system;
  int msm;  ///< 1..7
};
std::optional<MsmKind> msmKind(int type);
/// Message number of an MSM type for a system (e.g. Gps, 7 -> 1077); 0 if none.
int msmMessageNumber(System system, int msm);

}  // namespace gvins::rtcm
