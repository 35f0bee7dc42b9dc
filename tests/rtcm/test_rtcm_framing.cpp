// Framing: CRC-24Q, the Framer against an independent scan on every bundled RTCM file, chunked
// feeding, corrupted and truncated frames, garbage between frames.
#include <gtest/gtest.h>

#include <random>
#include <string_view>

#include "gvins/rtcm/crc24q.hpp"
#include "gvins/rtcm/decoder.hpp"
#include "gvins/rtcm/framer.hpp"
#include "independent_frame_scan.hpp"

namespace gvins::rtcm {
namespace {

using testing::dataDir;
using testing::independentScan;
using testing::readBytes;

std::map<int, std::int64_t> frameTypes(const std::vector<std::uint8_t>& d, std::size_t chunk,
                                       FramerStats* stats = nullptr) {
  Framer f;
  std::map<int, std::int64_t> types;
  Frame fr;
  for (std::size_t i = 0; i < d.size(); i += chunk) {
    f.feed({d.data() + i, std::min(chunk, d.size() - i)});
    while (f.next(fr)) ++types[fr.type()];
  }
  f.finish();
  while (f.next(fr)) ++types[fr.type()];
  if (stats) *stats = f.stats();
  return types;
}

TEST(Crc24q, CatalogueCheckValue) {
  // CRC-24Q is the CRC catalogue's CRC-24/LTE-A: check value of "123456789" is 0xCDE703.
  const std::string_view s = "123456789";
  EXPECT_EQ(crc24q({reinterpret_cast<const std::uint8_t*>(s.data()), s.size()}), 0xCDE703u);
  // Continuation gives the same result as one pass.
  const auto* p = reinterpret_cast<const std::uint8_t*>(s.data());
  EXPECT_EQ(crc24q({p + 4, 5}, crc24q({p, 4})), 0xCDE703u);
  EXPECT_EQ(testing::bitwiseCrc24q(p, 9), 0xCDE703u);
}

TEST(Framer, EveryBundledFileMatchesIndependentScan) {
  const auto files = testing::rtcmFiles();
  ASSERT_GE(files.size(), 80u);
  std::int64_t total = 0;
  for (const auto& path : files) {
    SCOPED_TRACE(path.string());
    const auto d = readBytes(path);
    const auto ref = independentScan(d);
    FramerStats st;
    const auto got = frameTypes(d, 4096, &st);
    EXPECT_EQ(got, ref.types);
    EXPECT_EQ(st.frames, ref.frames);
    EXPECT_EQ(st.crcFailures, ref.badCandidates);
    EXPECT_EQ(st.bytes, static_cast<std::int64_t>(d.size()));
    total += st.frames;
  }
  std::cerr << "frames in " << files.size() << " files: " << total << "\n";
}

TEST(Framer, CountsMatchTheDataReadme) {
  // Message counts documented in ../shared/data/README.md (and tests/data/README.md).
  const auto glo = frameTypes(readBytes(dataDir() / "rtcm/rtklib_testglo.rtcm3"), 1 << 20);
  EXPECT_EQ(glo, (std::map<int, std::int64_t>{{1004, 186}, {1005, 19}, {1012, 186}, {1019, 19}, {1020, 19}}));
  const auto gmsd = frameTypes(readBytes(dataDir() / "rtcm/rtklib_GMSD7_20121014.rtcm3"), 1 << 20);
  EXPECT_EQ(gmsd, (std::map<int, std::int64_t>{{1007, 28}, {1008, 28}, {1019, 15}, {1020, 16}, {1033, 28},
                                               {1077, 257}, {1087, 257}, {1117, 257}, {1127, 257}}));
  const auto cssr = frameTypes(readBytes(dataDir() / "rtcm/cssrlib_idd2023229c.rtc"), 1 << 20);
  EXPECT_EQ(cssr.at(1019), 3407);
  EXPECT_EQ(cssr.at(1046), 2672);
  for (int t : {1059, 1060, 1242, 1243}) EXPECT_GT(cssr.at(t), 0) << t;
  // go-gnss: one valid frame per file, of the type in its name.
  int n = 0;
  for (const auto& e : std::filesystem::directory_iterator(dataDir() / "rtcm/go-gnss_frames")) {
    const int type = std::stoi(e.path().filename().string().substr(0, 4));
    EXPECT_EQ(frameTypes(readBytes(e.path()), 1 << 20), (std::map<int, std::int64_t>{{type, 1}})) << e.path();
    ++n;
  }
  EXPECT_EQ(n, 69);
}

TEST(Framer, AnyChunkSizeGivesTheSameFrames) {
  const auto d = readBytes(dataDir() / "rtcm/rtklib_GMSD7_20121014.rtcm3");
  const auto whole = frameTypes(d, d.size());
  for (std::size_t chunk : {1u, 2u, 3u, 7u, 100u, 1029u, 65536u}) {
    FramerStats st;
    EXPECT_EQ(frameTypes(d, chunk, &st), whole) << "chunk " << chunk;
    EXPECT_EQ(st.truncatedFrames, 1) << "the file is cut mid-frame";
  }
}

TEST(Framer, CorruptedFramesAreSkippedAndCounted) {
  // pyrtcm's BADCRC log is the MIXED log with one byte of its first frame (1005) changed.
  const auto good = readBytes(dataDir() / "rtcm/pyrtcm_pygpsdata-MIXED-RTCM3.log");
  const auto bad = readBytes(dataDir() / "rtcm/pyrtcm_pygpsdata-MIXED-RTCM3BADCRC.log");
  ASSERT_EQ(good.size(), bad.size());
  FramerStats sg, sb;
  const auto tg = frameTypes(good, 64, &sg);
  const auto tb = frameTypes(bad, 64, &sb);
  EXPECT_EQ(sg.crcFailures, 0);
  EXPECT_EQ(sb.crcFailures, 1);
  auto expect = tg;
  expect.erase(1005);
  EXPECT_EQ(tb, expect);
  EXPECT_EQ(sb.frames, sg.frames - 1);
  // The skipped bytes are those of the corrupted frame.
  EXPECT_EQ(sb.skippedBytes - sg.skippedBytes, 25);

  // BADHDR: UBX data with a damaged header; no RTCM frame at all, every byte skipped.
  const auto hdr = readBytes(dataDir() / "rtcm/pyrtcm_pygpsdata-BADHDR.log");
  FramerStats sh;
  EXPECT_TRUE(frameTypes(hdr, 13, &sh).empty());
  EXPECT_EQ(sh.skippedBytes, static_cast<std::int64_t>(hdr.size()));
}

TEST(Framer, GarbageBetweenFramesAndFlippedBits) {
  const auto d = readBytes(dataDir() / "rtcm/rtklib_testglo.rtcm3");
  const auto ref = independentScan(d);
  // Cut the good frames out and interleave them with random garbage that contains preambles.
  std::vector<std::vector<std::uint8_t>> frames;
  {
    Framer f;
    f.feed(d);
    Frame fr;
    while (f.next(fr)) {
      std::vector<std::uint8_t> v{0xD3, static_cast<std::uint8_t>(fr.payload.size() >> 8),
                                  static_cast<std::uint8_t>(fr.payload.size() & 0xFF)};
      v.insert(v.end(), fr.payload.begin(), fr.payload.end());
      const std::uint32_t c = crc24q(v);
      v.push_back(static_cast<std::uint8_t>(c >> 16));
      v.push_back(static_cast<std::uint8_t>(c >> 8));
      v.push_back(static_cast<std::uint8_t>(c));
      frames.push_back(std::move(v));
    }
  }
  ASSERT_EQ(static_cast<std::int64_t>(frames.size()), ref.frames);
  std::mt19937 rng(42);
  std::vector<std::uint8_t> mixed;
  std::int64_t corrupted = 0;
  std::map<int, std::int64_t> expect;
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const int junk = static_cast<int>(rng() % 40);
    for (int j = 0; j < junk; ++j) mixed.push_back(j % 7 == 0 ? 0xD3 : static_cast<std::uint8_t>(rng()));
    std::vector<std::uint8_t> f = frames[k];
    if (k % 10 == 3) {  // flip one payload bit: this frame must be lost, the rest kept
      f[3 + rng() % (f.size() - 6)] ^= static_cast<std::uint8_t>(1u << (rng() % 8));
      ++corrupted;
    } else {
      ++expect[(f[3] << 4) | (f[4] >> 4)];
    }
    mixed.insert(mixed.end(), f.begin(), f.end());
  }
  for (std::size_t chunk : {1u, 5u, 4096u}) {
    FramerStats st;
    const auto got = frameTypes(mixed, chunk, &st);
    EXPECT_EQ(got, expect) << "chunk " << chunk;
    EXPECT_GE(st.crcFailures, corrupted);
    EXPECT_EQ(got, independentScan(mixed).types);
  }
}

TEST(Framer, TruncatedFrameThenGoodFramesAtStreamEnd) {
  const auto d = readBytes(dataDir() / "rtcm/go-gnss_frames/1005_frame.bin");
  // A frame cut after 10 bytes, then two complete frames: the framer must not wait forever for the
  // first one once the stream ends.
  std::vector<std::uint8_t> s(d.begin(), d.begin() + 10);
  s.insert(s.end(), d.begin(), d.end());
  s.insert(s.end(), d.begin(), d.end());
  Framer f;
  f.feed(s);
  Frame fr;
  int n = 0;
  while (f.next(fr)) ++n;
  // The truncated candidate claims 19 payload bytes and so swallows the start of the next frame:
  // its CRC fails, the framer resynchronises and finds both complete frames.
  f.finish();
  while (f.next(fr)) ++n;
  EXPECT_EQ(n, 2);
  EXPECT_EQ(f.stats().crcFailures, 1);

  // Cut at the very end: counted as truncated, not as a CRC failure.
  Framer g;
  std::vector<std::uint8_t> t(d.begin(), d.end());
  t.insert(t.end(), d.begin(), d.end() - 4);
  g.feed(t);
  n = 0;
  while (g.next(fr)) ++n;
  g.finish();
  while (g.next(fr)) ++n;
  EXPECT_EQ(n, 1);
  EXPECT_EQ(g.stats().truncatedFrames, 1);
  EXPECT_EQ(g.stats().crcFailures, 0);
  EXPECT_EQ(g.stats().skippedBytes, static_cast<std::int64_t>(d.size() - 4));
}

}  // namespace
}  // namespace gvins::rtcm
