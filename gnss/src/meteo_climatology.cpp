#include "gvins/gnss/meteo_climatology.hpp"

#include <algorithm>
#include <cmath>

#include "gvins/base/constants.hpp"

namespace gvins {

namespace {
// RTCA DO-229 table A-2: P0 (hPa), T0 (K), e0 (hPa), beta (K/m), lambda; then the seasonal
// variations of the same five quantities. Rows: 15, 30, 45, 60, 75 degrees latitude.
constexpr double kAverage[5][5] = {{1013.25, 299.65, 26.31, 6.30e-3, 2.77},
                                   {1017.25, 294.15, 21.79, 6.05e-3, 3.15},
                                   {1015.75, 283.15, 11.66, 5.58e-3, 2.57},
                                   {1011.75, 272.15, 6.78, 5.39e-3, 1.81},
                                   {1013.00, 263.65, 4.11, 4.53e-3, 1.55}};
constexpr double kSeasonal[5][5] = {{0.0, 0.0, 0.0, 0.0, 0.0},
                                    {-3.75, 7.0, 8.85, 0.25e-3, 0.33},
                                    {-2.25, 11.0, 7.24, 0.32e-3, 0.46},
                                    {-1.75, 15.0, 5.36, 0.81e-3, 0.74},
                                    {-0.50, 14.5, 3.39, 0.62e-3, 0.30}};
constexpr double kRd = 287.054;  // J/(kg K), dry-air gas constant (DO-229)
constexpr double kG = 9.80665;   // m/s^2
}  // namespace

SurfaceMeteo climatologicalMeteo(double latitude, double height, double dayOfYear) {
  const double absLat = std::abs(latitude) * constants::kRadToDeg;
  double avg[5], sea[5];
  const double f = std::clamp((absLat - 15.0) / 15.0, 0.0, 4.0);
  const int i = std::min(3, static_cast<int>(f));
  const double w = f - i;
  for (int k = 0; k < 5; ++k) {
    avg[k] = kAverage[i][k] + w * (kAverage[i + 1][k] - kAverage[i][k]);
    sea[k] = kSeasonal[i][k] + w * (kSeasonal[i + 1][k] - kSeasonal[i][k]);
  }
  const double doyMin = latitude >= 0.0 ? 28.0 : 211.0;
  const double c = std::cos(2.0 * 3.14159265358979323846 * (dayOfYear - doyMin) / 365.25);
  double v[5];
  for (int k = 0; k < 5; ++k) v[k] = avg[k] - sea[k] * c;
  const double p0 = v[0], t0 = v[1], e0 = v[2], beta = v[3], lambda = v[4];
  const double h = std::clamp(height, -500.0, 10000.0);
  const double ratio = std::max(1.0 - beta * h / t0, 0.1);
  SurfaceMeteo m;
  m.temperature = t0 - beta * h;
  m.pressure = p0 * std::pow(ratio, kG / (kRd * beta));
  m.waterVapour = e0 * std::pow(ratio, (lambda + 1.0) * kG / (kRd * beta));
  return m;
}

}  // namespace gvins
