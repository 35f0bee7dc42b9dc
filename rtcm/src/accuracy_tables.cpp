#include "gvins/rtcm/accuracy_tables.hpp"

#include <cmath>

namespace gvins::rtcm {

double uraMetres(int n) {
  if (n < 0) n = 0;
  if (n <= 6) return std::round(std::pow(2.0, 1.0 + n / 2.0) * 10.0) / 10.0;
  if (n < 15) return std::ldexp(1.0, n - 2);
  return 8192.0;
}

int uraIndex(double metres) {
  for (int n = 0; n < 15; ++n) {
    if (uraMetres(n) >= metres - 1e-9) return n;
  }
  return 15;
}

double sisaMetres(int n) {
  if (n < 0) return -1.0;
  if (n < 50) return n * 0.01;
  if (n < 75) return 0.5 + (n - 50) * 0.02;
  if (n < 100) return 1.0 + (n - 75) * 0.04;
  if (n < 126) return 2.0 + (n - 100) * 0.16;
  return -1.0;
}

int sisaIndex(double metres) {
  if (metres < 0.0 || metres > 6.0 + 1e-9) return 255;
  int best = 0;
  double bestErr = 1e9;
  for (int n = 0; n < 126; ++n) {
    const double e = std::abs(sisaMetres(n) - metres);
    if (e < bestErr) {
      bestErr = e;
      best = n;
    }
  }
  return best;
}

double glonassFtMetres(int ft) {
  static constexpr double kFt[15] = {1, 2, 2.5, 4, 5, 7, 10, 12, 14, 16, 32, 64, 128, 256, 512};
  return ft >= 0 && ft < 15 ? kFt[ft] : 0.0;
}

int glonassFtIndex(double metres) {
  if (metres <= 0.0) return 15;
  for (int ft = 0; ft < 15; ++ft) {
    if (glonassFtMetres(ft) >= metres - 1e-9) return ft;
  }
  return 14;
}

}  // namespace gvins::rtcm
