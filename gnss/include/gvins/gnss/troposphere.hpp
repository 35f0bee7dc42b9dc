// Slant tropospheric delay: Saastamoinen zenith delays mapped with the Niell functions. The
// station part (zenith delays, mapping coefficients) is computed once per station and day and
// evaluated per elevation.
#pragma once

#include "gvins/base/geodetic.hpp"
#include "gvins/base/gnss_time.hpp"
#include "gvins/gnss/niell_mapping.hpp"

namespace gvins {

struct TroposphereDelay {
  double slant = 0.0;            ///< m
  double zenithHydrostatic = 0.0;
  double zenithWet = 0.0;
  double mapHydrostatic = 1.0;
  double mapWet = 1.0;
};

/// Surface meteorology behind the Saastamoinen zenith delays.
enum class TroposphereMeteo {
  Off,               ///< no tropospheric delay
  StandardAtmosphere,  ///< standard atmosphere with a relative humidity (saastamoinen.hpp)
  Climatology,       ///< latitude/season climatology (climatologicalMeteo)
};

/// Saastamoinen zenith delays and Niell mapping coefficients of one station and day.
struct StationTroposphere {
  double zenithHydrostatic = 0.0;  ///< m (0: no model, e.g. off or an implausible height)
  double zenithWet = 0.0;          ///< m
  NiellCoefficients niell;

  /// Station part for a geodetic position and fractional day of year; zero delays for `Off` or
  /// heights outside -500 m .. 20 km.
  static StationTroposphere at(const Geodetic& station, double dayOfYear, TroposphereMeteo meteo,
                               double relativeHumidity = 0.5);
  bool valid() const { return zenithHydrostatic > 0.0; }
  /// Slant delay and mapping factors at an elevation (rad; Niell clamps it to 1 degree).
  TroposphereDelay slant(double elevation) const;
};

/// Fractional day of year of a GPS time (UTC-free calendar day of GPST, as the models use it).
double fractionalDayOfYear(const GpsTime& t);

/// Slant delay for a station (geodetic), satellite elevation (rad) and time, from a standard
/// atmosphere with the given relative humidity: StationTroposphere::at(...).slant(elevation).
/// Stations below -500 m or above 20 km (e.g. an unconverged position) and elevations at or
/// below the horizon get zero delay.
TroposphereDelay slantTroposphereDelay(const Geodetic& station, double elevation, const GpsTime& t,
                                       double relativeHumidity = 0.5);

}  // namespace gvins
