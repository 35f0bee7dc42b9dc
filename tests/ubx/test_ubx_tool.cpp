// gvins-ubx end to end: `info` message counts against the independent frame scan on every bundled
// log (and NMEA counts against a plain text count), `to-rinex` on the walk log read back against
// RTKLIB's conversion, with the signals convbin drops counted per system.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>

#include "gvins/base/rinex_obs_reader.hpp"
#include "gvins/ephemeris/rinex_nav.hpp"
#include "independent_ubx_scan.hpp"
#include "run_command.hpp"

namespace gvins::ubx {
namespace {

using testing::dataDir;
using testing::readBytes;

const std::string kTool = std::string(GVINS_BIN_DIR) + "/gvins-ubx";

std::pair<std::string, int> run(const std::string& cmd) { return gvins::test::runCommand(cmd); }

/// NMEA sentences counted as text: "$" + printable characters + "*hh" + CR LF, checksum right.
std::int64_t countNmea(const std::vector<std::uint8_t>& d) {
  const std::string s(d.begin(), d.end());
  std::int64_t n = 0;
  static const std::regex re(R"(\$([\x20-\x23\x25-\x29\x2B-\x7E]{5,})\*([0-9A-F]{2})\r\n)");
  for (auto it = std::sregex_iterator(s.begin(), s.end(), re); it != std::sregex_iterator(); ++it) {
    unsigned sum = 0;
    for (char c : (*it)[1].str()) sum ^= static_cast<unsigned char>(c);
    if (sum == std::stoul((*it)[2].str(), nullptr, 16)) ++n;
  }
  return n;
}

TEST(UbxTool, InfoCountsEqualTheIndependentScan) {
  for (const auto& path : testing::ubxFiles()) {
    SCOPED_TRACE(path.string());
    const auto d = readBytes(path);
    const auto ref = testing::independentScan(d);
    const auto [out, rc] = run(kTool + " info " + path.string());
    ASSERT_EQ(rc, 0) << out;
    std::map<int, std::int64_t> got;
    std::istringstream in(out);
    std::string line;
    std::int64_t nmea = -1;
    while (std::getline(in, line)) {
      unsigned cls = 0, id = 0;
      long long n = 0;
      if (std::sscanf(line.c_str(), "  0x%2X-0x%2X %lld", &cls, &id, &n) == 3) got[static_cast<int>(cls * 256 + id)] = n;
      long long k = 0;
      if (std::sscanf(line.c_str(), "other %lld NMEA", &k) == 1) nmea = k;
    }
    EXPECT_EQ(got, ref.types);
    EXPECT_EQ(nmea, countNmea(d));
  }
  // From stdin as well.
  const auto [out, rc] = run(kTool + " info - < " + (dataDir() / "ubx/pyubx2_pygpsdata-RXMRAWX.log").string());
  EXPECT_EQ(rc, 0);
  EXPECT_NE(out.find("0x02-0x15      14  RXM-RAWX"), std::string::npos) << out;
  EXPECT_NE(out.find("14 epochs"), std::string::npos) << out;
}

// The SFRBX rows per gnssId/sigId: the walk log's sources decoded or not, and BeiDou D2 (GEO) pages
// (no real log holds them: the synthetic log of test_sfrbx_d2.cpp).
TEST(UbxTool, InfoBreaksSfrbxDownBySource) {
  auto row = [](const std::string& out, const std::string& ids) {
    const auto at = out.find("\n  " + ids + " ");
    return at == std::string::npos ? std::string() : out.substr(at + 1, out.find('\n', at + 1) - at - 1);
  };
  const auto [walk, rc] = run(kTool + " info " + (dataDir() / "ubx/gnss_1730.ubx").string());
  ASSERT_EQ(rc, 0);
  EXPECT_NE(walk.find("44 CNAV group delay sets, 0 parity and 0 CRC failures, 1551 of systems not decoded"),
            std::string::npos) << walk;
  // GPS L5 CNAV: 108 messages, 32 of type 30 (the Python tally of test_sfrbx_cnav.cpp).
  EXPECT_NE(row(walk, "0/6").find("CNAV (L5)                        108       32           0        0"),
            std::string::npos) << walk;
  const std::string b2a = row(walk, "3/8");
  EXPECT_NE(b2a.find("B-CNAV2 (not decoded)"), std::string::npos) << walk;
  EXPECT_EQ(b2a.substr(b2a.find_last_not_of(' ') - 3), " 364") << walk;  // no records, no checks
  EXPECT_NE(row(walk, "3/4").find("D1 (MEO/IGSO)                    153        8           0        0"),
            std::string::npos) << walk;
  const auto [d2, rc2] = run(kTool + " info " + (dataDir() / "ubx_synthetic/beidou_d2_nagoya_geo.ubx").string());
  ASSERT_EQ(rc2, 0);
  EXPECT_NE(row(d2, "3/1").find("D2 (GEO)                          80        8           0        0"), std::string::npos) << d2;
}

TEST(UbxTool, ToRinexKeepsEverySignalAndAgreesWithConvbin) {
  const auto dir = std::filesystem::temp_directory_path() / ("gvins_ubx_tool_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string prefix = (dir / "walk").string();
  const auto [out, rc] = run(kTool + " to-rinex " + (dataDir() / "ubx/gnss_1730.ubx").string() + " -o " + prefix + " 2>&1");
  ASSERT_EQ(rc, 0) << out;
  RinexObsReader ours(prefix + ".obs");
  RinexObsReader theirs((dataDir() / "reference/rtklib-2.4.3/ubx_gnss_1730_convbin.obs.gz").string());
  std::map<char, std::int64_t> oursPerSys, theirsPerSys, onlyOurs;
  std::int64_t epochs = 0, values = 0;
  double maxC = 0, maxL = 0;
  ObsEpoch a, b;
  while (theirs.next(b)) {
    ASSERT_TRUE(ours.next(a));
    ASSERT_NEAR(a.time - b.time, 0.0, 1e-7);
    ++epochs;
    for (const auto& s : a.sats) {
      const SatObs* t = b.find(s.sat);
      for (const auto& g : s.signals) {
        ++oursPerSys[systemLetter(s.sat.system)];
        const SignalObs* h = t ? t->find(g.code) : nullptr;
        if (!h) {
          ++onlyOurs[systemLetter(s.sat.system)];
          continue;
        }
        if (g.hasCode() && h->hasCode()) maxC = std::max(maxC, std::abs(g.pseudorange - h->pseudorange)), ++values;
        if (g.hasPhase() && h->hasPhase()) maxL = std::max(maxL, std::abs(g.carrierPhase - h->carrierPhase)), ++values;
      }
    }
    for (const auto& s : b.sats) theirsPerSys[systemLetter(s.sat.system)] += static_cast<std::int64_t>(s.signals.size());
  }
  EXPECT_FALSE(ours.next(a));
  EXPECT_EQ(epochs, 536);
  // Both files written at 0.001 resolution from the same doubles: equal to the last digit.
  EXPECT_LE(maxC, 1e-6);
  EXPECT_LE(maxL, 1e-6);
  EXPECT_GT(values, 20000);
  // Signals per system, RAWX blocks of the independent scan (test_ubx_rawx.cpp): GPS 1C+2L+5Q
  // 3842+4115+3752, Galileo 1C+5Q+6B 3199+4032+2932, BeiDou 6I+1P+5P 5416+4174+4809, SBAS 1579.
  EXPECT_EQ(oursPerSys['G'], 11709);
  EXPECT_EQ(oursPerSys['E'], 10163);
  EXPECT_EQ(oursPerSys['C'], 14399);
  EXPECT_EQ(oursPerSys['S'], 1579);
  EXPECT_EQ(theirsPerSys.count('C'), 0u);  // convbin drops every BeiDou signal of this receiver
  EXPECT_EQ(onlyOurs['G'], 3752);          // GPS L5 Q
  EXPECT_EQ(onlyOurs['E'], 4032 + 2932);   // E5a Q, E6 B
  EXPECT_EQ(onlyOurs['C'], 14399);
  EXPECT_EQ(onlyOurs['S'], 0);
  std::cerr << "walk log: " << epochs << " epochs; signals ours/convbin G " << oursPerSys['G'] << "/" << theirsPerSys['G']
            << " E " << oursPerSys['E'] << "/" << theirsPerSys['E'] << " C " << oursPerSys['C'] << "/" << theirsPerSys['C']
            << " S " << oursPerSys['S'] << "/" << theirsPerSys['S'] << "\n";
  // The navigation file from the log's own SFRBX: every record convbin assembled is there with the
  // same orbit (RTKLIB decodes the same subframes independently).
  const NavData nav = readRinexNav(prefix + ".nav");
  const NavData ref = readRinexNav((dataDir() / "reference/rtklib-2.4.3/ubx_gnss_1730_convbin.nav").string());
  int matched = 0;
  for (const KeplerEphemeris& r : ref.kepler) {
    for (const KeplerEphemeris& k : nav.kepler) {
      if (k.sat == r.sat && k.toe == r.toe) {
        EXPECT_NEAR(k.sqrtA, r.sqrtA, 1e-6) << r.sat.str();
        EXPECT_NEAR(k.e, r.e, 1e-12) << r.sat.str();
        ++matched;
        break;
      }
    }
  }
  EXPECT_EQ(matched, static_cast<int>(ref.kepler.size()));
  EXPECT_GE(matched, 12);  // GPS 4 + BeiDou 8 (convbin's SBAS records are not Keplerian)
  std::cerr << "walk log navigation: " << nav.kepler.size() << " records ours, " << ref.kepler.size()
            << " convbin, all of convbin's matched\n";
  std::filesystem::remove_all(dir);
}

TEST(UbxTool, InfoOnAMixedUbxRtcmNmeaStream) {
  // The F9P log (UBX + NMEA) with an RTCM 3 log spliced in after every 100 kB: the RTCM frames
  // are counted, the UBX messages and NMEA sentences are all still found.
  const auto ubx = readBytes(dataDir() / "ubx/gpsd_ublox-zed-f9p_hpg1.11.log");
  const auto rtcm = readBytes(dataDir() / "rtcm/rtklib_testglo.rtcm3");
  const auto starts = testing::independentScan(ubx).offsets;
  std::vector<std::uint8_t> mixed;
  int splices = 0;
  for (std::size_t i = 0; i < ubx.size();) {
    // Cut only where a UBX frame starts (never inside a frame or a sentence).
    const auto next = std::lower_bound(starts.begin(), starts.end(), i + 100000);
    const std::size_t j = next == starts.end() ? ubx.size() : *next;
    mixed.insert(mixed.end(), ubx.begin() + static_cast<std::ptrdiff_t>(i), ubx.begin() + static_cast<std::ptrdiff_t>(j));
    if (j < ubx.size()) {
      mixed.insert(mixed.end(), rtcm.begin(), rtcm.end());
      ++splices;
    }
    i = j;
  }
  ASSERT_GE(splices, 10);
  const auto dir = std::filesystem::temp_directory_path() / ("gvins_ubx_mixed_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto path = dir / "mixed.bin";
  {
    std::ofstream o(path, std::ios::binary);
    o.write(reinterpret_cast<const char*>(mixed.data()), static_cast<std::streamsize>(mixed.size()));
  }
  const auto [out, rc] = run(kTool + " info - < " + path.string());
  std::filesystem::remove_all(dir);
  ASSERT_EQ(rc, 0) << out;
  long long nmea = -1, rtcmCount = -1;
  std::istringstream in(out);
  std::string line;
  std::map<int, std::int64_t> got;
  while (std::getline(in, line)) {
    unsigned cls = 0, id = 0;
    long long n = 0;
    if (std::sscanf(line.c_str(), "  0x%2X-0x%2X %lld", &cls, &id, &n) == 3) got[static_cast<int>(cls * 256 + id)] = n;
    std::sscanf(line.c_str(), "other %lld NMEA sentences, %lld RTCM 3 frames", &nmea, &rtcmCount);
  }
  EXPECT_EQ(got, testing::independentScan(ubx).types);
  EXPECT_EQ(nmea, countNmea(ubx));
  // rtklib_testglo.rtcm3 holds 429 frames (../shared/data/README.md: 1004 x186, 1012 x186,
  // 1005/1019/1020 x19), all with good CRCs.
  EXPECT_EQ(rtcmCount, 429LL * splices);
  EXPECT_NE(out.find("checksum fail  0 UBX"), std::string::npos) << out;
}

TEST(UbxTool, BadInputsFailCleanly) {
  EXPECT_EQ(run(kTool + " 2>/dev/null").second, 2);
  EXPECT_EQ(run(kTool + " info 2>/dev/null").second, 2);
  EXPECT_EQ(run(kTool + " to-rinex x.ubx 2>/dev/null").second, 2);  // no -o
  EXPECT_EQ(run(kTool + " info /nonexistent.ubx 2>/dev/null").second, 1);
  // A log with SFRBX but no RAWX: the navigation file only (its 8 records, as gvins-ubx info
  // counts them; the sfrbx tests compare such records with convbin's).
  const auto dir = std::filesystem::temp_directory_path() / ("gvins_ubx_bad_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto [out, rc] = run(kTool + " to-rinex " + (dataDir() / "ubx/gpsd_ublox-x20p.log").string() + " -o " +
                             (dir / "x").string() + " 2>&1");
  EXPECT_EQ(rc, 0) << out;
  EXPECT_FALSE(std::filesystem::exists(dir / "x.obs"));
  ASSERT_TRUE(std::filesystem::exists(dir / "x.nav")) << out;
  const NavData nav = readRinexNav((dir / "x.nav").string());
  EXPECT_EQ(nav.kepler.size() + nav.glonass.size(), 8u);
  // Neither RAWX nor SFRBX (NMEA text only): nothing to convert, no output left behind.
  {
    std::ofstream o(dir / "nmea.txt");
    o << "$GNGGA,172814.00,4005.80159,N,10508.83000,W,1,12,0.99,1579.9,M,-21.4,M,,*40\r\n";
  }
  const auto [out2, rc2] = run(kTool + " to-rinex " + (dir / "nmea.txt").string() + " -o " + (dir / "y").string() + " 2>&1");
  EXPECT_EQ(rc2, 1);
  EXPECT_NE(out2.find("no UBX frame"), std::string::npos) << out2;
  EXPECT_FALSE(std::filesystem::exists(dir / "y.obs"));
  EXPECT_FALSE(std::filesystem::exists(dir / "y.nav"));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace gvins::ubx
