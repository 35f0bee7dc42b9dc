// Time and place of the bundled nagoya_static_2024 recording (tests/data/gnss/nagoya_static_2024,
// see tests/data/README.md): 2024-06-24, observations 08:20-08:25 GPST, broadcast records in
// base.nav.gz valid 08:00-10:00. Shared by the tests of several modules.
#pragma once

#include "gvins/base/gnss_time.hpp"

namespace gvins::test {

/// 2024-06-24 hour:minute:second GPST.
inline GpsTime nagoyaTime(int hour = 8, int minute = 20, double second = 0.0) {
  CalendarTime c;
  c.year = 2024;
  c.month = 6;
  c.day = 24;
  c.hour = hour;
  c.minute = minute;
  c.second = second;
  return GpsTime::fromCalendar(c);
}

}  // namespace gvins::test
