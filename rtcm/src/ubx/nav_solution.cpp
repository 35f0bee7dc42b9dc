#include "gvins/ubx/nav_solution.hpp"

#include <cmath>
#include <string>

#include "payload_reader.hpp"

namespace gvins::ubx {

NavPvt parseNavPvt(std::span<const std::uint8_t> payload) {
  const detail::PayloadReader r(payload);
  r.need(0, 92, "NAV-PVT length");
  NavPvt p;
  p.iTow = r.u4(0, "iTOW");
  p.year = r.u2(4, "year");
  p.month = r.u1(6, "month");
  p.day = r.u1(7, "day");
  p.hour = r.u1(8, "hour");
  p.minute = r.u1(9, "min");
  p.second = r.u1(10, "sec");
  p.valid = r.u1(11, "valid");
  p.tAcc = r.u4(12, "tAcc") * 1e-9;
  p.nano = r.i4(16, "nano");
  p.fixType = r.u1(20, "fixType");
  p.flags = r.u1(21, "flags");
  p.numSv = r.u1(23, "numSV");
  p.lonDeg = r.i4(24, "lon") * 1e-7;
  p.latDeg = r.i4(28, "lat") * 1e-7;
  p.height = r.i4(32, "height") * 1e-3;
  p.hMsl = r.i4(36, "hMSL") * 1e-3;
  p.hAcc = r.u4(40, "hAcc") * 1e-3;
  p.vAcc = r.u4(44, "vAcc") * 1e-3;
  p.velN = r.i4(48, "velN") * 1e-3;
  p.velE = r.i4(52, "velE") * 1e-3;
  p.velD = r.i4(56, "velD") * 1e-3;
  p.sAcc = r.u4(68, "sAcc") * 1e-3;
  p.pDop = r.u2(76, "pDOP") * 0.01;
  if (p.iTow >= 604800000u) throw rtcm::MessageError("iTOW", std::to_string(p.iTow) + " ms is not a time of week");
  if (std::abs(p.latDeg) > 90.0) throw rtcm::MessageError("lat", "latitude " + std::to_string(p.latDeg) + " deg out of range");
  if (std::abs(p.lonDeg) > 180.0) throw rtcm::MessageError("lon", "longitude " + std::to_string(p.lonDeg) + " deg out of range");
  if (p.carrierSolution() == 3) throw rtcm::MessageError("flags", "carrSoln 3 is reserved");
  if (p.timeValid() && (p.month < 1 || p.month > 12 || p.day < 1 || p.day > 31 || p.hour > 23 ||
                        p.minute > 59 || p.second > 60)) {
    throw rtcm::MessageError("valid", "date/time flagged valid but out of range");
  }
  return p;
}

NavPvtSolution navPvtSolution(const NavPvt& p) {
  if (!p.fixOk() || (p.fixType != 2 && p.fixType != 3 && p.fixType != 4)) return NavPvtSolution::None;
  if (p.fixType == 2) return NavPvtSolution::TwoD;
  if (p.carrierSolution() == 2) return NavPvtSolution::RtkFixed;
  if (p.carrierSolution() == 1) return NavPvtSolution::RtkFloat;
  return p.differential() ? NavPvtSolution::Differential : NavPvtSolution::Single;
}

GpsTime timeOfWeekNear(double tow, const GpsTime& near) {
  const int week = near.week();
  GpsTime best = GpsTime::fromWeekTow(week, tow);
  for (const int w : {week - 1, week + 1}) {
    const GpsTime t = GpsTime::fromWeekTow(w, tow);
    if (std::abs(t - near) < std::abs(best - near)) best = t;
  }
  return best;
}

std::optional<GpsTime> navPvtUtcAsGpst(const NavPvt& p) {
  if (!p.timeValid() || !p.fullyResolved()) return std::nullopt;
  const CalendarTime utc{p.year, p.month, p.day, p.hour, p.minute, static_cast<double>(p.second)};
  if (!isValidCalendar(utc)) return std::nullopt;
  return utcToGpst(utc) + p.nano * 1e-9;
}

NavClock parseNavClock(std::span<const std::uint8_t> payload) {
  const detail::PayloadReader r(payload);
  r.need(0, 20, "NAV-CLOCK length");
  NavClock c;
  c.iTow = r.u4(0, "iTOW");
  c.biasS = r.i4(4, "clkB") * 1e-9;
  c.driftSps = r.i4(8, "clkD") * 1e-9;
  c.timeAccS = r.u4(12, "tAcc") * 1e-9;
  c.freqAccSps = r.u4(16, "fAcc") * 1e-12;  // ps/s
  return c;
}

NavTimeGps parseNavTimeGps(std::span<const std::uint8_t> payload) {
  const detail::PayloadReader r(payload);
  r.need(0, 16, "NAV-TIMEGPS length");
  NavTimeGps t;
  t.iTow = r.u4(0, "iTOW");
  t.fTow = r.i4(4, "fTOW");
  t.week = r.i2(8, "week");
  t.leapS = r.i1(10, "leapS");
  t.valid = r.u1(11, "valid");
  return t;
}

}  // namespace gvins::ubx
