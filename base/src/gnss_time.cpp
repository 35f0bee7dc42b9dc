#include "gvins/base/gnss_time.hpp"

#include <array>
#include <cmath>
#include <cstdio>

namespace gvins {
namespace {

constexpr std::int64_t kSecondsPerDay = 86400;
// 1980-01-06 is day 3657 after 1970-01-01.
constexpr std::int64_t kGpsEpochDays = 3657;

struct LeapEntry {
  int year, month, day;  // UTC date from which the offset applies
  int gpstMinusUtc;
};
// IERS Bulletin C history of UTC leap seconds, expressed as GPST - UTC
// (GPS ICD IS-GPS-200 20.3.3.5.2.4: GPST was UTC at 1980-01-06).
constexpr std::array<LeapEntry, 18> kLeapTable{{
    {1981, 7, 1, 1},  {1982, 7, 1, 2},  {1983, 7, 1, 3},  {1985, 7, 1, 4},  {1988, 1, 1, 5},
    {1990, 1, 1, 6},  {1991, 1, 1, 7},  {1992, 7, 1, 8},  {1993, 7, 1, 9},  {1994, 7, 1, 10},
    {1996, 1, 1, 11}, {1997, 7, 1, 12}, {1999, 1, 1, 13}, {2006, 1, 1, 14}, {2009, 1, 1, 15},
    {2012, 7, 1, 16}, {2015, 7, 1, 17}, {2017, 1, 1, 18},
}};

std::int64_t secondsOfDate(int y, int m, int d) {
  return (daysFromCivil(y, m, d) - kGpsEpochDays) * kSecondsPerDay;
}

// GPST-UTC for an instant given as UTC seconds counted like GPST seconds from 1980-01-06.
int leapAtUtcSeconds(std::int64_t utcSec) {
  for (auto it = kLeapTable.rbegin(); it != kLeapTable.rend(); ++it) {
    if (utcSec >= secondsOfDate(it->year, it->month, it->day)) return it->gpstMinusUtc;
  }
  return 0;
}

}  // namespace

// Howard Hinnant's days_from_civil algorithm (public-domain description, "chrono-Compatible
// Low-Level Date Algorithms").
std::int64_t daysFromCivil(int year, int month, int day) {
  const std::int64_t y = static_cast<std::int64_t>(year) - (month <= 2 ? 1 : 0);
  const std::int64_t era = (y >= 0 ? y : y - 399) / 400;
  const std::int64_t yoe = y - era * 400;
  const std::int64_t mp = (month + 9) % 12;
  const std::int64_t doy = (153 * mp + 2) / 5 + day - 1;
  const std::int64_t doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + doe - 719468;
}

void civilFromDays(std::int64_t z, int& year, int& month, int& day) {
  z += 719468;
  const std::int64_t era = (z >= 0 ? z : z - 146096) / 146097;
  const std::int64_t doe = z - era * 146097;
  const std::int64_t yoe = (doe - doe / 1460 + doe / 36524 - doe / 146096) / 365;
  const std::int64_t doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
  const std::int64_t mp = (5 * doy + 2) / 153;
  day = static_cast<int>(doy - (153 * mp + 2) / 5 + 1);
  month = static_cast<int>(mp < 10 ? mp + 3 : mp - 9);
  year = static_cast<int>(yoe + era * 400 + (month <= 2 ? 1 : 0));
}

int dayOfYear(int year, int month, int day) {
  return static_cast<int>(daysFromCivil(year, month, day) - daysFromCivil(year, 1, 1)) + 1;
}

double modifiedJulianDate(const CalendarTime& t) {
  // MJD 0 = 1858-11-17 00:00.
  const std::int64_t days = daysFromCivil(t.year, t.month, t.day) - daysFromCivil(1858, 11, 17);
  return static_cast<double>(days) + (t.hour * 3600.0 + t.minute * 60.0 + t.second) / 86400.0;
}

bool isValidCalendar(const CalendarTime& t) {
  if (t.month < 1 || t.month > 12 || t.day < 1) return false;
  static constexpr int kDays[] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  const bool leap = (t.year % 4 == 0 && t.year % 100 != 0) || t.year % 400 == 0;
  const int maxDay = kDays[t.month - 1] + (t.month == 2 && leap ? 1 : 0);
  if (t.day > maxDay) return false;
  if (t.hour < 0 || t.hour > 23 || t.minute < 0 || t.minute > 59) return false;
  return t.second >= 0.0 && t.second < 61.0;
}

GpsTime GpsTime::fromSeconds(std::int64_t whole, double fraction) {
  GpsTime t;
  t.sec_ = whole;
  t.frac_ = 0.0;
  t += fraction;
  return t;
}

GpsTime GpsTime::fromWeekTow(int week, double tow) {
  GpsTime t;
  t.sec_ = static_cast<std::int64_t>(week) * 604800;
  t += tow;
  return t;
}

GpsTime GpsTime::fromCalendar(const CalendarTime& c) {
  GpsTime t;
  t.sec_ = secondsOfDate(c.year, c.month, c.day) + c.hour * 3600 + c.minute * 60;
  t += c.second;
  return t;
}

GpsTime& GpsTime::operator+=(double seconds) {
  const double whole = std::floor(seconds);
  sec_ += static_cast<std::int64_t>(whole);
  frac_ += seconds - whole;
  const double carry = std::floor(frac_);
  if (carry != 0.0) {
    sec_ += static_cast<std::int64_t>(carry);
    frac_ -= carry;
  }
  if (frac_ >= 1.0) {  // rounding can leave exactly 1.0
    sec_ += 1;
    frac_ -= 1.0;
  }
  if (frac_ < 0.0) frac_ = 0.0;
  return *this;
}

int GpsTime::week() const {
  std::int64_t w = sec_ / 604800;
  if (sec_ < 0 && sec_ % 604800 != 0) --w;
  return static_cast<int>(w);
}

double GpsTime::tow() const {
  return static_cast<double>(sec_ - static_cast<std::int64_t>(week()) * 604800) + frac_;
}

CalendarTime GpsTime::toCalendar() const {
  std::int64_t days = sec_ / kSecondsPerDay;
  std::int64_t sod = sec_ % kSecondsPerDay;
  if (sod < 0) {
    sod += kSecondsPerDay;
    --days;
  }
  CalendarTime c;
  civilFromDays(days + kGpsEpochDays, c.year, c.month, c.day);
  c.hour = static_cast<int>(sod / 3600);
  c.minute = static_cast<int>((sod % 3600) / 60);
  c.second = static_cast<double>(sod % 60) + frac_;
  return c;
}

std::string GpsTime::toString(int decimals) const {
  if (decimals < 0) decimals = 0;
  if (decimals > 9) decimals = 9;
  const std::int64_t scale = [&] {
    std::int64_t s = 1;
    for (int i = 0; i < decimals; ++i) s *= 10;
    return s;
  }();
  std::int64_t units = std::llround(frac_ * static_cast<double>(scale));
  GpsTime whole = fromSeconds(sec_);
  if (units >= scale) {
    whole = fromSeconds(sec_ + 1);
    units -= scale;
  }
  const CalendarTime c = whole.toCalendar();
  char buf[64];
  const int sec = static_cast<int>(c.second);
  if (decimals == 0) {
    std::snprintf(buf, sizeof buf, "%04d-%02d-%02d %02d:%02d:%02d", c.year, c.month, c.day, c.hour,
                  c.minute, sec);
  } else {
    std::snprintf(buf, sizeof buf, "%04d-%02d-%02d %02d:%02d:%02d.%0*lld", c.year, c.month, c.day,
                  c.hour, c.minute, sec, decimals, static_cast<long long>(units));
  }
  return buf;
}

int leapSecondsAtGpst(const GpsTime& gpst) {
  for (auto it = kLeapTable.rbegin(); it != kLeapTable.rend(); ++it) {
    if (gpst.wholeSeconds() >= secondsOfDate(it->year, it->month, it->day) + it->gpstMinusUtc) {
      return it->gpstMinusUtc;
    }
  }
  return 0;
}

int leapSecondsAtUtc(const CalendarTime& utc) {
  return leapAtUtcSeconds(GpsTime::fromCalendar(utc).wholeSeconds());
}

GpsTime utcToGpst(const CalendarTime& utc) {
  const GpsTime asIf = GpsTime::fromCalendar(utc);
  return asIf + static_cast<double>(leapAtUtcSeconds(asIf.wholeSeconds()));
}

CalendarTime gpstToUtc(const GpsTime& gpst) {
  return (gpst - static_cast<double>(leapSecondsAtGpst(gpst))).toCalendar();
}

GpsTime gstToGpst(int gstWeek, double tow) { return GpsTime::fromWeekTow(gstWeek + kGstWeekOffset, tow); }

void gpstToGst(const GpsTime& t, int& gstWeek, double& tow) {
  gstWeek = t.week() - kGstWeekOffset;
  tow = t.tow();
}

GpsTime bdtToGpst(int bdtWeek, double tow) {
  return GpsTime::fromWeekTow(bdtWeek + kBdtWeekOffset, tow) - kBdtMinusGpst;
}

void gpstToBdt(const GpsTime& t, int& bdtWeek, double& tow) {
  const GpsTime b = t + kBdtMinusGpst;
  bdtWeek = b.week() - kBdtWeekOffset;
  tow = b.tow();
}

GpsTime glonassToGpst(const CalendarTime& moscow) {
  const GpsTime utcAsIf = GpsTime::fromCalendar(moscow) - 10800.0;
  return utcAsIf + static_cast<double>(leapAtUtcSeconds(utcAsIf.wholeSeconds()));
}

CalendarTime gpstToGlonass(const GpsTime& gpst) {
  return (gpst - static_cast<double>(leapSecondsAtGpst(gpst)) + 10800.0).toCalendar();
}

int resolveWeek(int truncatedWeek, int bits, const GpsTime& reference) {
  const int mod = 1 << bits;
  const int refWeek = reference.week();
  const double k = std::round(static_cast<double>(refWeek - truncatedWeek) / mod);
  return truncatedWeek + static_cast<int>(k) * mod;
}

GpsTime nearestTow(double tow, const GpsTime& reference) {
  GpsTime t = GpsTime::fromWeekTow(reference.week(), tow);
  const double d = t - reference;
  if (d > kSecondsPerWeek / 2) t -= kSecondsPerWeek;
  else if (d < -kSecondsPerWeek / 2) t += kSecondsPerWeek;
  return t;
}

}  // namespace gvins
