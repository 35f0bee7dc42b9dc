#include "gvins/ubx/nav_solution.hpp"

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
  p.nano = r.i4(16, "nano");
  p.fixType = r.u1(20, "fixType");
  p.flags = r.u1(21, "flags");
  p.numSv = r.u1(23, "numSV");
  p.lonDeg = r.i4(24, "lon") * 1e-7;
  p.latDeg = r.i4(28, "lat") * 1e-7;
  p.height = r.i4(32, "height") * 1e-3;
  p.hAcc = r.u4(40, "hAcc") * 1e-3;
  p.vAcc = r.u4(44, "vAcc") * 1e-3;
  p.velN = r.i4(48, "velN") * 1e-3;
  p.velE = r.i4(52, "velE") * 1e-3;
  p.velD = r.i4(56, "velD") * 1e-3;
  if (p.timeValid() && (p.month < 1 || p.month > 12 || p.day < 1 || p.day > 31 || p.hour > 23 ||
                        p.minute > 59 || p.second > 60)) {
    throw rtcm::MessageError("valid", "date/time flagged valid but out of range");
  }
  return p;
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
