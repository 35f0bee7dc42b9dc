// Saastamoinen zenith tropospheric delays with a standard atmosphere.
#pragma once

#include "gvins/base/geodetic.hpp"

namespace gvins {

/// Surface meteorology: total pressure (hPa), temperature (K), water-vapour partial pressure (hPa).
struct SurfaceMeteo {
  double pressure = 1013.25;
  double temperature = 288.15;
  double waterVapour = 0.0;
};

/// Standard atmosphere at an ellipsoidal height (m, clamped to [-500, 10000]) with the given
/// relative humidity (0..1): pressure and temperature by the lapse-rate model of the U.S. Standard
/// Atmosphere 1976 (P = 1013.25 (1 - 2.2557e-5 h)^5.2568 hPa, T = 288.15 - 6.5e-3 h K), water
/// vapour pressure from the saturation formula e_s = 6.108 exp(17.15 (T-273.15)... ) in the form
/// e = RH * 6.108 * exp((17.15 T - 4684) / (T - 38.45)) hPa (Magnus-type, T in K).
SurfaceMeteo standardAtmosphere(double height, double relativeHumidity);

/// Zenith hydrostatic delay (m): Saastamoinen (1972) as written by Davis et al. (1985),
/// ZHD = 0.0022768 P / (1 - 0.00266 cos(2 lat) - 0.28e-6 h).
double saastamoinenZenithHydrostatic(double pressure, double latitude, double height);

/// Zenith wet delay (m): Saastamoinen (1972), ZWD = 0.002277 (1255 / T + 0.05) e.
double saastamoinenZenithWet(double temperature, double waterVapour);

}  // namespace gvins
