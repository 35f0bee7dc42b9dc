// Example consumer of an installed SRI-GVINS (SriGvins::gnss): broadcast satellite positions and
// single point positioning fixes from a RINEX observation file and a navigation file.
//
//   satellite_spp OBS NAV ["YYYY-MM-DD HH:MM:SS.ffffff"]
//
// Prints, for every satellite of the first observation epoch, its broadcast position (ECEF, m) and
// clock offset (ns) at the given GPST instant (default: the first epoch's time tag), then the SPP
// fix of the first epoch and the mean of the fixes of all epochs, as ECEF and latitude, longitude
// (degrees) and ellipsoidal height (m).
#include <cmath>
#include <cstdio>
#include <exception>
#include <numbers>
#include <optional>
#include <string>

#include <gvins/base/geodetic.hpp>
#include <gvins/base/gnss_time.hpp>
#include <gvins/base/rinex_obs_reader.hpp>
#include <gvins/ephemeris/ephemeris_store.hpp>
#include <gvins/ephemeris/rinex_nav.hpp>
#include <gvins/gnss/spp.hpp>

namespace {

std::optional<gvins::GpsTime> parseTime(const char* text) {
  gvins::CalendarTime c;
  if (std::sscanf(text, "%d-%d-%d %d:%d:%lf", &c.year, &c.month, &c.day, &c.hour, &c.minute, &c.second) != 6)
    return std::nullopt;
  return gvins::GpsTime::fromCalendar(c);
}

void printFix(const char* label, const Eigen::Vector3d& ecef, const std::string& extra) {
  const gvins::Geodetic g = gvins::ecefToGeodetic(ecef);
  constexpr double kDeg = 180.0 / std::numbers::pi;
  std::printf("%s ecef %.3f %.3f %.3f llh %.9f %.9f %.3f %s\n", label, ecef.x(), ecef.y(), ecef.z(),
              g.lat * kDeg, g.lon * kDeg, g.height, extra.c_str());
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3 || argc > 4) {
    std::fprintf(stderr, "usage: %s OBS NAV [\"YYYY-MM-DD HH:MM:SS.ffffff\" (GPST)]\n", argv[0]);
    return 2;
  }
  std::optional<gvins::GpsTime> at;
  if (argc == 4 && !(at = parseTime(argv[3]))) {
    std::fprintf(stderr, "%s: cannot read the time '%s' (expected YYYY-MM-DD HH:MM:SS.ffffff)\n", argv[0], argv[3]);
    return 2;
  }
  try {
    gvins::EphemerisStore nav;
    nav.add(gvins::readRinexNav(argv[2]));
    gvins::RinexObsReader reader(argv[1]);
    gvins::SppSolver solver(nav);
    solver.setGlonassChannels(reader.header().glonassChannels);
    if (reader.header().station.approxPosition) solver.setInitialPosition(*reader.header().station.approxPosition);

    gvins::ObsEpoch epoch;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    long epochs = 0, fixes = 0;
    while (reader.next(epoch)) {
      if (epochs++ == 0) {
        const gvins::GpsTime t = at.value_or(epoch.time);
        for (const gvins::SatObs& s : epoch.sats) {
          const auto state = nav.satelliteState(s.sat, t);
          if (!state) continue;
          std::printf("sat %s %s %.3f %.3f %.3f %.3f\n", s.sat.str().c_str(), t.toString(6).c_str(),
                      state->position.x(), state->position.y(), state->position.z(), state->clockBias * 1e9);
        }
      }
      const gvins::SppSolution fix = solver.solve(epoch);
      if (!fix.valid()) continue;
      if (fixes == 0)
        printFix("fix first", fix.position,
                 fix.time.toString(1) + " sats " + std::to_string(fix.numSatellites));
      sum += fix.position;
      ++fixes;
    }
    if (fixes == 0) {
      std::fprintf(stderr, "no SPP fix in %ld epochs of %s\n", epochs, argv[1]);
      return 1;
    }
    printFix("fix mean", sum / static_cast<double>(fixes), "epochs " + std::to_string(epochs) + " fixes " + std::to_string(fixes));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
  return 0;
}
