// UBX framing: the Framer against an independent scan and the documented counts on every bundled
// UBX log, any chunk size, corrupted, oversize and truncated frames, garbage between frames.
#include <gtest/gtest.h>

#include <random>

#include "gvins/ubx/ubx_framer.hpp"
#include "independent_ubx_scan.hpp"

namespace gvins::ubx {
namespace {

using testing::dataDir;
using testing::independentScan;
using testing::makeFrame;
using testing::readBytes;

std::map<int, std::int64_t> frameTypes(const std::vector<std::uint8_t>& d, std::size_t chunk,
                                       FramerStats* stats = nullptr) {
  Framer f;
  std::map<int, std::int64_t> types;
  Frame fr;
  auto take = [&] {
    EXPECT_EQ(d[static_cast<std::size_t>(fr.offset)], 0xB5);
    EXPECT_EQ(d[static_cast<std::size_t>(fr.offset) + 2], fr.msgClass);
    ++types[fr.type()];
  };
  for (std::size_t i = 0; i < d.size(); i += chunk) {
    f.feed({d.data() + i, std::min(chunk, d.size() - i)});
    while (f.next(fr)) take();
  }
  f.finish();
  while (f.next(fr)) take();
  if (stats) *stats = f.stats();
  return types;
}

TEST(UbxFramer, FletcherChecksumOfAKnownPoll) {
  // The MON-VER poll request B5 62 0A 04 00 00 has checksum 0E 34 (u-blox interface description
  // example; also what u-center sends).
  const std::vector<std::uint8_t> body{0x0A, 0x04, 0x00, 0x00};
  EXPECT_EQ(fletcher8(body), 0x340E);
  EXPECT_EQ(makeFrame(0x0A, 0x04, {}), (std::vector<std::uint8_t>{0xB5, 0x62, 0x0A, 0x04, 0, 0, 0x0E, 0x34}));
}

TEST(UbxFramer, EveryBundledLogMatchesIndependentScan) {
  const auto files = testing::ubxFiles();
  ASSERT_EQ(files.size(), 6u);
  for (const auto& path : files) {
    SCOPED_TRACE(path.string());
    const auto d = readBytes(path);
    const auto ref = independentScan(d);
    FramerStats st;
    EXPECT_EQ(frameTypes(d, 4096, &st), ref.types);
    EXPECT_EQ(st.frames, ref.frames);
    EXPECT_EQ(st.checksumFailures, ref.badCandidates);
    EXPECT_EQ(st.bytes, static_cast<std::int64_t>(d.size()));
  }
}

TEST(UbxFramer, CountsMatchTheDataReadme) {
  // Message counts documented in ../shared/data/README.md (and tests/data/README.md).
  const auto walk = frameTypes(readBytes(dataDir() / "ubx/gnss_1730.ubx"), 1 << 20);
  EXPECT_EQ(walk, (std::map<int, std::int64_t>{{0x0107, 536}, {0x0213, 2328}, {0x0215, 536}}));
  const auto f9p = frameTypes(readBytes(dataDir() / "ubx/gpsd_ublox-zed-f9p_hpg1.11.log"), 1 << 20);
  EXPECT_EQ(f9p, (std::map<int, std::int64_t>{{0x0122, 655}, {0x0214, 654}, {0x0215, 654}}));
  const auto m8t = frameTypes(readBytes(dataDir() / "ubx/gpsd_ublox-neo-m8t.log"), 1 << 20);
  EXPECT_EQ(m8t.at(0x0215), 39);
  const auto py = frameTypes(readBytes(dataDir() / "ubx/pyubx2_pygpsdata-RXMRAWX.log"), 1 << 20);
  EXPECT_EQ(py, (std::map<int, std::int64_t>{{0x0215, 14}}));
}

TEST(UbxFramer, AnyChunkSizeGivesTheSameFrames) {
  // The F9P log interleaves NMEA with UBX: the framer skips the text.
  const auto d = readBytes(dataDir() / "ubx/gpsd_ublox-zed-f9p_hpg1.11.log");
  const auto whole = frameTypes(d, d.size());
  for (std::size_t chunk : {1u, 2u, 3u, 7u, 100u, 8200u, 65536u}) {
    FramerStats st;
    EXPECT_EQ(frameTypes(d, chunk, &st), whole) << "chunk " << chunk;
    EXPECT_EQ(st.checksumFailures, 0);
    EXPECT_EQ(st.truncatedFrames, 0);
  }
}

TEST(UbxFramer, GarbageBetweenFramesAndFlippedBits) {
  const auto d = readBytes(dataDir() / "ubx/pyubx2_pygpsdata-RXMRAWX.log");
  std::vector<std::vector<std::uint8_t>> frames;
  {
    Framer f;
    f.feed(d);
    Frame fr;
    while (f.next(fr)) frames.push_back(makeFrame(fr.msgClass, fr.msgId, {fr.payload.begin(), fr.payload.end()}));
  }
  ASSERT_EQ(frames.size(), 14u);
  std::mt19937 rng(7);
  std::vector<std::uint8_t> mixed;
  std::int64_t corrupted = 0, kept = 0;
  for (int rep = 0; rep < 5; ++rep) {
    for (std::size_t k = 0; k < frames.size(); ++k) {
      const int junk = static_cast<int>(rng() % 30);
      for (int j = 0; j < junk; ++j) mixed.push_back(j % 5 == 0 ? 0xB5 : j % 5 == 1 ? 0x62 : static_cast<std::uint8_t>(rng()));
      std::vector<std::uint8_t> f = frames[k];
      if ((k + static_cast<std::size_t>(rep)) % 4 == 1) {  // flip one bit after the sync chars
        f[2 + rng() % (f.size() - 2)] ^= static_cast<std::uint8_t>(1u << (rng() % 8));
        ++corrupted;
      } else {
        ++kept;
      }
      mixed.insert(mixed.end(), f.begin(), f.end());
    }
  }
  for (std::size_t chunk : {1u, 5u, 4096u}) {
    FramerStats st;
    const auto got = frameTypes(mixed, chunk, &st);
    EXPECT_EQ(st.frames, kept) << "chunk " << chunk;
    EXPECT_GE(st.checksumFailures + st.oversizeLengths, corrupted);
    EXPECT_EQ(got, independentScan(mixed).types);
  }
}

TEST(UbxFramer, OversizeLengthIsSkippedWithoutWaiting) {
  // A sync pair announcing 60000 bytes followed by a good frame: the framer must not wait for the
  // 60000 bytes but resynchronise on the next frame at once.
  const auto good = makeFrame(0x01, 0x07, std::vector<std::uint8_t>(92, 0x11));
  std::vector<std::uint8_t> s{0xB5, 0x62, 0x02, 0x15, 0x60, 0xEA};
  s.insert(s.end(), good.begin(), good.end());
  Framer f;
  f.feed(s);
  Frame fr;
  ASSERT_TRUE(f.next(fr));  // before finish(): nothing to wait for
  EXPECT_EQ(fr.type(), 0x0107);
  EXPECT_EQ(fr.offset, 6);
  EXPECT_EQ(fr.payload.size(), 92u);
  EXPECT_EQ(f.stats().oversizeLengths, 1);
  EXPECT_EQ(f.stats().skippedBytes, 6);
  // A larger limit accepts a longer payload.
  const auto big = makeFrame(0x02, 0x15, std::vector<std::uint8_t>(9000, 0));
  Framer g(10000);
  g.feed(big);
  ASSERT_TRUE(g.next(fr));
  EXPECT_EQ(fr.payload.size(), 9000u);
  Framer h;
  h.feed(big);
  h.finish();
  EXPECT_FALSE(h.next(fr));
  EXPECT_EQ(h.stats().oversizeLengths, 1);
}

TEST(UbxFramer, TruncatedFrameAtStreamEnd) {
  const auto a = makeFrame(0x01, 0x07, std::vector<std::uint8_t>(92, 0x22));
  std::vector<std::uint8_t> s = a;
  s.insert(s.end(), a.begin(), a.end() - 3);
  Framer f;
  f.feed(s);
  Frame fr;
  int n = 0;
  while (f.next(fr)) ++n;
  EXPECT_EQ(n, 1);
  f.finish();
  while (f.next(fr)) ++n;
  EXPECT_EQ(n, 1);
  EXPECT_EQ(f.stats().truncatedFrames, 1);
  EXPECT_EQ(f.stats().checksumFailures, 0);
  EXPECT_EQ(f.stats().skippedBytes, static_cast<std::int64_t>(a.size() - 3));
  // A truncated candidate that swallows the start of a good frame: resynchronised, not lost.
  std::vector<std::uint8_t> t(a.begin(), a.begin() + 20);
  t.insert(t.end(), a.begin(), a.end());
  Framer g;
  g.feed(t);
  n = 0;
  while (g.next(fr)) ++n;
  g.finish();
  while (g.next(fr)) ++n;
  EXPECT_EQ(n, 1);
  EXPECT_EQ(g.stats().checksumFailures, 1);
}

}  // namespace
}  // namespace gvins::ubx
