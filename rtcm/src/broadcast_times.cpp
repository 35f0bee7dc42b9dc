#include "broadcast_times.hpp"

#include <cmath>
#include <cstdint>

namespace gvins::rtcm {

GpsTime nearWeek(GpsTime t, const GpsTime& near) {
  const double d = t - near;
  if (d > kSecondsPerWeek / 2) t -= kSecondsPerWeek * std::round(d / kSecondsPerWeek);
  else if (d < -kSecondsPerWeek / 2) t += kSecondsPerWeek * std::round(-d / kSecondsPerWeek);
  return t;
}

GpsTime glonassTodNear(double tod, const GpsTime& near) {
  const std::int64_t leap = leapSecondsAtGpst(near);
  const std::int64_t glo = near.wholeSeconds() - leap + 10800;
  const double nearTod = static_cast<double>(((glo % 86400) + 86400) % 86400) + near.fraction();
  double d = tod - nearTod;
  if (d >= 43200.0) d -= 86400.0;
  if (d < -43200.0) d += 86400.0;
  return near + d;
}

double gpsFitHours(bool flag, int iodc) {
  if (!flag) return 4.0;
  if (iodc >= 240 && iodc <= 247) return 8.0;
  if ((iodc >= 248 && iodc <= 255) || iodc == 496) return 14.0;
  if ((iodc >= 497 && iodc <= 503) || (iodc >= 1021 && iodc <= 1023)) return 26.0;
  return 6.0;
}

}  // namespace gvins::rtcm
