// Time scales of precise orbit and clock products (SP3 "%c" line, RINEX clock "TIME SYSTEM ID"):
// conversion of calendar epochs to and from GPST. Internal to gvins_ephemeris.
#pragma once

#include <string>
#include <string_view>

#include "gvins/base/gnss_time.hpp"

namespace gvins {

/// True for the time systems SP3-d (Hilla 2016, %c line) and RINEX clock 3.04 (TIME SYSTEM ID)
/// define: GPS, GLO, GAL, BDT, QZS, IRN, TAI, UTC.
bool isProductTimeSystem(std::string_view ts);

/// A calendar epoch of the given time system to GPST: GPS/GAL/QZS/IRN are GPST; BDT = GPST - 14 s
/// (BDS-SIS-ICD 4.2); TAI = GPST + 19 s (IERS Conventions 2010, ch. 10); UTC through the leap-second
/// table; GLO = UTC(SU) + 3 h (GLONASS ICD 3.3.3).
GpsTime productTimeToGpst(const CalendarTime& c, std::string_view ts);
/// Inverse of productTimeToGpst.
CalendarTime gpstToProductTime(const GpsTime& t, std::string_view ts);

}  // namespace gvins
