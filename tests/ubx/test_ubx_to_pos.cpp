// gvins-ubx to-pos: the receiver's NAV-PVT solutions as a .pos file. On the walk log against the
// publisher's track gnss_1730_sf.pos (written from the same NAV-PVT messages by other software:
// equal latitude, longitude, Q, satellites, sigmas and velocity, and heights 21.387 m apart:
// the shipped track holds NAV-PVT's hMSL, not the ellipsoidal height); the week against
// NAV-PVT's own UTC date on a log without RXM-RAWX; hand-built streams for the week rules, the
// quality mapping and malformed input.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>

#include "gvins/base/geodetic.hpp"
#include "gvins/base/local_frame.hpp"
#include "gvins/gnss/pos_reader.hpp"
#include "gvins/ubx/ubx_decoder.hpp"
#include "independent_ubx_scan.hpp"
#include "run_command.hpp"

namespace gvins::ubx {
namespace {

using testing::dataDir;
using testing::makeFrame;
using Bytes = std::vector<std::uint8_t>;

const std::string kTool = std::string(GVINS_BIN_DIR) + "/gvins-ubx";

std::pair<std::string, int> run(const std::string& cmd) { return gvins::test::runCommand(cmd); }

struct TempDir {
  std::filesystem::path path;
  explicit TempDir(const std::string& tag)
      : path(std::filesystem::temp_directory_path() / ("gvins_to_pos_" + tag + "_" + std::to_string(::getpid()))) {
    std::filesystem::create_directories(path);
  }
  ~TempDir() { std::filesystem::remove_all(path); }
  std::string operator/(const std::string& f) const { return (path / f).string(); }
};

void putU(Bytes& b, std::size_t o, std::uint64_t v, int n) {
  for (int i = 0; i < n; ++i) b[o + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(v >> (8 * i));
}

/// A NAV-PVT frame (u-blox F9 HPG 1.32 layout, 92 bytes): 2025-08-28 17:30:21 UTC + `nanoUtc`,
/// lat 40.0966916, lon -105.1471665, height 1580.048 m (hMSL 1601.435), hAcc 14 mm, vAcc 10 mm,
/// velocity N/E/D 0.5/-0.25/0.1 m/s, sAcc 70 mm/s.
Bytes navPvt(std::uint32_t iTowMs, std::uint8_t fixType, std::uint8_t flags, std::int32_t latE7 = 400966916,
             std::uint8_t valid = 0x07) {
  Bytes p(92, 0);
  putU(p, 0, iTowMs, 4);
  putU(p, 4, 2025, 2);
  p[6] = 8;
  p[7] = 28;
  p[8] = 17;
  p[9] = 30;
  p[10] = 21;
  p[11] = valid;
  putU(p, 16, 749542955, 4);
  p[20] = fixType;
  p[21] = flags;
  p[23] = 25;
  putU(p, 24, static_cast<std::uint32_t>(-1051471665), 4);
  putU(p, 28, static_cast<std::uint32_t>(latE7), 4);
  putU(p, 32, 1580048, 4);
  putU(p, 36, 1601435, 4);
  putU(p, 40, 14, 4);
  putU(p, 44, 10, 4);
  putU(p, 48, 500, 4);
  putU(p, 52, static_cast<std::uint32_t>(-250), 4);
  putU(p, 56, 100, 4);
  putU(p, 68, 70, 4);
  return makeFrame(0x01, 0x07, p);
}

/// NAV-TIMEGPS frame: week, iTOW, valid = tow, week and leap seconds.
Bytes timeGps(std::uint32_t iTowMs, int week) {
  Bytes p(16, 0);
  putU(p, 0, iTowMs, 4);
  putU(p, 8, static_cast<std::uint64_t>(week), 2);
  p[10] = 18;
  p[11] = 0x07;
  return makeFrame(0x01, 0x20, p);
}

void writeBytes(const std::string& path, const std::vector<Bytes>& frames) {
  std::ofstream o(path, std::ios::binary);
  for (const Bytes& f : frames) o.write(reinterpret_cast<const char*>(f.data()), static_cast<std::streamsize>(f.size()));
}

Geodetic geodeticDeg(const Eigen::Vector3d& ecef) {
  Geodetic g = ecefToGeodetic(ecef);
  g.lat *= 180.0 / M_PI;
  g.lon *= 180.0 / M_PI;
  return g;
}

TEST(UbxToPos, WalkLogIsThePublishersTrackWithEllipsoidalHeights) {
  const TempDir dir("walk");
  const auto [log, rc] = run(kTool + " to-pos " + (dataDir() / "ubx/gnss_1730.ubx").string() + " -o " + dir / "walk.pos" + " 2>&1");
  ASSERT_EQ(rc, 0) << log;
  EXPECT_NE(log.find("536 rows from 536 NAV-PVT messages"), std::string::npos) << log;
  EXPECT_NE(log.find("Q=1 349 Q=2 187"), std::string::npos) << log;
  const PosFile ours = readPosFile(dir / "walk.pos");
  const PosFile theirs = readPosFile((dataDir() / "gnss_imu/walk_0827/gnss_1730_sf.pos").string());
  ASSERT_EQ(ours.solutions.size(), 536u);
  ASSERT_EQ(theirs.solutions.size(), 536u);
  double maxLatLon = 0.0, minDh = 1e9, maxDh = -1e9, maxDt = 0.0, maxSd = 0.0, maxVel = 0.0;
  for (std::size_t i = 0; i < ours.solutions.size(); ++i) {
    const PositionSolution& a = ours.solutions[i];
    const PositionSolution& b = theirs.solutions[i];
    const Geodetic ga = geodeticDeg(a.position), gb = geodeticDeg(b.position);
    maxLatLon = std::max({maxLatLon, std::abs(ga.lat - gb.lat), std::abs(ga.lon - gb.lon)});
    minDh = std::min(minDh, ga.height - gb.height);
    maxDh = std::max(maxDh, ga.height - gb.height);
    // Theirs: NAV-PVT's UTC time with the nanoseconds, printed to the ms; ours: iTOW (ms).
    maxDt = std::max(maxDt, std::abs(a.time - b.time));
    EXPECT_EQ(a.quality, b.quality) << i;
    EXPECT_EQ(a.numSatellites, b.numSatellites) << i;
    // Both split hAcc equally over north and east (sdn = sde = hAcc/sqrt 2) and write sdu = vAcc.
    const Eigen::Matrix3d r = ecefToEnuRotation(ga.lat * M_PI / 180.0, ga.lon * M_PI / 180.0);
    const Eigen::Matrix3d ca = r * a.positionCovariance * r.transpose(), cb = r * b.positionCovariance * r.transpose();
    for (int k = 0; k < 3; ++k) maxSd = std::max(maxSd, std::abs(std::sqrt(ca(k, k)) - std::sqrt(cb(k, k))));
    ASSERT_TRUE(a.velocity && b.velocity) << i;
    maxVel = std::max(maxVel, (*a.velocity - *b.velocity).cwiseAbs().maxCoeff());
  }
  std::cerr << "to-pos vs gnss_1730_sf.pos: lat/lon max diff " << maxLatLon << " deg, height diff " << minDh << " .. "
            << maxDh << " m, time " << maxDt * 1e3 << " ms, sd " << maxSd << " m, velocity " << maxVel << " m/s\n";
  EXPECT_LE(maxLatLon, 5e-9);  // both print NAV-PVT's 1e-7 deg integers
  // NAV-PVT height - hMSL is -21.387/-21.388 m over the walk: the shipped track is in MSL heights.
  EXPECT_GE(minDh, -21.387 - 0.002);
  EXPECT_LE(maxDh, -21.387 + 0.002);
  EXPECT_LE(maxDt, 0.001 + 1e-6);  // theirs 0.46 ms earlier, printed truncated: 1 ms apart
  EXPECT_LE(maxSd, 6e-5);   // our 4 decimals against their 7
  EXPECT_LE(maxVel, 1e-6);  // velN, velE, -velD in mm/s
}

TEST(UbxToPos, WeekFromNavTimeGpsAgreesWithTheUtcDate) {
  // The F9P log without RXM-RAWX: the week comes from NAV-TIMEGPS; NAV-PVT's own UTC date and
  // nanoseconds, through the leap-second table, must give the same instant to the ms rounding.
  const std::string log = (dataDir() / "ubx/gpsd_ublox-zed-f9p-sfrbx.log").string();
  const TempDir dir("f9p");
  const auto [text, rc] = run(kTool + " to-pos " + log + " -o " + dir / "f9p.pos" + " 2>&1");
  ASSERT_EQ(rc, 0) << text;
  const PosFile ours = readPosFile(dir / "f9p.pos");
  std::vector<GpsTime> utc;
  Decoder dec;
  const auto bytes = testing::readBytes(log);
  dec.feed(bytes);
  dec.finish();
  while (auto item = dec.poll()) {
    if (const auto* p = std::get_if<NavPvt>(&*item)) utc.push_back(navPvtUtcAsGpst(*p).value());
  }
  ASSERT_EQ(ours.solutions.size(), 19u);
  ASSERT_EQ(utc.size(), 19u);
  for (std::size_t i = 0; i < utc.size(); ++i) EXPECT_NEAR(ours.solutions[i].time - utc[i], 0.0, 0.001) << i;
  EXPECT_EQ(ours.solutions[0].time.week(), 2109);  // 2020-06-10
}

TEST(UbxToPos, QualityWeekRulesAndMalformedMessages) {
  const TempDir dir("rules");
  // Week 2381 from NAV-TIMEGPS after the first two NAV-PVTs (they wait for it); the fourth
  // NAV-PVT crosses the week rollover (iTOW 0.25 s into week 2382, the reference still in 2381).
  const std::uint32_t lastMs = 604799750;
  writeBytes(dir / "s.ubx", {navPvt(lastMs - 500, 3, 0x83), navPvt(lastMs - 250, 3, 0x43), timeGps(lastMs - 250, 2381),
                             navPvt(lastMs, 3, 0x03), navPvt(250, 3, 0x01), navPvt(500, 2, 0x01),
                             navPvt(750, 3, 0x00), navPvt(1000, 1, 0x01), navPvt(1250, 5, 0x01),
                             navPvt(1500, 3, 0x01, 950000000), navPvt(1750, 4, 0x01)});
  const auto [text, rc] = run(kTool + " to-pos " + dir / "s.ubx" + " -o " + dir / "s.pos" + " 2>&1");
  ASSERT_EQ(rc, 0) << text;
  const PosFile f = readPosFile(dir / "s.pos");
  ASSERT_EQ(f.solutions.size(), 5u) << text;
  const std::vector<SolutionQuality> q{SolutionQuality::Fix, SolutionQuality::Float, SolutionQuality::Dgps,
                                       SolutionQuality::Single, SolutionQuality::Single};
  const std::vector<GpsTime> t{GpsTime::fromWeekTow(2381, 604799.25), GpsTime::fromWeekTow(2381, 604799.5),
                               GpsTime::fromWeekTow(2381, 604799.75), GpsTime::fromWeekTow(2382, 0.25),
                               GpsTime::fromWeekTow(2382, 1.75)};
  for (std::size_t i = 0; i < q.size(); ++i) {
    EXPECT_EQ(f.solutions[i].quality, q[i]) << i;
    EXPECT_NEAR(f.solutions[i].time - t[i], 0.0, 1e-6) << i;
  }
  // Position, sigmas and velocity of a row against the frame's fields.
  const PositionSolution& s = f.solutions[0];
  const Geodetic g = geodeticDeg(s.position);
  EXPECT_NEAR(g.lat, 40.0966916, 1e-9);
  EXPECT_NEAR(g.lon, -105.1471665, 1e-9);
  EXPECT_NEAR(g.height, 1580.048, 1e-4);
  const Eigen::Matrix3d r = ecefToEnuRotation(g.lat * M_PI / 180.0, g.lon * M_PI / 180.0);
  const Eigen::Matrix3d c = r * s.positionCovariance * r.transpose();
  EXPECT_NEAR(std::sqrt(c(0, 0)), 0.014 / std::sqrt(2.0), 1e-4);
  EXPECT_NEAR(std::sqrt(c(2, 2)), 0.010, 1e-4);
  ASSERT_TRUE(s.velocity);
  const Eigen::Vector3d v = r * *s.velocity;  // E, N, U
  EXPECT_NEAR(v.x(), -0.25, 1e-5);
  EXPECT_NEAR(v.y(), 0.5, 1e-5);
  EXPECT_NEAR(v.z(), -0.1, 1e-5);
  const Eigen::Matrix3d cv = r * s.velocityCovariance * r.transpose();
  EXPECT_NEAR(std::sqrt(cv(2, 2)), 0.070 / std::sqrt(3.0), 1e-4);
  // Left out: 2D fix; fixType 3 without gnssFixOK, dead reckoning only, time only; the latitude
  // of 95 deg is a malformed message, named with its field.
  EXPECT_NE(text.find("3 without a 3D fix"), std::string::npos) << text;
  EXPECT_NE(text.find("1 2D fixes"), std::string::npos) << text;
  EXPECT_NE(text.find("Q=1 1 Q=2 1 Q=4 1 Q=5 2"), std::string::npos) << text;
  EXPECT_NE(text.find("1 malformed messages"), std::string::npos) << text;
  EXPECT_NE(text.find("NAV-PVT lat: latitude 95"), std::string::npos) << text;
}

TEST(UbxToPos, WithoutRawxOrTimeGpsTheUtcDateGivesTheWeek) {
  const TempDir dir("utc");
  // 17:30:21.7495 UTC + 18 s = 17:30:39.7495 GPST on Thursday 2025-08-28: TOW 408639.75 s (week 2381).
  writeBytes(dir / "u.ubx", {navPvt(408639750, 3, 0x01), navPvt(408640000, 3, 0x01, 400966916, 0x03)});
  const auto [text, rc] = run(kTool + " to-pos " + dir / "u.ubx" + " -o " + dir / "u.pos" + " 2>&1");
  ASSERT_EQ(rc, 0) << text;
  const PosFile f = readPosFile(dir / "u.pos");
  ASSERT_EQ(f.solutions.size(), 1u) << text;  // the second has no fullyResolved flag: no week
  EXPECT_NEAR(f.solutions[0].time - GpsTime::fromWeekTow(2381, 408639.75), 0.0, 1e-6);
  EXPECT_NE(text.find("1 without a GPS week"), std::string::npos) << text;
  EXPECT_NE(text.find("1 rows dated by NAV-PVT's UTC date"), std::string::npos) << text;
}

TEST(UbxToPos, BadInputsFailCleanly) {
  const TempDir dir("bad");
  // No NAV-PVT (the X20P log has SFRBX only): exit 1 naming the file, no output left behind.
  const std::string x20p = (dataDir() / "ubx/gpsd_ublox-x20p.log").string();
  const auto [text, rc] = run(kTool + " to-pos " + x20p + " -o " + dir / "x.pos" + " 2>&1");
  EXPECT_EQ(rc, 1);
  EXPECT_NE(text.find(x20p + ": no NAV-PVT message"), std::string::npos) << text;
  EXPECT_FALSE(std::filesystem::exists(dir / "x.pos"));
  // An empty input and a truncated NAV-PVT (payload cut to 60 bytes, checksum valid).
  writeBytes(dir / "empty.ubx", {});
  EXPECT_EQ(run(kTool + " to-pos " + dir / "empty.ubx" + " -o " + dir / "e.pos" + " 2>/dev/null").second, 1);
  Bytes shortPvt(60, 0);
  writeBytes(dir / "short.ubx", {makeFrame(0x01, 0x07, shortPvt), timeGps(1000, 2381)});
  const auto [st, src] = run(kTool + " to-pos " + dir / "short.ubx" + " -o " + dir / "s.pos" + " 2>&1");
  EXPECT_EQ(src, 1) << st;  // the only NAV-PVT was malformed: none decoded
  EXPECT_NE(st.find("1 malformed"), std::string::npos) << st;
  // Usage errors: exit 2.
  EXPECT_EQ(run(kTool + " to-pos 2>/dev/null").second, 2);
  EXPECT_EQ(run(kTool + " to-pos " + x20p + " 2>/dev/null").second, 2);  // no -o
  EXPECT_EQ(run(kTool + " to-pos " + x20p + " -o 2>/dev/null").second, 2);
  EXPECT_EQ(run(kTool + " to-pos a b -o c 2>/dev/null").second, 2);
  EXPECT_EQ(run(kTool + " to-pos --frob a -o c 2>/dev/null").second, 2);
}

}  // namespace
}  // namespace gvins::ubx
