// gvins-orbit end to end: its CSV rows against RTKLIB's satellite positions and clocks, and its
// error handling. Needs the gvins-orbit target built (it is part of every full build).
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "gvins/base/line_reader.hpp"
#include "gvins/ephemeris/broadcast_sp3.hpp"
#include "gvins/ephemeris/ephemeris_store.hpp"
#include "gvins/ephemeris/satellite_antenna.hpp"
#include "gvins/ephemeris/rinex_nav.hpp"
#include "gvins/ephemeris/sp3.hpp"
#include "nagoya_recording.hpp"

namespace {

const std::string kData = GVINS_TEST_DATA;
const std::string kApp = std::string(GVINS_BIN_DIR) + "/gvins-orbit";

struct AppRun {
  int status = -1;
  std::string out;
};

AppRun run(const std::string& args, bool withStderr = true) {
  AppRun r;
  FILE* p = popen((kApp + " " + args + (withStderr ? " 2>&1" : " 2>/dev/null")).c_str(), "r");
  if (!p) return r;
  char buf[4096];
  std::size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) r.out.append(buf, n);
  const int st = pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return r;
}

}  // namespace

TEST(OrbitApp, RowsAgreeWithRtklib) {
  // The first epoch of the nagoya RTKLIB reference (08:20:00 receive time; transmit times differ
  // by satellite): evaluate gvins-orbit at the first GPS row's time and compare the GPS and
  // BeiDou rows whose transmit time is within 40 ms of it, moved to their time by the printed
  // velocity and drift (second-order terms < 1 mm).
  gvins::LineReader ref(kData + "/reference/rtklib-2.4.3/satpos/nagoya_base_nav.csv.gz");
  std::string line;
  ref.next(line);
  ref.next(line);
  const std::string time = line.substr(4, 26);  // "2024-06-24 08:19:59.931494"
  const AppRun r = run(kData + "/gnss/nagoya_static_2024/base.nav.gz --time \"" + time + "\" --gpst", false);
  ASSERT_EQ(r.status, 0) << r.out;
  std::map<std::string, std::vector<double>> rows;
  std::istringstream out(r.out);
  std::string l;
  std::getline(out, l);
  ASSERT_EQ(l, "sat,x,y,z,vx,vy,vz,clock_s,drift_s_per_s");
  while (std::getline(out, l)) {
    if (l.size() < 4 || l[3] != ',') continue;
    std::vector<double> v;
    std::istringstream f(l.substr(4));
    std::string x;
    while (std::getline(f, x, ',')) v.push_back(std::stod(x));
    ASSERT_EQ(v.size(), 8u) << l;
    rows[l.substr(0, 3)] = v;
  }
  EXPECT_GE(rows.size(), 60u);
  // Reference rows of this epoch (the first ~60 lines).
  int compared = 0;
  gvins::LineReader ref2(kData + "/reference/rtklib-2.4.3/satpos/nagoya_base_nav.csv.gz");
  ref2.next(line);
  gvins::CalendarTime c0;
  std::sscanf(time.c_str(), "%d-%d-%d %d:%d:%lf", &c0.year, &c0.month, &c0.day, &c0.hour, &c0.minute, &c0.second);
  const gvins::GpsTime t0 = gvins::GpsTime::fromCalendar(c0);
  while (ref2.next(line)) {
    const std::string sat = line.substr(0, 3);
    if (sat[0] != 'G' && sat[0] != 'C') continue;  // same record choice as RTKLIB for these
    gvins::CalendarTime c;
    double x, y, z, clk;
    std::sscanf(line.c_str() + 4, "%d-%d-%d %d:%d:%lf,%lf,%lf,%lf,%lf", &c.year, &c.month, &c.day, &c.hour,
                &c.minute, &c.second, &x, &y, &z, &clk);
    const double dt = gvins::GpsTime::fromCalendar(c) - t0;
    if (std::fabs(dt) > 0.5) break;  // next epoch
    if (std::fabs(dt) > 0.04) continue;  // velocity extrapolation good to < 1 mm within 40 ms
    const auto it = rows.find(sat);
    ASSERT_NE(it, rows.end()) << sat;
    const auto& v = it->second;
    const double dx = v[0] + v[3] * dt - x, dy = v[1] + v[4] * dt - y, dz = v[2] + v[5] * dt - z;
    EXPECT_LT(std::sqrt(dx * dx + dy * dy + dz * dz), 0.01) << sat;
    EXPECT_NEAR((v[6] + v[7] * dt) * 1e9, clk, 0.1) << sat;
    ++compared;
  }
  EXPECT_GE(compared, 15);
}

