// UBX as a receiver input of the GNSS tools: BaseReader detects UBX by content (and still RTCM
// and RINEX), reads its epochs and adds the SFRBX ephemerides to the store; gvins-spp runs on the
// walk log alone (no navigation file) and is scored horizontally against the receiver's own RTK
// track (gnss_1730_sf.pos: NAV-PVT, mean-sea-level heights), next to RTKLIB's SPP on convbin's
// conversion of the same log.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>

#include "gvins/base/geodetic.hpp"
#include "gvins/base/local_frame.hpp"
#include "gvins/ephemeris/ephemeris_store.hpp"
#include "gvins/gnss/base_reader.hpp"
#include "gvins/gnss/pos_reader.hpp"
#include "independent_ubx_scan.hpp"
#include "run_command.hpp"

namespace gvins::ubx {
namespace {

using testing::dataDir;

TEST(UbxInput, DetectedByContentNextToRinexAndRtcm) {
  for (const auto& path : testing::ubxFiles()) {
    EXPECT_EQ(BaseReader::detect(path.string()), BaseFormat::Ubx) << path;
  }
  EXPECT_EQ(BaseReader::detect((dataDir() / "rtcm/rtklib_GMSD7_20121014.rtcm3").string()), BaseFormat::Rtcm);
  EXPECT_EQ(BaseReader::detect((dataDir() / "rtcm/pyrtcm_pygpsdata-MIXED-RTCM3.log").string()), BaseFormat::Rtcm);
  EXPECT_EQ(BaseReader::detect((dataDir() / "rtcm/go-gnss_frames/1077_frame.bin").string()), BaseFormat::Rtcm);
  EXPECT_EQ(BaseReader::detect((dataDir() / "gnss/nagoya_static_2024/base.obs.gz").string()), BaseFormat::Rinex);
  EXPECT_EQ(BaseReader::detect((dataDir() / "reference/rtklib-2.4.3/rtcm_testglo_convbin.obs").string()), BaseFormat::Rinex);
}

TEST(UbxInput, ReaderDeliversEpochsAndSfrbxEphemerides) {
  EphemerisStore nav;
  auto r = BaseReader::open((dataDir() / "ubx/gnss_1730.ubx").string(), GpsTime{}, &nav);
  ASSERT_EQ(r->format(), BaseFormat::Ubx);
  ObsEpoch e;
  int epochs = 0;
  std::size_t navAfterFirst = 0;
  while (r->next(e)) {
    if (++epochs == 1) navAfterFirst = nav.size();
  }
  EXPECT_EQ(epochs, 536);  // RXM-RAWX count of the independent scan
  EXPECT_EQ(navAfterFirst, 0u);  // the log starts cold: ephemerides arrive with the subframes
  EXPECT_EQ(nav.size(), 19u);    // as gvins-ubx to-rinex writes them (test_ubx_tool.cpp)
  EXPECT_FALSE(r->antennaPosition());
  EXPECT_TRUE(r->mayHaveDoppler());
  EXPECT_EQ(r->skipped(), 0);
  // The F9P log: GLONASS channels from RAWX freqId, no SFRBX.
  auto f9p = BaseReader::open((dataDir() / "ubx/gpsd_ublox-zed-f9p_hpg1.11.log").string(), GpsTime{}, &nav);
  epochs = 0;
  while (f9p->next(e)) ++epochs;
  EXPECT_EQ(epochs, 654);
  EXPECT_EQ(f9p->glonassChannels().get(2), -4);  // convbin's "GLONASS SLOT / FRQ #": R02 -4
}

std::pair<std::string, int> run(const std::string& cmd) { return gvins::test::runCommand(cmd); }

struct Score {
  std::size_t n = 0;
  double hrms = 0.0;
};

/// Horizontal RMS against the reference track, matching epochs within 5 ms (the track is tagged
/// 1 ms after RAWX's rcvTow).
Score score(const PosFile& sol, const PosFile& ref) {
  Score s;
  double sum = 0.0;
  for (const auto& p : sol.solutions) {
    const auto it = std::lower_bound(ref.solutions.begin(), ref.solutions.end(), p.time,
                                     [](const PositionSolution& a, const GpsTime& t) { return a.time - t < -0.005; });
    if (it == ref.solutions.end() || std::abs(it->time - p.time) > 0.005) continue;
    const Eigen::Vector3d enu = ecefToEnu(p.position, it->position);
    sum += enu.head<2>().squaredNorm();
    ++s.n;
  }
  s.hrms = s.n ? std::sqrt(sum / static_cast<double>(s.n)) : 0.0;
  return s;
}

/// The shipped track (RTKLIB .pos layout, Q/ns written as floats): GPST date, time, latitude,
/// longitude, height (above mean sea level: only the horizontal is scored).
PosFile readTrack(const std::filesystem::path& path) {
  PosFile f;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '%') continue;
    CalendarTime c;
    double lat = 0, lon = 0, h = 0;
    if (std::sscanf(line.c_str(), "%d/%d/%d %d:%d:%lf %lf %lf %lf", &c.year, &c.month, &c.day, &c.hour, &c.minute,
                    &c.second, &lat, &lon, &h) != 9) {
      ADD_FAILURE() << "bad track line: " << line;
      continue;
    }
    PositionSolution p;
    p.time = GpsTime::fromCalendar(c);
    p.position = geodeticToEcef({lat * M_PI / 180.0, lon * M_PI / 180.0, h});
    f.solutions.push_back(p);
  }
  return f;
}

