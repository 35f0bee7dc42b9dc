// Slant tropospheric delay: Saastamoinen zenith delays mapped with the Niell functions.
#pragma once

#include "gvins/base/geodetic.hpp"
#include "gvins/base/gnss_time.hpp"

namespace gvins {

struct TroposphereDelay {
  double slant = 0.0;            ///< m
  double zenithHydrostatic = 0.0;
  double zenithWet = 0.0;
  double mapHydrostatic = 1.0;
  double mapWet = 1.0;
};

/// Slant delay for a station (geodetic), satellite elevation (rad) and time, from a standard
/// atmosphere with the given relative humidity. Stations below -500 m or above 20 km (e.g. an
/// unconverged position) get zero delay.
TroposphereDelay slantTroposphereDelay(const Geodetic& station, double elevation, const GpsTime& t,
                                       double relativeHumidity = 0.5);

}  // namespace gvins
