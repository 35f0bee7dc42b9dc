// Time helpers shared by the broadcast ephemeris decoders (RTCM ephemeris messages and u-blox
// SFRBX navigation data): both must fill the records identically. Not installed.
#pragma once

#include "gvins/base/gnss_time.hpp"

namespace gvins::rtcm {

/// Moves t by whole weeks so that it is within half a week of `near`.
GpsTime nearWeek(GpsTime t, const GpsTime& near);

/// GLONASS time of day (Moscow, s) as the GPST instant nearest `near`.
GpsTime glonassTodNear(double tod, const GpsTime& near);

/// GPS/QZSS LNAV fit interval in hours from the fit interval flag and IODC
/// (IS-GPS-200 20.3.4.4, table 20-XII).
double gpsFitHours(bool flag, int iodc);

}  // namespace gvins::rtcm
