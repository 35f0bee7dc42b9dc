// GNSS time: a GPST instant kept as whole seconds since the GPS epoch plus a fraction, so that
// sums and differences stay exact to far below a nanosecond over any span of GNSS history.
// Conversions to and from calendar dates, GPS/Galileo/BeiDou week numbering, UTC (leap-second
// table) and GLONASS time (UTC(SU) + 3 h).
#pragma once

#include <compare>
#include <cstdint>
#include <string>

namespace gvins {

/// Calendar date and time of day in whatever time scale the caller states.
struct CalendarTime {
  int year = 1980;
  int month = 1;
  int day = 6;
  int hour = 0;
  int minute = 0;
  double second = 0.0;
};

/// An instant in GPS time (GPST).
///
/// Stored as integer seconds since 1980-01-06 00:00:00 GPST and a fraction in [0, 1), which keeps
/// femtosecond resolution; arithmetic with doubles renormalises the fraction.
class GpsTime {
 public:
  constexpr GpsTime() = default;

  /// From GPS week (full, not modulo 1024) and time of week in seconds (may exceed a week or be
  /// negative; it is normalised).
  static GpsTime fromWeekTow(int week, double tow);
  /// From seconds since the GPS epoch split into whole and fractional parts.
  static GpsTime fromSeconds(std::int64_t whole, double fraction = 0.0);
  /// From a calendar date/time read as GPST.
  static GpsTime fromCalendar(const CalendarTime& gpst);

  int week() const;
  double tow() const;
  /// Whole seconds since the GPS epoch.
  std::int64_t wholeSeconds() const { return sec_; }
  /// Fraction of the second in [0, 1).
  double fraction() const { return frac_; }
  /// Seconds since the GPS epoch as a double (loses resolution below ~0.1 us; for display only).
  double toSecondsApprox() const { return static_cast<double>(sec_) + frac_; }

  /// Calendar date/time in GPST.
  CalendarTime toCalendar() const;
  /// "YYYY-MM-DD HH:MM:SS.sss" in GPST with the given number of decimals (0-9).
  std::string toString(int decimals = 3) const;

  GpsTime& operator+=(double seconds);
  GpsTime& operator-=(double seconds) { return *this += -seconds; }
  friend GpsTime operator+(GpsTime t, double s) { return t += s; }
  friend GpsTime operator-(GpsTime t, double s) { return t -= s; }
  /// Difference in seconds, exact in the whole-second part.
  friend double operator-(const GpsTime& a, const GpsTime& b) {
    return static_cast<double>(a.sec_ - b.sec_) + (a.frac_ - b.frac_);
  }
  friend auto operator<=>(const GpsTime&, const GpsTime&) = default;
  friend bool operator==(const GpsTime&, const GpsTime&) = default;

 private:
  std::int64_t sec_ = 0;
  double frac_ = 0.0;
};

/// Seconds in a GPS week.
inline constexpr double kSecondsPerWeek = 604800.0;

// ---- calendar helpers -----------------------------------------------------------------------

/// Days since 1970-01-01 of a proleptic Gregorian date (negative before).
std::int64_t daysFromCivil(int year, int month, int day);
/// Inverse of daysFromCivil.
void civilFromDays(std::int64_t days, int& year, int& month, int& day);
/// Day of year, 1-366.
int dayOfYear(int year, int month, int day);
/// Modified Julian Date of a calendar time (in its own scale).
double modifiedJulianDate(const CalendarTime& t);
/// Checks ranges of a calendar time (month 1-12, valid day, hour 0-23, minute 0-59,
/// second in [0, 61)); returns false for impossible dates.
bool isValidCalendar(const CalendarTime& t);

// ---- UTC and leap seconds ---------------------------------------------------------------------

/// GPST - UTC in whole seconds at the given GPST instant, from the built-in IERS leap-second
/// table (IERS Bulletin C; 18 s since 2017-01-01). Before 1981-07-01 it is 0.
int leapSecondsAtGpst(const GpsTime& gpst);
/// GPST - UTC for a UTC calendar instant.
int leapSecondsAtUtc(const CalendarTime& utc);
/// UTC calendar time (no leap-second smear; 23:59:60 is not produced) to GPST.
GpsTime utcToGpst(const CalendarTime& utc);
/// GPST to a UTC calendar time.
CalendarTime gpstToUtc(const GpsTime& gpst);

// ---- other GNSS time scales ---------------------------------------------------------------------

/// Galileo System Time: aligned with GPST (the GGTO of a few ns is a broadcast correction, not
/// part of the scale); GST week 0 began 1999-08-22 00:00 = GPS week 1024 (Galileo OS SIS ICD 5.1.2).
inline constexpr int kGstWeekOffset = 1024;
GpsTime gstToGpst(int gstWeek, double tow);
void gpstToGst(const GpsTime& t, int& gstWeek, double& tow);

/// BeiDou Time: BDT = GPST - 14 s; BDT week 0 began 2006-01-01 00:00:00 UTC = GPS week 1356
/// (BDS-SIS-ICD-B1I 3.0, sec. 4.2).
inline constexpr int kBdtWeekOffset = 1356;
inline constexpr double kBdtMinusGpst = -14.0;
GpsTime bdtToGpst(int bdtWeek, double tow);
void gpstToBdt(const GpsTime& t, int& bdtWeek, double& tow);

/// GLONASS time: UTC(SU) + 3 h (GLONASS ICD ed. 5.1, 3.3.3). Leap seconds follow UTC.
GpsTime glonassToGpst(const CalendarTime& moscow);
CalendarTime gpstToGlonass(const GpsTime& gpst);

/// Resolves a week number transmitted modulo 2^bits (e.g. 10 bits for GPS LNAV) to the full week
/// nearest to the week of the reference time.
int resolveWeek(int truncatedWeek, int bits, const GpsTime& reference);

/// Resolves a time of week (no week number) to the instant nearest to the reference time.
GpsTime nearestTow(double tow, const GpsTime& reference);

}  // namespace gvins
