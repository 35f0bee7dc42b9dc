#include "gvins/gnss/troposphere.hpp"

#include "gvins/gnss/meteo_climatology.hpp"
#include "gvins/gnss/saastamoinen.hpp"

namespace gvins {

double fractionalDayOfYear(const GpsTime& t) {
  const CalendarTime c = t.toCalendar();
  return dayOfYear(c.year, c.month, c.day) + (c.hour + c.minute / 60.0 + c.second / 3600.0) / 24.0;
}

StationTroposphere StationTroposphere::at(const Geodetic& station, double dayOfYear, TroposphereMeteo meteo,
                                          double relativeHumidity) {
  StationTroposphere s;
  if (meteo == TroposphereMeteo::Off || station.height < -500.0 || station.height > 20000.0) return s;
  const SurfaceMeteo m = meteo == TroposphereMeteo::Climatology ? climatologicalMeteo(station.lat, station.height, dayOfYear)
                                                                : standardAtmosphere(station.height, relativeHumidity);
  s.zenithHydrostatic = saastamoinenZenithHydrostatic(m.pressure, station.lat, station.height);
  s.zenithWet = saastamoinenZenithWet(m.temperature, m.waterVapour);
  s.niell = niellCoefficients(station, dayOfYear);
  return s;
}

TroposphereDelay StationTroposphere::slant(double elevation) const {
  TroposphereDelay d;
  d.zenithHydrostatic = zenithHydrostatic;
  d.zenithWet = zenithWet;
  const MappingFactors mf = niellMapping(niell, elevation);
  d.mapHydrostatic = mf.hydrostatic;
  d.mapWet = mf.wet;
  d.slant = zenithHydrostatic * mf.hydrostatic + zenithWet * mf.wet;
  return d;
}

TroposphereDelay slantTroposphereDelay(const Geodetic& station, double elevation, const GpsTime& t,
                                       double relativeHumidity) {
  if (station.height < -500.0 || station.height > 20000.0 || elevation <= 0.0) return {};
  return StationTroposphere::at(station, fractionalDayOfYear(t), TroposphereMeteo::StandardAtmosphere, relativeHumidity)
      .slant(elevation);
}

}  // namespace gvins
