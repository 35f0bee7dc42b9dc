// The bundled Nagoya rover/base pair (tests/data/gnss/nagoya_static_2024, provenance in
// tests/data/README.md) loaded once per test program: both observation files with their
// headers, the navigation file, the surveyed base position and the reference rover position.
// Shared by the RTK, Doppler-check and signal-matching tests. Needs GVINS_TEST_DATA.
#pragma once

#include <fstream>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "gvins/base/geodetic.hpp"
#include "gvins/base/rinex_obs_reader.hpp"
#include "gvins/ephemeris/ephemeris_store.hpp"
#include "gvins/ephemeris/rinex_nav.hpp"

namespace gvins::test {

struct RecordedPair {
  std::vector<ObsEpoch> rover, base;
  RinexObsHeader roverHeader, baseHeader;
  EphemerisStore nav;
  Eigen::Vector3d basePosition = Eigen::Vector3d::Zero();
  Eigen::Vector3d truth = Eigen::Vector3d::Zero();  ///< rover position (zero where unknown)
};

/// ECEF of the "lat lon h" (deg, deg, m) in a text file.
inline Eigen::Vector3d readLlhFile(const std::string& path) {
  std::ifstream f(path);
  double lat = 0, lon = 0, h = 0;
  f >> lat >> lon >> h;
  return geodeticToEcef(geodeticFromDegrees(lat, lon, h));
}

inline std::string nagoyaPairDir() { return std::string(GVINS_TEST_DATA) + "/gnss/nagoya_static_2024/"; }

inline const RecordedPair& nagoyaPair() {
  static const RecordedPair d = [] {
    RecordedPair s;
    const std::string dir = nagoyaPairDir();
    s.rover = readRinexObs(dir + "rover.obs.gz", &s.roverHeader);
    s.base = readRinexObs(dir + "base.obs.gz", &s.baseHeader);
    s.nav.add(readRinexNav(dir + "base.nav.gz"));
    s.basePosition = readLlhFile(dir + "base_position.txt");
    s.truth = readLlhFile(dir + "rover_position.txt");
    return s;
  }();
  return d;
}

}  // namespace gvins::test
