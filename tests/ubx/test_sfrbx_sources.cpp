// SFRBX counters per gnssId/sigId (BeiDou GEO apart): the walk log's messages per source as counted
// once by a separate Python frame scanner (the figures below), and every log's against a tally of
// the raw bytes made here with the independent frame scan (payload bytes 0 gnssId, 1 svId, 2 sigId;
// svId 1-5 and 59-63 are BeiDou GEO). No real log bundled here holds a BeiDou GEO (D2) subframe.
#include <gtest/gtest.h>

#include <map>

#include "sfrbx_log.hpp"

namespace gvins::ubx {
namespace {

using testing::dataDir;
using testing::decodeLog;

TEST(SfrbxSources, WalkLogBreakdownMatchesIndependentTally) {
  const auto log = decodeLog(dataDir() / "ubx" / "gnss_1730.ubx");
  struct Row {
    int gnss, sig;
    std::uint64_t messages;
    bool decoded;
    const char* message;
  };
  const Row expected[] = {
      {0, 0, 80, true, "LNAV"},   {0, 4, 40, true, "CNAV (L2C)"},
      {0, 6, 108, true, "CNAV (L5)"}, {1, 0, 307, false, "SBAS (not decoded)"},
      {2, 1, 396, true, "I/NAV"}, {2, 3, 98, false, "F/NAV (not decoded)"},
      {2, 8, 634, false, "E6 C/NAV (not decoded)"}, {3, 4, 153, true, "D1 (MEO/IGSO)"},
      {3, 6, 148, false, "B-CNAV1 (not decoded)"}, {3, 8, 364, false, "B-CNAV2 (not decoded)"},
  };
  const auto& by = log.assembler.countsBySource();
  ASSERT_EQ(by.size(), std::size(expected));
  std::uint64_t skipped = 0, ephemerides = 0;
  for (const Row& r : expected) {
    const NavigationSource src{static_cast<std::uint8_t>(r.gnss), static_cast<std::uint8_t>(r.sig), false};
    const auto it = by.find(src);
    ASSERT_NE(it, by.end()) << r.gnss << "/" << r.sig;
    EXPECT_EQ(it->second.messages, r.messages) << r.gnss << "/" << r.sig;
    const NavigationSourceInfo info = navigationSourceInfo(src);
    EXPECT_EQ(info.decoded, r.decoded);
    EXPECT_EQ(info.message, r.message);
    // A source not decoded is skipped as a whole; a decoded one never is.
    EXPECT_EQ(it->second.skipped, r.decoded ? 0u : r.messages) << r.gnss << "/" << r.sig;
    skipped += it->second.skipped;
    ephemerides += it->second.ephemerides;
  }
  EXPECT_EQ(skipped, 1551u);  // the "not decoded" figure of gvins-ubx info
  EXPECT_EQ(ephemerides, log.assembler.total().ephemerides);
  EXPECT_EQ(log.assembler.total().messages, 2328u);
}

TEST(SfrbxSources, EveryLogMatchesARawByteTally) {
  for (const auto& path : testing::ubxFiles()) {
    SCOPED_TRACE(path.string());
    const std::vector<std::uint8_t> d = testing::readBytes(path);
    std::map<NavigationSource, std::uint64_t> tally;
    for (std::size_t at : testing::independentScan(d).offsets) {
      if (d[at + 2] != 0x02 || d[at + 3] != 0x13) continue;
      const std::uint8_t* p = d.data() + at + 6;
      tally[{p[0], p[2], p[0] == 3 && ((p[1] >= 1 && p[1] <= 5) || (p[1] >= 59 && p[1] <= 63))}]++;
    }
    const auto log = decodeLog(path);
    std::map<NavigationSource, std::uint64_t> ours;
    for (const auto& [src, c] : log.assembler.countsBySource()) ours[src] = c.messages;
    EXPECT_EQ(ours, tally);
    bool geo = false;
    for (const auto& [src, n] : tally) geo = geo || src.beidouGeo;
    EXPECT_FALSE(geo);  // measured: no GEO subframe in any bundled log
  }
}

TEST(SfrbxSources, BeiDouGeoAndUnknownIdsAreTheirOwnRows) {
  EXPECT_EQ(navigationSourceInfo({3, 4, false}).message, "D1 (MEO/IGSO)");
  EXPECT_EQ(navigationSourceInfo({3, 0, true}).message.substr(0, 8), "D2 (GEO)");
  EXPECT_FALSE(navigationSourceInfo({4, 0, false}).decoded);  // IMES
  EXPECT_FALSE(navigationSourceInfo({0, 9, false}).decoded);  // reserved GPS sigId
  NavigationAssembler a;
  SfrbxMessage m;
  m.gnssId = 3;
  m.svId = 2;  // C02: GEO
  m.sigId = 0;
  m.words.assign(10, 0u);
  a.add(m, GpsTime{});
  m.gnssId = 9;  // reserved gnssId
  a.add(m, GpsTime{});
  const auto& by = a.countsBySource();
  ASSERT_EQ(by.size(), 2u);
  EXPECT_EQ(by.begin()->first.beidouGeo, true);
  EXPECT_EQ(by.rbegin()->first.gnssId, 9);
  EXPECT_EQ(by.rbegin()->second.unknownMessages, 1u);
  EXPECT_EQ(a.total().messages, 2u);
}

}  // namespace
}  // namespace gvins::ubx
