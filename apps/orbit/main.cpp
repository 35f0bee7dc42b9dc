// gvins-orbit: satellite positions, velocities and clocks from broadcast navigation files and
// precise products, and the broadcast orbit/clock errors against the products.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "gvins/base/command_line.hpp"
#include "gvins/base/parse_error.hpp"
#include "gvins/ephemeris/ephemeris_store.hpp"
#include "gvins/ephemeris/orbit_comparison.hpp"
#include "gvins/ephemeris/precise_product_files.hpp"

namespace {

const char* kUsage =
    "usage: gvins-orbit NAV... [ORBIT.sp3...] [CLOCK.clk...] [ANT.atx] --time \"YYYY-MM-DD HH:MM:SS[.ffffff]\"\n"
    "                   [--gpst|--utc] [--compare [--duration S] [--step S]] [options]\n"
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
    "ORBIT/CLOCK  precise products (SP3-c/d *.sp3, RINEX clock *.clk, plain or .gz; told apart by\n"
    "          name): where they cover a satellite its state comes from them.\n"
    "ANT.atx   ANTEX file: satellite antenna offsets added to the products' centre-of-mass\n"
    "          positions (IGS SP3); satellites without an entry keep their broadcast states.\n"
    "--compare broadcast minus precise instead of states (needs an SP3 file), one row per\n"
    "          satellite and epoch: gpst,sat,radial_m,along_m,cross_m,clock_m,sisre_m (orbit in the\n"
    "          precise state's radial/along/cross frame, clock as c*dt; SISRE after Montenbruck et\n"
    "          al. 2018 with the per-epoch mean clock difference of each system removed, which a\n"
    "          receiver clock absorbs); RMS per system on stderr. Give the ANTEX file with IGS SP3\n"
    "          orbits (centres of mass; broadcast ones are antenna phase centres).\n"
    "--duration S, --step S   with --compare: epochs T, T+step, ... up to T+duration (default one\n"
    "          epoch; step 300 s).\n"
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

/// --compare: broadcast minus precise, epoch after epoch (CSV rows on stdout, RMS per system on
/// stderr); the clock differences of each system are referred to their mean at the epoch for the
/// SISRE.
int compareOrbits(const gvins::EphemerisStore& store, const std::shared_ptr<gvins::PreciseEphemeris>& precise,
                  const std::shared_ptr<gvins::AntexData>& antennas, const gvins::EphemerisSelection& policy,
                  const gvins::GpsTime& t, double duration, double step) {
  struct Acc {
    double r2 = 0, a2 = 0, c2 = 0, k2 = 0, s2 = 0;
    int n = 0;
  };
  std::map<int, Acc> acc;
  gvins::EphemerisStore preciseStore;  // the products with the antenna offsets, if any
  preciseStore.setPrecise(precise);
  if (antennas) preciseStore.setSatelliteAntennas(antennas);
  int epochs = 0;
  for (double dt = 0.0; dt <= duration + 1e-9; dt += step) {
    const gvins::GpsTime te = t + dt;
    std::vector<std::pair<gvins::SatId, gvins::OrbitDifference>> rows;
    double sum[gvins::kNumSystems] = {};
    int cnt[gvins::kNumSystems] = {};
    for (const gvins::SatId sat : store.satellites()) {
      const auto b = store.satelliteState(sat, te, policy);
      const auto p = preciseStore.preciseState(sat, te);
      if (!b || !p) continue;
      const gvins::OrbitDifference d = gvins::orbitDifference(*b, *p);
      rows.emplace_back(sat, d);
      sum[gvins::systemIndex(sat.system)] += d.clock;
      ++cnt[gvins::systemIndex(sat.system)];
    }
    for (const auto& [sat, d] : rows) {
      if (acc.empty()) std::printf("gpst,sat,radial_m,along_m,cross_m,clock_m,sisre_m\n");  // with the first row
      const int si = gvins::systemIndex(sat.system);
      const double mean = sum[si] / cnt[si];
      const double e = gvins::sisre(sat, d, mean);
      std::printf("%s,%s,%.4f,%.4f,%.4f,%.4f,%.4f\n", te.toString(3).c_str(), sat.str().c_str(), d.radial, d.along,
                  d.cross, d.clock, e);
      Acc& a = acc[si];
      a.r2 += d.radial * d.radial;
      a.a2 += d.along * d.along;
      a.c2 += d.cross * d.cross;
      a.k2 += (d.clock - mean) * (d.clock - mean);
      a.s2 += e * e;
      ++a.n;
    }
    ++epochs;
  }
  std::fflush(stdout);
  std::fprintf(stderr, "gvins-orbit: broadcast minus precise, %d epoch(s) from %s GPST, RMS [m]\n", epochs,
               t.toString(3).c_str());
  std::fprintf(stderr, "  system     rows   radial    along    cross  clock-mean    SISRE\n");
  for (const auto& [si, a] : acc) {
    const auto rms = [&](double x) { return std::sqrt(x / a.n); };
    std::fprintf(stderr, "  %-8s %6d %8.3f %8.3f %8.3f %11.3f %8.3f\n",
                 std::string(gvins::systemName(static_cast<gvins::System>(si))).c_str(), a.n, rms(a.r2), rms(a.a2),
                 rms(a.c2), rms(a.k2), rms(a.s2));
  }
  if (acc.empty()) {
    std::fprintf(stderr,
                 "gvins-orbit: --compare: no satellite has both a broadcast ephemeris and a precise state at %s GPST%s "
                 "(the navigation files and the products do not overlap there)\n",
                 t.toString(3).c_str(), duration > 0.0 ? " or later in --duration" : "");
    return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> files;
  gvins::PreciseProductFiles products;
  std::string timeText;
  bool utc = false, unhealthy = false, realtime = false, compare = false;
  double duration = 0.0, step = 300.0;
  gvins::CommandLine cl("gvins-orbit", kUsage, argc, argv);
  while (cl.next()) {
    if (cl.is("--time")) timeText = cl.value();
    else if (cl.is("--gpst")) utc = false;
    else if (cl.is("--utc")) utc = true;
    else if (cl.is("--unhealthy")) unhealthy = true;
    else if (cl.is("--realtime")) realtime = true;
    else if (cl.is("--compare")) compare = true;
    else if (cl.is("--duration")) duration = cl.number(0.0, 30.0 * 86400.0, "s (0 to 30 days)");
    else if (cl.is("--step")) step = cl.number(1.0, 30.0 * 86400.0, "s (1 s to 30 days)");
    else if (const std::string& f = cl.operand(); !products.add(f)) files.push_back(f);
  }
  for (const std::string& b : products.biases)
    std::fprintf(stderr, "gvins-orbit: note: %s: code biases do not change satellite states; not used\n", b.c_str());
  const std::vector<std::string>& sp3Files = products.orbits;
  const std::vector<std::string>& clockFiles = products.clocks;
  const std::vector<std::string>& antennaFiles = products.antennas;
  if (compare && sp3Files.empty()) {
    std::fprintf(stderr, "gvins-orbit: --compare needs a precise orbit file (*.sp3)\n");
    return 2;
  }
  if (files.empty() || timeText.empty()) {
    std::fprintf(stderr, "gvins-orbit: %s\n%s", files.empty() ? "no navigation file given" : "--time is required",
                 kUsage);
    return 2;
  }
  gvins::CalendarTime cal;
  if (!parseTime(timeText.c_str(), cal)) {
    std::fprintf(stderr, "gvins-orbit: bad --time '%s' (expected \"YYYY-MM-DD HH:MM:SS[.ffffff]\")\n", timeText.c_str());
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
  std::shared_ptr<gvins::PreciseEphemeris> precise;
  if (!sp3Files.empty()) {
    try {
      precise = gvins::readPreciseProducts(sp3Files, clockFiles);
    } catch (const gvins::ParseError& e) {
      std::fprintf(stderr, "gvins-orbit: %s\n", e.what());
      return 1;
    }
  } else if (!clockFiles.empty()) {
    std::fprintf(stderr, "gvins-orbit: clock files need an SP3 orbit file\n");
    return 2;
  }

  std::shared_ptr<gvins::AntexData> antennas;
  if (!antennaFiles.empty()) {
    try {
      antennas = gvins::readAntennaFiles(antennaFiles);
    } catch (const gvins::ParseError& e) {
      std::fprintf(stderr, "gvins-orbit: %s\n", e.what());
      return 1;
    }
  }

  gvins::EphemerisSelection policy;
  policy.allowUnhealthy = unhealthy;
  if (realtime) policy.futureTolerance = -1.0;
  if (compare) return compareOrbits(store, precise, antennas, policy, t, duration, step);
  if (precise) store.setPrecise(precise);
  if (antennas) store.setSatelliteAntennas(antennas);
  int perSystem[gvins::kNumSystems] = {};
  std::vector<std::pair<gvins::SatId, gvins::SatelliteState>> states;
  for (const gvins::SatId sat : store.satellites()) {
    if (const auto st = store.satelliteState(sat, t, policy)) states.emplace_back(sat, *st);
  }
  if (states.empty()) {
    // A header alone would look like a valid answer for an empty sky.
    std::fprintf(stderr,
                 "gvins-orbit: --time %s GPST: no satellite has a usable ephemeris at that time in %zu record(s) of "
                 "%zu file(s) (time outside the files' validity windows%s)\n",
                 t.toString(6).c_str(), store.size(), files.size(), unhealthy ? "" : ", or all unhealthy");
    return 1;
  }
  std::printf("sat,x,y,z,vx,vy,vz,clock_s,drift_s_per_s\n");
  for (const auto& [sat, state] : states) {
    const gvins::SatelliteState* st = &state;
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
