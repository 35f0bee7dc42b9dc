#include "gvins/gnss/saastamoinen.hpp"

#include <algorithm>
#include <cmath>

namespace gvins {

SurfaceMeteo standardAtmosphere(double height, double relativeHumidity) {
  const double h = std::clamp(height, -500.0, 10000.0);
  SurfaceMeteo m;
  m.pressure = 1013.25 * std::pow(1.0 - 2.2557e-5 * h, 5.2568);
  m.temperature = 288.15 - 6.5e-3 * h;
  const double rh = std::clamp(relativeHumidity, 0.0, 1.0);
  m.waterVapour = rh * 6.108 * std::exp((17.15 * m.temperature - 4684.0) / (m.temperature - 38.45));
  return m;
}

double saastamoinenZenithHydrostatic(double pressure, double latitude, double height) {
  return 0.0022768 * pressure / (1.0 - 0.00266 * std::cos(2.0 * latitude) - 0.28e-6 * height);
}

double saastamoinenZenithWet(double temperature, double waterVapour) {
  return 0.002277 * (1255.0 / temperature + 0.05) * waterVapour;
}

}  // namespace gvins