TEST(OrbitApp, UtcOptionShiftsByLeapSeconds) {
  const std::string nav = kData + "/gnss/nagoya_static_2024/base.nav.gz";
  const AppRun a = run(nav + " --time \"2024-06-24 08:20:00\"", false);
  const AppRun b = run(nav + " --time 2024-06-24T08:19:42 --utc", false);
  ASSERT_EQ(a.status, 0);
  ASSERT_EQ(b.status, 0);
  EXPECT_GT(a.out.size(), 1000u);
  EXPECT_EQ(a.out, b.out);
}

TEST(OrbitApp, ErrorsAreClear) {
  const AppRun noTime = run(kData + "/gnss/nagoya_static_2024/base.nav.gz");
  EXPECT_EQ(noTime.status, 2);
  EXPECT_NE(noTime.out.find("--time is required"), std::string::npos);
  const AppRun badTime = run(kData + "/gnss/nagoya_static_2024/base.nav.gz --time \"2024-13-01 00:00:00\"");
  EXPECT_EQ(badTime.status, 2);
  EXPECT_NE(badTime.out.find("bad --time"), std::string::npos);
  const AppRun badFile = run(kData + "/gnss/nagoya_static_2024/base.obs.gz --time \"2024-06-24 08:20:00\"");
  EXPECT_EQ(badFile.status, 1);
  EXPECT_NE(badFile.out.find("base.obs.gz:1: field 'RINEX VERSION / TYPE'"), std::string::npos) << badFile.out;
  const AppRun help = run("--help");
  EXPECT_EQ(help.status, 0);
  EXPECT_NE(help.out.find("sat,x,y,z,vx,vy,vz,clock_s,drift_s_per_s"), std::string::npos);
}

// --compare against an SP3 file made from the broadcast GPS orbits displaced by a known
// radial/along/cross offset and clocks by a common 0.2 m: the rows give back the offsets (with
// the opposite sign: broadcast minus precise), and the SISRE, with the common clock removed,
// sqrt((0.98·0.3)² + (1.2² + 0.5²)/49) = 0.348 m (Montenbruck et al. 2018 GPS weights).
TEST(OrbitApp, CompareRecoversKnownOrbitAndClockOffsets) {
  const std::string nav = kData + "/gnss/nagoya_static_2024/base.nav.gz";
  gvins::EphemerisStore store;
  store.add(gvins::readRinexNav(nav));
  const gvins::GpsTime t0 = gvins::test::nagoyaTime(8, 0);
  gvins::Sp3Data d;
  d.interval = 300.0;
  for (gvins::SatId s : store.satellites())
    if (s.system == gvins::System::Gps) d.satellites.push_back(s);
  const double kc = 299792458.0;
  for (double dt = 0.0; dt <= 3600.0; dt += 300.0) {
    gvins::Sp3Epoch ep;
    ep.time = t0 + dt;
    for (gvins::SatId s : d.satellites) {
      gvins::Sp3Record r;
      r.sat = s;
      if (const auto st = store.satelliteState(s, ep.time)) {
        const Eigen::Vector3d rh = st->position.normalized();
        const Eigen::Vector3d ch = st->position.cross(st->velocity).normalized();
        const Eigen::Vector3d ah = ch.cross(rh);
        r.position = st->position + 0.3 * rh - 1.2 * ah + 0.5 * ch;
        r.clock = st->clockBias + 2.0 * st->position.dot(st->velocity) / (kc * kc) + 0.2 / kc;
      }
      ep.records.push_back(r);
    }
    d.epochs.push_back(ep);
  }
  const std::string sp3 = (std::filesystem::temp_directory_path() / ("gvins_orbit_" + std::to_string(::getpid()) + ".sp3")).string();
  {
    std::ofstream f(sp3);
    gvins::writeSp3(f, d);
  }
  const AppRun r = run(nav + " " + sp3 + " --time \"2024-06-24 08:20:00\" --compare --duration 600 --step 300", false);
  ASSERT_EQ(r.status, 0) << r.out;
  std::istringstream in(r.out);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "gpst,sat,radial_m,along_m,cross_m,clock_m,sisre_m");
  int rows = 0;
  while (std::getline(in, line)) {
    std::vector<double> v;
    std::stringstream ls(line);
    std::string cell;
    for (int k = 0; std::getline(ls, cell, ','); ++k)
      if (k >= 2) v.push_back(std::stod(cell));
    ASSERT_EQ(v.size(), 5u) << line;
    // Interpolation and SP3 rounding: 1 mm.
    EXPECT_NEAR(v[0], -0.3, 2e-3) << line;
    EXPECT_NEAR(v[1], 1.2, 2e-3) << line;
    EXPECT_NEAR(v[2], -0.5, 2e-3) << line;
    EXPECT_NEAR(v[3], -0.2, 2e-3) << line;
    EXPECT_NEAR(v[4], 0.348, 2e-3) << line;
    ++rows;
  }
  EXPECT_GT(rows, 3 * 8);  // three epochs of the GPS satellites with records
  std::filesystem::remove(sp3);
  const AppRun noSp3 = run(nav + " --time \"2024-06-24 08:20:00\" --compare");
  EXPECT_EQ(noSp3.status, 2);
  EXPECT_NE(noSp3.out.find("--compare needs a precise orbit file"), std::string::npos) << noSp3.out;
}

