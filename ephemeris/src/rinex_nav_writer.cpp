// RINEX 3.04 mixed navigation writer (RINEX 3.04 appendix: navigation header and GPS, Galileo,
// QZSS, BDS and GLONASS record layouts).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <numeric>
#include <ostream>
#include <string>

#include "gvins/ephemeris/rinex_nav.hpp"

namespace gvins {
namespace {


// Fortran D19.12 written with an 'E' exponent; magnitudes outside the two-digit exponent range
// are saturated (tiny values become 0) so that every field keeps its 19 columns.
void putNumber(std::string& s, double v) {
  if (!std::isfinite(v)) v = 0.0;
  if (std::fabs(v) < 1e-99) v = 0.0;
  if (v >= 1e99) v = 9.999999999999e98;
  if (v <= -1e99) v = -9.999999999999e98;
  char buf[32];
  std::snprintf(buf, sizeof buf, "%19.12E", v);
  s += buf;
}

void putLabel(std::ostream& out, std::string body, const char* label) {
  body.resize(60, ' ');
  out << body << label << '\n';
}

std::string epochText(const CalendarTime& c) {
  char buf[32];
  // Seconds are integral in navigation records; round (CalendarTime keeps the fraction).
  int sec = static_cast<int>(std::lround(c.second));
  std::snprintf(buf, sizeof buf, " %04d %02d %02d %02d %02d %02d", c.year, c.month, c.day, c.hour, c.minute,
                std::min(sec, 59));
  return buf;
}

// Continuation line: 4X, 4D19.12 (fewer values leave the line short, as RINEX allows).
void putOrbit(std::ostream& out, std::initializer_list<double> values) {
  std::string s = "    ";
  for (double v : values) putNumber(s, v);
  out << s << '\n';
}

// Seconds of `t` counted from the start of the week containing `ref` (may be negative or exceed a
// week, as RINEX 3.04 asks for the transmission time).
double secondsInWeekOf(const GpsTime& t, const GpsTime& ref) {
  return t - GpsTime::fromWeekTow(ref.week(), 0.0);
}

void writeKepler(std::ostream& out, const KeplerEphemeris& e) {
  const System sys = e.sat.system;
  const bool bds = sys == System::BeiDou;
  const double toGpst = bds ? -kBdtMinusGpst : 0.0;  // own time scale = GPST - toGpst
  const GpsTime tocOwn = e.toc - toGpst;
  const GpsTime toeOwn = e.toe - toGpst;
  std::string first = e.sat.str() + epochText(tocOwn.toCalendar());
  putNumber(first, e.af0);
  putNumber(first, e.af1);
  putNumber(first, e.af2);
  out << first << '\n';

  const int weekOwn = bds ? toeOwn.week() - kBdtWeekOffset : toeOwn.week();  // Galileo: GPS-aligned
  const double ttr = e.ttr == GpsTime{} ? 0.9999e9 : secondsInWeekOf(e.ttr - toGpst, toeOwn);
  putOrbit(out, {static_cast<double>(e.iode), e.crs, e.deltaN, e.m0});
  putOrbit(out, {e.cuc, e.e, e.cus, e.sqrtA});
  putOrbit(out, {toeOwn.tow(), e.cic, e.omega0, e.cis});
  putOrbit(out, {e.i0, e.crc, e.omega, e.omegaDot});
  switch (sys) {
    case System::Galileo: {
      int sources = e.codesOnL2;
      if (sources == 0 || galileoMessageFromDataSources(sources) != e.message) {
        // Data sources consistent with the message: I/NAV E1-B + E5b-I, clock for E5b,E1 (bits 0, 2,
        // 9); F/NAV E5a-I, clock for E5a,E1 (bits 1, 8) (RINEX 3.04 table A8).
        sources = e.message == NavMessage::GalileoFnav ? 0x102 : 0x205;
      }
      putOrbit(out, {e.iDot, static_cast<double>(sources), static_cast<double>(weekOwn), 0.0});
      putOrbit(out, {e.ura, static_cast<double>(e.health), e.tgd[0], e.tgd[1]});
      putOrbit(out, {ttr, 0.0});
      break;
    }
    case System::BeiDou:
      putOrbit(out, {e.iDot, 0.0, static_cast<double>(weekOwn), 0.0});
      putOrbit(out, {e.ura, static_cast<double>(e.health), e.tgd[0], e.tgd[1]});
      putOrbit(out, {ttr, static_cast<double>(e.iodc)});
      break;
    default: {  // GPS, QZSS LNAV
      putOrbit(out, {e.iDot, static_cast<double>(e.codesOnL2), static_cast<double>(weekOwn),
                     static_cast<double>(e.l2pDataFlag)});
      putOrbit(out, {e.ura, static_cast<double>(e.health), e.tgd[0], static_cast<double>(e.iodc)});
      // GPS: fit interval in hours; QZSS: the fit interval flag (0 = 2 h, 1 = longer).
      const double fit = sys == System::Qzss ? (e.fitInterval > 2.5 ? 1.0 : 0.0) : e.fitInterval;
      putOrbit(out, {ttr, fit});
      break;
    }
  }
}

void writeGlonass(std::ostream& out, const GlonassEphemeris& g) {
  // tb and the frame time are UTC in RINEX; the same leap-second offset is used for both.
  const CalendarTime tbUtc = gpstToUtc(g.toe);
  const GpsTime tbUtcInstant = GpsTime::fromCalendar(tbUtc);
  const double leap = g.toe - tbUtcInstant;
  const GpsTime tofUtc = g.tof == GpsTime{} ? tbUtcInstant : g.tof - leap;
  std::string first = g.sat.str() + epochText(tbUtc);
  putNumber(first, -g.tauN);
  putNumber(first, g.gammaN);
  putNumber(first, secondsInWeekOf(tofUtc, tbUtcInstant));
  out << first << '\n';
  putOrbit(out, {g.position.x() * 1e-3, g.velocity.x() * 1e-3, g.acceleration.x() * 1e-3,
                 static_cast<double>(g.health)});
  putOrbit(out, {g.position.y() * 1e-3, g.velocity.y() * 1e-3, g.acceleration.y() * 1e-3,
                 static_cast<double>(g.frequencyChannel)});
  putOrbit(out, {g.position.z() * 1e-3, g.velocity.z() * 1e-3, g.acceleration.z() * 1e-3,
                 static_cast<double>(g.age)});
}

void putIono(std::ostream& out, const char* type, const double* v, int n) {
  std::string s = type;
  s.resize(4, ' ');
  s += ' ';
  char buf[32];
  for (int i = 0; i < 4; ++i) {
    std::snprintf(buf, sizeof buf, "%12.4E", i < n ? v[i] : 0.0);
    s += buf;
  }
  putLabel(out, s, "IONOSPHERIC CORR");
}

}  // namespace

void writeRinexNav(std::ostream& out, const NavData& nav, std::string_view programName) {
  putLabel(out, "     3.04           N: GNSS NAV DATA    M: MIXED", "RINEX VERSION / TYPE");
  {
    char date[32];
    const std::time_t now = std::time(nullptr);
    std::tm utc{};
    gmtime_r(&now, &utc);
    std::strftime(date, sizeof date, "%Y%m%d %H%M%S UTC", &utc);
    std::string s(programName.substr(0, 20));
    s.resize(40, ' ');
    s += date;
    putLabel(out, s, "PGM / RUN BY / DATE");
  }
  if (nav.iono.gps) {
    putIono(out, "GPSA", nav.iono.gps->alpha.data(), 4);
    putIono(out, "GPSB", nav.iono.gps->beta.data(), 4);
  }
  if (nav.iono.galileo) putIono(out, "GAL", nav.iono.galileo->ai.data(), 3);
  if (nav.iono.qzss) {
    putIono(out, "QZSA", nav.iono.qzss->alpha.data(), 4);
    putIono(out, "QZSB", nav.iono.qzss->beta.data(), 4);
  }
  if (nav.iono.beidou) {
    putIono(out, "BDSA", nav.iono.beidou->alpha.data(), 4);
    putIono(out, "BDSB", nav.iono.beidou->beta.data(), 4);
  }
  for (const auto& c : nav.timeCorrections) {
    std::string type(c.type, 4);
    if (type.find('\0') != std::string::npos) continue;
    char buf[96];
    std::snprintf(buf, sizeof buf, "%-4s %17.10E%16.9E %6d %4d", type.c_str(), c.a0, c.a1,
                  static_cast<int>(std::lround(c.referenceTow)), c.referenceWeek);
    putLabel(out, buf, "TIME SYSTEM CORR");
  }
  if (nav.leapSeconds) {
    char buf[16];
    std::snprintf(buf, sizeof buf, "%6d", *nav.leapSeconds);
    putLabel(out, buf, "LEAP SECONDS");
  }
  putLabel(out, "", "END OF HEADER");

  // Records in time order, then by satellite (the order of most merged navigation files).
  struct Item {
    GpsTime t;
    SatId sat;
    bool glonass;
    std::size_t index;
  };
  std::vector<Item> items;
  items.reserve(nav.kepler.size() + nav.glonass.size());
  for (std::size_t i = 0; i < nav.kepler.size(); ++i) {
    const auto& e = nav.kepler[i];
    if (e.sat.system == System::Gps || e.sat.system == System::Galileo || e.sat.system == System::BeiDou ||
        e.sat.system == System::Qzss) {
      items.push_back({e.toc, e.sat, false, i});
    }
  }
  for (std::size_t i = 0; i < nav.glonass.size(); ++i) items.push_back({nav.glonass[i].toe, nav.glonass[i].sat, true, i});
  std::stable_sort(items.begin(), items.end(), [](const Item& a, const Item& b) {
    if (!(a.t == b.t)) return a.t < b.t;
    return a.sat < b.sat;
  });
  for (const auto& it : items) {
    if (it.glonass) writeGlonass(out, nav.glonass[it.index]);
    else writeKepler(out, nav.kepler[it.index]);
  }
}

}  // namespace gvins
