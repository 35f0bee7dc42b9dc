#include "product_time_scale.hpp"

namespace gvins {
namespace {
constexpr double kTaiMinusGpst = 19.0;  // TAI - GPST, s (constant since the GPS epoch)
}

bool isProductTimeSystem(std::string_view ts) {
  return ts == "GPS" || ts == "GLO" || ts == "GAL" || ts == "BDT" || ts == "QZS" || ts == "IRN" ||
         ts == "TAI" || ts == "UTC";
}

GpsTime productTimeToGpst(const CalendarTime& c, std::string_view ts) {
  if (ts == "UTC") return utcToGpst(c);
  if (ts == "GLO") return glonassToGpst(c);
  GpsTime t = GpsTime::fromCalendar(c);
  if (ts == "BDT") t -= kBdtMinusGpst;  // GPST = BDT + 14 s
  if (ts == "TAI") t -= kTaiMinusGpst;  // GPST = TAI - 19 s
  return t;
}

CalendarTime gpstToProductTime(const GpsTime& t, std::string_view ts) {
  if (ts == "UTC") return gpstToUtc(t);
  if (ts == "GLO") return gpstToGlonass(t);
  if (ts == "BDT") return (t + kBdtMinusGpst).toCalendar();
  if (ts == "TAI") return (t + kTaiMinusGpst).toCalendar();
  return t.toCalendar();
}

}  // namespace gvins
