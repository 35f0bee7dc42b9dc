#include <gtest/gtest.h>

#include "gvins/base/gnss_time.hpp"

using namespace gvins;

TEST(GnssTime, WeekAndTowOfKnownDates) {
  // GPS week 2320 starts Sunday 2024-06-23 (week numbers from the nagoya base.nav header).
  const GpsTime t = GpsTime::fromCalendar({2024, 6, 24, 8, 20, 0.0});
  EXPECT_EQ(t.week(), 2320);
  EXPECT_DOUBLE_EQ(t.tow(), 86400.0 + 8 * 3600 + 20 * 60);
  // The GPS epoch and the first rollover (1999-08-22 = week 1024).
  EXPECT_EQ(GpsTime::fromCalendar({1980, 1, 6, 0, 0, 0}).wholeSeconds(), 0);
  EXPECT_EQ(GpsTime::fromCalendar({1999, 8, 22, 0, 0, 0}).week(), 1024);
  EXPECT_EQ(GpsTime::fromCalendar({2019, 4, 7, 0, 0, 0}).week(), 2048);
}

TEST(GnssTime, CalendarRoundTripAndString) {
  const CalendarTime c{2005, 4, 2, 23, 59, 59.9999996};
  const GpsTime t = GpsTime::fromCalendar(c);
  const CalendarTime back = t.toCalendar();
  EXPECT_EQ(back.year, 2005);
  EXPECT_EQ(back.day, 2);
  EXPECT_EQ(back.minute, 59);
  EXPECT_NEAR(back.second, 59.9999996, 1e-12);
  // Rounding to 3 decimals carries into the next day.
  EXPECT_EQ(t.toString(3), "2005-04-03 00:00:00.000");
  EXPECT_EQ(t.toString(7), "2005-04-02 23:59:59.9999996");
}

TEST(GnssTime, SubNanosecondArithmeticOverDecades) {
  const GpsTime a = GpsTime::fromCalendar({2024, 6, 24, 8, 20, 0.0});
  GpsTime b = a;
  for (int i = 0; i < 1000; ++i) b += 1e-10;  // 100 ns in 0.1 ns steps
  EXPECT_NEAR(b - a, 1e-7, 1e-15);
  const GpsTime c = a + 0.123456789012;
  EXPECT_NEAR(c - a, 0.123456789012, 1e-13);
  EXPECT_NEAR((a - 1.5) - a, -1.5, 0.0);
  EXPECT_LT(a, c);
  EXPECT_EQ(a + 0.0, a);
}

TEST(GnssTime, NegativeTowAndWeekNormalisation) {
  const GpsTime t = GpsTime::fromWeekTow(2000, -1.25);
  EXPECT_EQ(t.week(), 1999);
  EXPECT_DOUBLE_EQ(t.tow(), 604800.0 - 1.25);
  const GpsTime u = GpsTime::fromWeekTow(2000, 604800.0 + 3.0);
  EXPECT_EQ(u.week(), 2001);
  EXPECT_DOUBLE_EQ(u.tow(), 3.0);
}

TEST(GnssTime, LeapSecondsFromIersTable) {
  EXPECT_EQ(leapSecondsAtUtc({1980, 1, 6, 0, 0, 0}), 0);
  EXPECT_EQ(leapSecondsAtUtc({2005, 4, 2, 0, 0, 0}), 13);  // geonet RINEX 2 header: 13
  EXPECT_EQ(leapSecondsAtUtc({2016, 12, 31, 23, 59, 59}), 17);
  EXPECT_EQ(leapSecondsAtUtc({2017, 1, 1, 0, 0, 0}), 18);
  EXPECT_EQ(leapSecondsAtUtc({2024, 6, 24, 0, 0, 0}), 18);  // nagoya nav header: 18
  // The leap second of 2016-12-31: UTC 2017-01-01 00:00:00 is GPST 2017-01-01 00:00:18.
  const GpsTime g = utcToGpst({2017, 1, 1, 0, 0, 0});
  EXPECT_EQ(g.toString(0), "2017-01-01 00:00:18");
  EXPECT_EQ(leapSecondsAtGpst(g), 18);
  EXPECT_EQ(leapSecondsAtGpst(g - 1.0), 17);
  const CalendarTime u = gpstToUtc(GpsTime::fromCalendar({2024, 6, 24, 8, 20, 18.5}));
  EXPECT_EQ(u.hour, 8);
  EXPECT_EQ(u.minute, 20);
  EXPECT_DOUBLE_EQ(u.second, 0.5);
}

TEST(GnssTime, GalileoBeiDouGlonassScales) {
  const GpsTime t = GpsTime::fromCalendar({2021, 3, 19, 12, 0, 0.0});
  int w = 0;
  double tow = 0;
  gpstToGst(t, w, tow);
  EXPECT_EQ(w, t.week() - 1024);
  EXPECT_EQ(gstToGpst(w, tow), t);
  gpstToBdt(t, w, tow);
  EXPECT_EQ(w, t.week() - 1356);
  EXPECT_DOUBLE_EQ(tow, t.tow() - 14.0);
  EXPECT_EQ(bdtToGpst(w, tow), t);
  // BDT week 0 day 0 = 2006-01-01 00:00:00 UTC = GPST 00:00:14.
  EXPECT_EQ(bdtToGpst(0, 0.0).toString(0), "2006-01-01 00:00:14");
  // GLONASS time = UTC + 3 h.
  const CalendarTime m = gpstToGlonass(t);
  EXPECT_EQ(m.hour, 14);
  EXPECT_EQ(m.minute, 59);
  EXPECT_DOUBLE_EQ(m.second, 42.0);
  EXPECT_EQ(glonassToGpst(m), t);
}

TEST(GnssTime, WeekRolloverResolution) {
  const GpsTime ref = GpsTime::fromCalendar({2024, 6, 24, 0, 0, 0});
  EXPECT_EQ(resolveWeek(2320 % 1024, 10, ref), 2320);
  EXPECT_EQ(resolveWeek(2320 % 8192, 13, ref), 2320);
  // Week 1023 seen just after a rollover resolves backwards.
  EXPECT_EQ(resolveWeek(1023, 10, GpsTime::fromWeekTow(2048, 10.0)), 2047);
  // Time of week near the week boundary resolves to the previous week.
  const GpsTime r = GpsTime::fromWeekTow(2000, 5.0);
  const GpsTime n = nearestTow(604790.0, r);
  EXPECT_EQ(n.week(), 1999);
  EXPECT_NEAR(n - r, -15.0, 1e-12);
}

TEST(GnssTime, CalendarHelpers) {
  EXPECT_EQ(dayOfYear(2024, 12, 31), 366);
  EXPECT_EQ(dayOfYear(2005, 4, 2), 92);  // "07590920.05o" is day 092
  EXPECT_DOUBLE_EQ(modifiedJulianDate({1858, 11, 17, 0, 0, 0}), 0.0);
  EXPECT_DOUBLE_EQ(modifiedJulianDate({2000, 1, 1, 12, 0, 0}), 51544.5);
  EXPECT_TRUE(isValidCalendar({2024, 2, 29, 0, 0, 0}));
  EXPECT_FALSE(isValidCalendar({2023, 2, 29, 0, 0, 0}));
  EXPECT_FALSE(isValidCalendar({2023, 13, 1, 0, 0, 0}));
  EXPECT_FALSE(isValidCalendar({2023, 1, 1, 24, 0, 0}));
}
