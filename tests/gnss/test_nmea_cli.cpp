// --nmea and --kml of gvins-rtk and gvins-spp on the GEONET pair: every .pos row has one GGA and
// one RMC; the GGA, parsed back independently, gives the .pos position to < 1 mm, its quality
// follows the .pos Q (1 -> 4, 2 -> 5, 5 -> 1), its UTC time is the GPST time minus 13 s (2005);
// the KML has one coordinate line per row.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "gvins/base/geodetic.hpp"
#include "gvins/gnss/pos_reader.hpp"

using namespace gvins;

namespace {

const std::string kData = GVINS_TEST_DATA;
const std::string kGeonet = kData + "/gnss/geonet_0759_3040_2005/";

std::string tmp(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("gvins_nmea_cli_" + std::to_string(::getpid()) + "_" + name)).string();
}

std::vector<std::string> lines(const std::string& path) {
  std::ifstream f(path);
  std::vector<std::string> v;
  for (std::string l; std::getline(f, l);) v.push_back(l);
  return v;
}

std::vector<std::string> fields(const std::string& s) {
  std::vector<std::string> f(1);
  for (std::size_t i = 1; i < s.size() && s[i] != '*'; ++i) {
    if (s[i] == ',') f.emplace_back();
    else f.back() += s[i];
  }
  return f;
}

double angle(const std::string& v, const std::string& h, int degDigits) {
  const double a = std::stod(v.substr(0, static_cast<std::size_t>(degDigits))) + std::stod(v.substr(static_cast<std::size_t>(degDigits))) / 60.0;
  return h == "S" || h == "W" ? -a : a;
}

void checkAgainstPos(const std::string& tool, const std::string& args) {
  const std::string pos = tmp(tool + ".pos"), nmea = tmp(tool + ".nmea"), kml = tmp(tool + ".kml");
  const std::string cmd = std::string(GVINS_BIN_DIR) + "/" + tool + " -q -o " + pos + " --nmea " + nmea + " --kml " + kml + " " + args + " 2>/dev/null";
  ASSERT_EQ(WEXITSTATUS(std::system(cmd.c_str())), 0) << cmd;
  const PosFile p = readPosFile(pos);
  const auto n = lines(nmea);
  ASSERT_GT(p.solutions.size(), 100u);
  ASSERT_EQ(n.size(), 2 * p.solutions.size());
  int qualities[7] = {};
  for (std::size_t i = 0; i < p.solutions.size(); ++i) {
    const PositionSolution& s = p.solutions[i];
    const auto g = fields(n[2 * i]);
    ASSERT_EQ(g.size(), 15u) << n[2 * i];
    EXPECT_EQ(g[0], "GNGGA");
    EXPECT_EQ(fields(n[2 * i + 1])[0], "GNRMC");
    const Eigen::Vector3d back = geodeticToEcef(geodeticFromDegrees(angle(g[2], g[3], 2), angle(g[4], g[5], 3), std::stod(g[9]) + std::stod(g[11])));
    // The .pos itself rounds latitude/longitude to 1e-9 deg (0.1 mm) and height to 0.1 mm.
    EXPECT_LT((back - s.position).norm(), 1e-3) << n[2 * i];
    const int q = std::stoi(g[6]);
    EXPECT_EQ(q, s.quality == SolutionQuality::Fix ? 4 : s.quality == SolutionQuality::Float ? 5 : 1);
    ++qualities[q > 6 ? 0 : q];
    EXPECT_EQ(std::stoi(g[7]), s.numSatellites);
    // HDOP of the epoch's SPP geometry: 6-7 GPS satellites over Japan in 2005 give 1.2-1.7; the
    // 5-satellite stretch of the RTK run a poor geometry (8-14).
    ASSERT_FALSE(g[8].empty()) << n[2 * i];
    EXPECT_GT(std::stod(g[8]), 0.8) << n[2 * i];
    EXPECT_LT(std::stod(g[8]), s.numSatellites >= 6 ? 2.5 : 30.0) << n[2 * i];
    const CalendarTime c = (s.time - 13.0).toCalendar();  // GPST - UTC = 13 s in 2005
    char t[16];
    std::snprintf(t, sizeof t, "%02d%02d%05.2f", c.hour, c.minute, c.second);
    EXPECT_EQ(g[1], t);
  }
  EXPECT_GT(qualities[4] + qualities[1], 0);
  int coords = 0;
  for (const auto& l : lines(kml)) coords += std::count(l.begin(), l.end(), ',') == 2;
  EXPECT_EQ(coords, static_cast<int>(p.solutions.size()));
  for (const auto& f : {pos, nmea, kml}) std::filesystem::remove(f);
}

}  // namespace

TEST(NmeaCli, RtkNmeaMatchesPos) {
  checkAgainstPos("gvins-rtk", kGeonet + "07590920.05o.gz " + kGeonet + "30400920.05o.gz " + kGeonet + "07590920.05n.gz");
}

TEST(NmeaCli, SppNmeaMatchesPos) { checkAgainstPos("gvins-spp", kGeonet + "07590920.05o.gz " + kGeonet + "07590920.05n.gz"); }