// ANTEX among the inputs: centre-of-mass SP3 nodes (the broadcast phase-centre orbits of the GPS
// satellites minus their yaw-steered offsets, written as IGS products are) compared with the
// broadcast orbits. Without the ANTEX file the tool sees the offsets (about 1.4 m radial); with it
// the differences vanish to the SP3 rounding and interpolation (mm).
TEST(OrbitApp, AntexMovesCentreOfMassProductsToThePhaseCentre) {
  const std::string nav = kData + "/gnss/nagoya_static_2024/base.nav.gz";
  gvins::EphemerisStore store;
  store.add(gvins::readRinexNav(nav));
  const gvins::GpsTime t0 = gvins::test::nagoyaTime(8, 0);
  std::vector<gvins::SatId> gps;
  for (gvins::SatId s : store.satellites())
    if (s.system == gvins::System::Gps) gps.push_back(s);
  // ANTEX text: every GPS satellite with L1/L2 offsets (x, y, z in mm), valid from 2000 on.
  std::ostringstream atx;
  auto rec = [&](const std::string& body, const char* label) {
    std::string b = body;
    b.resize(60, ' ');
    atx << b << label << "\n";
  };
  rec("     1.4            G", "ANTEX VERSION / SYST");
  rec("A", "PCV TYPE / REFANT");
  rec("", "END OF HEADER");
  for (gvins::SatId s : gps) {
    char line[64];
    rec("", "START OF ANTENNA");
    std::snprintf(line, sizeof line, "%-20s%-20s%-10s%-10s", "BLOCK TEST", s.str().c_str(), "G999", "2000-001A");
    rec(line, "TYPE / SERIAL NO");
    rec("     0.0", "DAZI");
    rec("     0.0  14.0   1.0", "ZEN1 / ZEN2 / DZEN");
    rec("     2", "# OF FREQUENCIES");
    rec("  2000     1     1     0     0    0.0000000", "VALID FROM");
    for (const char* f : {"G01", "G02"}) {
      rec(std::string("   ") + f, "START OF FREQUENCY");
      rec("    279.00      0.00   1400.00", "NORTH / EAST / UP");
      std::string noazi = "   NOAZI";
      for (int k = 0; k < 15; ++k) noazi += "    0.00";
      atx << noazi << "\n";
      rec(std::string("   ") + f, "END OF FREQUENCY");
    }
    rec("", "END OF ANTENNA");
  }
  const std::string base = (std::filesystem::temp_directory_path() / ("gvins_orbit_atx_" + std::to_string(::getpid()))).string();
  const std::string atxFile = base + ".atx", sp3 = base + ".sp3";
  std::ofstream(atxFile) << atx.str();
  const auto antex = std::make_shared<gvins::AntexData>(gvins::readAntex(atxFile));
  gvins::Sp3Data d = gvins::broadcastSp3(store, t0, t0 + 3600.0, 300.0, gps);
  for (gvins::Sp3Epoch& ep : d.epochs) {
    for (gvins::Sp3Record& r : ep.records) {
      if (!r.position.allFinite()) continue;
      Eigen::Vector3d com = r.position;
      for (int i = 0; i < 3; ++i) com = r.position - *gvins::satelliteAntennaOffset(*antex, r.sat, ep.time, com);
      r.position = com;
    }
  }
  {
    std::ofstream f(sp3);
    gvins::writeSp3(f, d);
  }
  auto maxRadial = [&](const std::string& inputs) {
    const AppRun r = run(nav + " " + inputs + " --time \"2024-06-24 08:20:00\" --compare --duration 600 --step 300", false);
    EXPECT_EQ(r.status, 0) << r.out;
    std::istringstream in(r.out);
    std::string line;
    std::getline(in, line);
    double m = 0.0;
    int rows = 0;
    while (std::getline(in, line)) {
      std::stringstream ls(line);
      std::string cell;
      for (int k = 0; std::getline(ls, cell, ','); ++k)
        if (k >= 2 && k <= 4) m = std::max(m, std::abs(std::stod(cell)));
      ++rows;
    }
    EXPECT_GT(rows, 3 * 8);
    return m;
  };
  const double without = maxRadial(sp3), with = maxRadial(sp3 + " " + atxFile);
  std::printf("broadcast minus centre-of-mass products, largest orbit component: %.4f m without ANTEX, %.4f m with\n",
              without, with);
  EXPECT_GT(without, 1.0);
  EXPECT_LT(with, 3e-3);
  std::filesystem::remove(sp3);
  std::filesystem::remove(atxFile);
}
