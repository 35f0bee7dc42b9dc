#include "gvins/gnss/troposphere.hpp"

#include "gvins/gnss/niell_mapping.hpp"
#include "gvins/gnss/saastamoinen.hpp"

namespace gvins {

TroposphereDelay slantTroposphereDelay(const Geodetic& station, double elevation, const GpsTime& t,
                                       double relativeHumidity) {
  TroposphereDelay d;
  if (station.height < -500.0 || station.height > 20000.0 || elevation <= 0.0) return d;
  const SurfaceMeteo m = standardAtmosphere(station.height, relativeHumidity);
  d.zenithHydrostatic = saastamoinenZenithHydrostatic(m.pressure, station.lat, station.height);
  d.zenithWet = saastamoinenZenithWet(m.temperature, m.waterVapour);
  const CalendarTime c = t.toCalendar();
  const double doy = dayOfYear(c.year, c.month, c.day) + (c.hour + c.minute / 60.0 + c.second / 3600.0) / 24.0;
  const MappingFactors mf = niellMapping(station, elevation, doy);
  d.mapHydrostatic = mf.hydrostatic;
  d.mapWet = mf.wet;
  d.slant = d.zenithHydrostatic * mf.hydrostatic + d.zenithWet * mf.wet;
  return d;
}

}  // namespace gvins
