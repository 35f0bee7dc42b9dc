// gvins-orbit: satellite positions, velocities and clocks from broadcast navigation files.
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "gvins/base/parse_error.hpp"
#include "gvins/ephemeris/ephemeris_store.hpp"

namespace {

const char* kUsage =
    "usage: gvins-orbit NAV... --time \"YYYY-MM-DD HH:MM:SS[.ffffff]\" [--gpst|--utc] [options]\n"
    "\n"
    "Prints the state of every satellite with a usable broadcast ephemeris at the given time\n"
    "(taken as the signal transmit time), one CSV row per satellite:\n"
    "  sat,x,y,z,vx,vy,vz,clock_s,drift_s_per_s\n"
    "RINEX 3 satellite ids (G05, R12, E07, C23, J02), ECEF position in m and velocity in m/s\n"
    "(WGS 84; GLONASS in PZ-90.11), satellite clock offset in s including the relativistic\n"
    "correction and without group delays, clock drift in s/s.\n"
    "\n"
    "NAV       RINEX navigation files, versions 2.10/2.11, 3.0x or 4.0x, plain or gzip-compressed;\n"
    "          several files are merged.\n"
    "--time T  epoch, \"YYYY-MM-DD HH:MM:SS\" with optional fraction (also \"YYYY-MM-DDTHH:MM:SS\").\n"
    "--gpst    T is GPS time (default).\n"
    "--utc     T is UTC (converted with the leap-second table).\n"
    "--unhealthy   also print satellites whose broadcast health flags them unhealthy.\n"
    "--realtime    use no ephemeris transmitted after T (as a real-time receiver would).\n"
    "-h, --help    this text.\n"
    "\n"
    "Record choice per satellite: nearest toe within the system's validity window (GPS/QZSS half\n"
    "the fit interval, Galileo 4 h with I/NAV preferred, BeiDou 2 h, GLONASS 30 min), healthy only\n"
    "unless --unhealthy. A summary (satellites per system, skipped records) goes to stderr.\n";

bool parseTime(const char* text, gvins::CalendarTime& c) {
  char sep = ' ';
  int n = 0;
  double sec = 0.0;
  if (std::sscanf(text, "%d-%d-%d%c%d:%d:%lf%n", &c.year, &c.month, &c.day, &sep, &c.hour, &c.minute, &sec, &n) != 7) {
    return false;
  }
  if ((sep != ' ' && sep != 'T') || text[n] != '\0') return false;
  c.second = sec;
  return c.year >= 1980 && c.year < 2200 && gvins::isValidCalendar(c) && c.second < 60.0;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> files;
  const char* timeText = nullptr;
  bool utc = false, unhealthy = false, realtime = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "-h" || a == "--help") {
      std::fputs(kUsage, stdout);
      return 0;
    } else if (a == "--time") {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "gvins-orbit: --time needs a value\n");
        return 2;
      }
      timeText = argv[++i];
    } else if (a == "--gpst") {
      utc = false;
    } else if (a == "--utc") {
      utc = true;
    } else if (a == "--unhealthy") {
      unhealthy = true;
    } else if (a == "--realtime") {
      realtime = true;
    } else if (a.size() > 1 && a[0] == '-') {
      std::fprintf(stderr, "gvins-orbit: unknown option '%s' (see --help)\n", a.c_str());
      return 2;
    } else {
      files.push_back(a);
    }
  }
  if (files.empty() || !timeText) {
    std::fprintf(stderr, "gvins-orbit: %s\n%s", files.empty() ? "no navigation file given" : "--time is required",
                 kUsage);
    return 2;
  }
  gvins::CalendarTime cal;
  if (!parseTime(timeText, cal)) {
    std::fprintf(stderr, "gvins-orbit: bad --time '%s' (expected \"YYYY-MM-DD HH:MM:SS[.ffffff]\")\n", timeText);
    return 2;
  }
  const gvins::GpsTime t = utc ? gvins::utcToGpst(cal) : gvins::GpsTime::fromCalendar(cal);

  gvins::EphemerisStore store;
  std::size_t skipped = 0;
  for (const auto& f : files) {
    try {
      const gvins::NavData nav = gvins::readRinexNav(f);
      skipped += nav.skipped.size();
      store.add(nav);
    } catch (const gvins::ParseError& e) {
      std::fprintf(stderr, "gvins-orbit: %s\n", e.what());
      return 1;
    }
  }

  gvins::EphemerisSelection policy;
  policy.allowUnhealthy = unhealthy;
  if (realtime) policy.futureTolerance = -1.0;
  int perSystem[gvins::kNumSystems] = {};
  std::printf("sat,x,y,z,vx,vy,vz,clock_s,drift_s_per_s\n");
  for (const gvins::SatId sat : store.satellites()) {
    const auto st = store.satelliteState(sat, t, policy);
    if (!st) continue;
    std::printf("%s,%.4f,%.4f,%.4f,%.6f,%.6f,%.6f,%.12e,%.6e\n", sat.str().c_str(), st->position.x(),
                st->position.y(), st->position.z(), st->velocity.x(), st->velocity.y(), st->velocity.z(),
                st->clockBias, st->clockDrift);
    ++perSystem[gvins::systemIndex(sat.system)];
  }
  std::fflush(stdout);
  std::fprintf(stderr, "gvins-orbit: %s GPST, %zu records from %zu file(s), %zu skipped\n", t.toString(6).c_str(),
               store.size(), files.size(), skipped);
  std::fprintf(stderr, "  system   satellites\n");
  int total = 0;
  for (int s = 0; s < gvins::kNumSystems; ++s) {
    if (perSystem[s] == 0) continue;
    std::fprintf(stderr, "  %-8s %10d\n", std::string(gvins::systemName(static_cast<gvins::System>(s))).c_str(),
                 perSystem[s]);
    total += perSystem[s];
  }
  std::fprintf(stderr, "  %-8s %10d\n", "total", total);
  return 0;
}