TEST(UbxInput, SppOnTheWalkLogWithoutNavigationFile) {
  const std::string out = (std::filesystem::temp_directory_path() / ("gvins_ubx_spp_" + std::to_string(::getpid()) + ".pos")).string();
  const auto [log, rc] = run(std::string(GVINS_BIN_DIR) + "/gvins-spp -q -o " + out + " " +
                             (dataDir() / "ubx/gnss_1730.ubx").string() + " 2>&1");
  ASSERT_EQ(rc, 0) << log;
  EXPECT_NE(log.find("19 ephemerides from SFRBX"), std::string::npos) << log;
  const PosFile ours = readPosFile(out);
  std::filesystem::remove(out);
  const PosFile ref = readTrack(dataDir() / "ubx/gnss_1730_sf.pos");
  ASSERT_EQ(ref.solutions.size(), 536u);
  const PosFile rtklib = readPosFile((dataDir() / "reference/rtklib-2.4.3/ubx_gnss_1730_spp.pos").string());
  const Score a = score(ours, ref), b = score(rtklib, ref);
  std::cerr << "walk log SPP vs the publisher's RTK track: ours " << a.n << " epochs, horizontal RMS " << a.hrms
            << " m; RTKLIB (convbin obs + its nav of the whole log) " << b.n << " epochs, " << b.hrms << " m\n";
  // Ephemerides only as their subframes arrive: the first ~30 s have too few satellites.
  EXPECT_GE(a.n, 400u);
  EXPECT_LE(a.hrms, b.hrms + 1.0);
  EXPECT_LE(a.hrms, 10.0);
}

TEST(UbxInput, RtkTakesUbxAsRoverAndBase) {
  // Zero baseline: the walk log as rover and as base, no navigation file (SFRBX ephemerides of
  // both). Every double difference is zero, so every fixed epoch must sit on the base position.
  const std::string out = (std::filesystem::temp_directory_path() / ("gvins_ubx_rtk_" + std::to_string(::getpid()) + ".pos")).string();
  const std::string log = (dataDir() / "ubx/gnss_1730.ubx").string();
  const Eigen::Vector3d base = geodeticToEcef({40.0966916 * M_PI / 180.0, -105.1471665 * M_PI / 180.0, 1601.435});
  const auto [text, rc] = run(std::string(GVINS_BIN_DIR) + "/gvins-rtk -q --base-llh 40.0966916,-105.1471665,1601.435 -o " +
                              out + " " + log + " " + log + " 2>&1");
  ASSERT_EQ(rc, 0) << text;
  const PosFile sol = readPosFile(out);
  std::filesystem::remove(out);
  std::size_t fixed = 0;
  double worst = 0.0;
  for (const auto& p : sol.solutions) {
    if (p.quality != SolutionQuality::Fix) continue;
    ++fixed;
    worst = std::max(worst, (p.position - base).norm());
  }
  std::cerr << "zero-baseline RTK on the walk log: " << fixed << " fixed of " << sol.solutions.size() << ", worst "
            << worst << " m\n";
  EXPECT_GE(fixed, 400u);  // epochs with >= 4 satellites of known ephemeris
  EXPECT_LE(worst, 0.01);  // the solver stops iterating at mm level; SPP alone is 8 m off (above)
}

}  // namespace
}  // namespace gvins::ubx
