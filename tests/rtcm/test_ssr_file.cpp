// SSR files (rtcm/ssr_file.hpp): encodeSsrFrames splits messages that do not fit one frame
// (DF388 multiple-message bit on all parts but the last, counted with the decoder and the test's
// own frame scanner), readSsrFile reads a recorded stream back in order (through chunk
// boundaries, skipping other messages), throws gvins::ParseError naming the file when there is
// nothing to read, and skips damaged frames while counting them.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <stdexcept>
#include <string>
#include <unistd.h>
#include <vector>

#include "gvins/base/parse_error.hpp"
#include "gvins/rtcm/decoder.hpp"
#include "gvins/rtcm/encoder.hpp"
#include "gvins/rtcm/ssr_file.hpp"
#include "independent_frame_scan.hpp"
#include "ssr_field_checks.hpp"

namespace gvins::rtcm {
namespace {

namespace fs = std::filesystem;

const GpsTime kEpoch = GpsTime::fromWeekTow(2320, 116400.0);  // 2024-06-24 08:20:00 GPST

/// A file name under the temporary directory, removed at the end of the test.
class TempFile {
 public:
  explicit TempFile(const std::string& name)
      : path_((fs::temp_directory_path() / ("gvins_ssr_file_" + std::to_string(::getpid()) + "_" + name)).string()) {
    fs::remove(path_);
  }
  ~TempFile() {
    std::error_code ec;
    fs::remove(path_, ec);
  }
  const std::string& path() const { return path_; }
  void write(const std::vector<std::uint8_t>& bytes) const {
    std::ofstream f(path_, std::ios::binary);
    f.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  }

 private:
  std::string path_;
};

double uniform(std::mt19937& rng, double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); }

SsrHeader header(System sys, SsrKind kind, const GpsTime& epoch) {
  SsrHeader h;
  h.system = sys;
  h.kind = kind;
  h.epoch = epoch;
  h.updateInterval = 5.0;
  h.regionalDatum = false;
  h.iodSsr = 3;
  h.providerId = 4321;
  h.solutionId = 2;
  return h;
}

/// Combined orbit and clock corrections of satellites PRN 1..n with random values well inside
/// their fields.
SsrMessage combined(System sys, int n, const GpsTime& epoch, std::mt19937& rng) {
  SsrMessage m;
  m.header = header(sys, SsrKind::kCombined, epoch);
  for (int prn = 1; prn <= n; ++prn) {
    SsrSatellite s;
    s.sat = SatId(sys, prn);
    SsrOrbitCorrection o;
    o.issueOfData = static_cast<int>(rng() % 256);
    if (sys == System::BeiDou) o.iodCrc = static_cast<int>(rng() % 240);
    o.rac = {uniform(rng, -2, 2), uniform(rng, -3, 3), uniform(rng, -3, 3)};
    o.racRate = {uniform(rng, -1e-3, 1e-3), uniform(rng, -2e-3, 2e-3), uniform(rng, -2e-3, 2e-3)};
    s.orbit = o;
    s.clock = SsrClockCorrection{uniform(rng, -5, 5), uniform(rng, -1e-2, 1e-2), uniform(rng, -1e-5, 1e-5)};
    m.satellites.push_back(s);
  }
  return m;
}

/// Every result of decoding `bytes` (one feed, then finish).
struct Decoded {
  std::vector<SsrMessage> ssr;
  DecoderStats stats;
};

Decoded decodeAll(const std::vector<std::uint8_t>& bytes) {
  DecoderOptions o;
  o.referenceTime = kEpoch;
  Decoder dec(o);
  dec.feed(bytes);
  dec.finish();
  Decoded out;
  while (auto d = dec.poll())
    if (auto* s = std::get_if<SsrMessage>(&*d)) out.ssr.push_back(std::move(*s));
  out.stats = dec.stats();
  return out;
}

void expectSameHeader(const SsrHeader& got, const SsrHeader& sent) {
  EXPECT_EQ(got.system, sent.system);
  EXPECT_EQ(got.kind, sent.kind);
  EXPECT_EQ(got.epoch, sent.epoch);
  EXPECT_EQ(got.updateInterval, sent.updateInterval);
  EXPECT_EQ(got.iodSsr, sent.iodSsr);
  EXPECT_EQ(got.providerId, sent.providerId);
  EXPECT_EQ(got.solutionId, sent.solutionId);
}

/// Byte offsets of the frames the test's own scanner finds (good CRC), in order.
std::vector<std::size_t> frameOffsets(const std::vector<std::uint8_t>& d) {
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i + 6 <= d.size();) {
    const std::size_t len = (static_cast<std::size_t>(d[i + 1] & 3) << 8) | d[i + 2];
    EXPECT_EQ(d[i], 0xD3);
    out.push_back(i);
    i += len + 6;
  }
  return out;
}

// ---- encodeSsrFrames ------------------------------------------------------------------------

TEST(SsrFile, BeidouCombinedOfSixtySatellitesSplitsIntoThreeMessages) {
  std::mt19937 rng(1);
  const SsrMessage m = combined(System::BeiDou, 60, kEpoch, rng);
  // One frame cannot hold them (60 satellites of 215 bits are 1613 bytes).
  EXPECT_THROW(Encoder().ssr(m), std::invalid_argument);
  const std::vector<std::uint8_t> bytes = encodeSsrFrames({m});
  const testing::ScanResult scan = testing::independentScan(bytes);
  EXPECT_EQ(scan.frames, 3);
  EXPECT_EQ(scan.badCandidates, 0);
  EXPECT_EQ(scan.types.at(1261), 3);
  for (std::size_t off : frameOffsets(bytes)) {
    const std::size_t len = (static_cast<std::size_t>(bytes[off + 1] & 3) << 8) | bytes[off + 2];
    EXPECT_LE(len, 1023u);
  }
  const Decoded got = decodeAll(bytes);
  EXPECT_EQ(got.stats.malformed, 0);
  EXPECT_EQ(got.stats.ssrMessages, 3);
  ASSERT_EQ(got.ssr.size(), 3u);
  std::vector<SsrSatellite> all;
  for (std::size_t k = 0; k < 3; ++k) {
    SCOPED_TRACE("part " + std::to_string(k));
    const SsrMessage& p = got.ssr[k];
    EXPECT_EQ(p.header.messageType, 1261);
    expectSameHeader(p.header, m.header);
    EXPECT_EQ(p.header.multipleMessage, k < 2);  // DF388 on every part but the last
    EXPECT_FALSE(p.satellites.empty());
    all.insert(all.end(), p.satellites.begin(), p.satellites.end());
  }
  std::printf("60 BeiDou satellites: parts of %zu, %zu, %zu satellites, %zu bytes\n", got.ssr[0].satellites.size(),
              got.ssr[1].satellites.size(), got.ssr[2].satellites.size(), bytes.size());
  gvins::test::expectSameSatellites(all, m.satellites);
}

TEST(SsrFile, CodeBiasMessagesWithManyBiasesPerSatelliteSplitToo) {
  // 63 BeiDou satellites with a bias on each of the 16 signals: 63 x 315 bits, about 2.5 frames.
  std::mt19937 rng(2);
  const char* signals[] = {"2I", "2Q", "2X", "6I", "6Q", "6X", "7I", "7Q", "7X", "1D", "1P", "1X", "5D", "5P", "5X", "7D"};
  SsrMessage m;
  m.header = header(System::BeiDou, SsrKind::kCodeBias, kEpoch);
  for (int prn = 1; prn <= 63; ++prn) {
    SsrSatellite s;
    s.sat = SatId(System::BeiDou, prn);
    for (const char* c : signals) s.codeBiases.emplace_back(ObsCode(c[0], c[1]), uniform(rng, -20, 20));
    m.satellites.push_back(s);
  }
  EXPECT_THROW(Encoder().ssr(m), std::invalid_argument);
  const std::vector<std::uint8_t> bytes = encodeSsrFrames({m});
  const testing::ScanResult scan = testing::independentScan(bytes);
  ASSERT_GE(scan.frames, 3);
  EXPECT_EQ(scan.types.at(1260), scan.frames);
  const Decoded got = decodeAll(bytes);
  EXPECT_EQ(got.stats.malformed, 0);
  ASSERT_EQ(static_cast<std::int64_t>(got.ssr.size()), scan.frames);
  std::vector<SsrSatellite> all;
  for (std::size_t k = 0; k < got.ssr.size(); ++k) {
    expectSameHeader(got.ssr[k].header, m.header);
    EXPECT_EQ(got.ssr[k].header.multipleMessage, k + 1 < got.ssr.size());
    all.insert(all.end(), got.ssr[k].satellites.begin(), got.ssr[k].satellites.end());
  }
  std::printf("63 BeiDou satellites x 16 code biases: %lld frames, %zu bytes\n", static_cast<long long>(scan.frames),
              bytes.size());
  gvins::test::expectSameSatellites(all, m.satellites);
}

TEST(SsrFile, EmptyMessageGivesOneFrameAndOrderIsKept) {
  std::mt19937 rng(3);
  SsrMessage empty;
  empty.header = header(System::Glonass, SsrKind::kClock, kEpoch);
  const std::vector<std::uint8_t> one = encodeSsrFrames({empty});
  EXPECT_EQ(testing::independentScan(one).frames, 1);
  Decoded got = decodeAll(one);
  ASSERT_EQ(got.ssr.size(), 1u);
  EXPECT_EQ(got.ssr[0].header.messageType, 1064);
  EXPECT_TRUE(got.ssr[0].satellites.empty());
  EXPECT_FALSE(got.ssr[0].header.multipleMessage);
  EXPECT_TRUE(encodeSsrFrames({}).empty());

  // A message that announces more itself keeps DF388 on its last part; messages stay in order.
  SsrMessage gps = combined(System::Gps, 3, kEpoch, rng);
  gps.header.multipleMessage = true;
  const SsrMessage bds = combined(System::BeiDou, 30, kEpoch + 5.0, rng);
  got = decodeAll(encodeSsrFrames({gps, empty, bds}));
  ASSERT_EQ(got.ssr.size(), 4u);
  EXPECT_EQ(got.ssr[0].header.messageType, 1060);
  EXPECT_TRUE(got.ssr[0].header.multipleMessage);
  EXPECT_EQ(got.ssr[1].header.messageType, 1064);
  EXPECT_EQ(got.ssr[2].header.messageType, 1261);
  EXPECT_TRUE(got.ssr[2].header.multipleMessage);
  EXPECT_FALSE(got.ssr[3].header.multipleMessage);
  EXPECT_EQ(got.ssr[3].header.epoch, kEpoch + 5.0);
  EXPECT_EQ(got.ssr[2].satellites.size() + got.ssr[3].satellites.size(), 30u);

  // Encoder errors pass through.
  SsrMessage bad = gps;
  bad.header.updateInterval = 3.0;
  EXPECT_THROW(encodeSsrFrames({bad}), std::invalid_argument);
}

// ---- readSsrFile ----------------------------------------------------------------------------

TEST(SsrFile, ReadBackInOrderThroughChunkBoundariesSkippingOtherMessages) {
  // 60 epochs every 5 s of GPS (32 satellites: two frames) and BeiDou (60: three) corrections with a
  // station position (1005, not SSR) between the epochs: about 150 kB, more than two of the
  // reader's 64 KiB chunks, so frames cross chunk boundaries.
  std::mt19937 rng(4);
  std::vector<SsrMessage> sent;
  std::vector<std::uint8_t> bytes;
  StationPosition station;
  station.stationId = 12;
  station.arp = Eigen::Vector3d(-3962108.7, 3381309.5, 3668678.6);
  const std::vector<std::uint8_t> stationFrame = Encoder(12).stationPosition(station);
  for (int k = 0; k < 60; ++k) {
    const GpsTime t = kEpoch + 5.0 * k;
    const std::vector<SsrMessage> epoch = {combined(System::Gps, 32, t, rng), combined(System::BeiDou, 60, t, rng)};
    const auto f = encodeSsrFrames(epoch);
    bytes.insert(bytes.end(), f.begin(), f.end());
    bytes.insert(bytes.end(), stationFrame.begin(), stationFrame.end());
    sent.insert(sent.end(), epoch.begin(), epoch.end());
  }
  ASSERT_GT(bytes.size(), 2u * 65536u);
  const TempFile file("roundtrip.rtcm3");
  file.write(bytes);
  // Resolved against a reference three days away.
  const SsrFile got = readSsrFile(file.path(), kEpoch + 3 * 86400.0);
  EXPECT_EQ(got.stats.malformed, 0);
  EXPECT_EQ(got.stats.framing.crcFailures, 0);
  EXPECT_EQ(got.stats.messages.at(1005), 60);
  EXPECT_EQ(got.stats.messages.at(1060), 120);  // 26 + 6 satellites
  EXPECT_EQ(got.stats.messages.at(1261), 180);  // 26 + 26 + 8
  EXPECT_EQ(got.stats.ssrMessages, 300);
  ASSERT_EQ(got.messages.size(), 300u);
  // Parts in stream order: GPS x 2, BeiDou x 3 per epoch; joined they are the messages sent.
  std::size_t j = 0;
  for (const SsrMessage& m : sent) {
    SCOPED_TRACE(std::string(systemName(m.header.system)) + " " + m.header.epoch.toString(0));
    std::vector<SsrSatellite> all;
    do {
      ASSERT_LT(j, got.messages.size());
      expectSameHeader(got.messages[j].header, m.header);
      all.insert(all.end(), got.messages[j].satellites.begin(), got.messages[j].satellites.end());
    } while (got.messages[j++].header.multipleMessage);
    gvins::test::expectSameSatellites(all, m.satellites);
  }
  EXPECT_EQ(j, got.messages.size());
}

TEST(SsrFile, NoFrameAtAllIsAParseErrorNamingTheFile) {
  const TempFile text("text.rtcm3"), empty("empty.rtcm3"), missing("missing.rtcm3");
  {
    std::ofstream f(text.path());
    f << "this is a RINEX file, not an RTCM 3 stream\n";
    for (int i = 0; i < 2000; ++i) f << "G05 " << i << " 20000000.000\n";
  }
  std::ofstream(empty.path()).close();
  for (const std::string& p : {text.path(), empty.path(), missing.path()}) {
    SCOPED_TRACE(p);
    try {
      readSsrFile(p, kEpoch);
      ADD_FAILURE() << "no ParseError";
    } catch (const ParseError& e) {
      EXPECT_EQ(e.file(), p);
      EXPECT_NE(std::string(e.what()).find(p), std::string::npos) << e.what();
      EXPECT_FALSE(e.reason().empty());
    }
  }
  // A stream of other messages only is no error: no SSR messages, and the stats say what there was.
  const TempFile obsOnly("station.rtcm3");
  StationPosition station;
  station.arp = Eigen::Vector3d(-3962108.7, 3381309.5, 3668678.6);
  obsOnly.write(Encoder().stationPosition(station));
  const SsrFile none = readSsrFile(obsOnly.path(), kEpoch);
  EXPECT_TRUE(none.messages.empty());
  EXPECT_EQ(none.stats.messages.at(1005), 1);
}

TEST(SsrFile, DamagedFramesAreSkippedAndCounted) {
  // Six good messages; the third one's frame gets a flipped payload bit (CRC failure), the fifth
  // one is a well-framed 1060 that announces more satellites than it holds (malformed).
  std::mt19937 rng(6);
  std::vector<SsrMessage> sent;
  std::vector<std::vector<std::uint8_t>> frames;
  for (int k = 0; k < 6; ++k) {
    sent.push_back(combined(System::Gps, 4 + k, kEpoch + 5.0 * k, rng));
    frames.push_back(encodeSsrFrames({sent.back()}));
  }
  frames[2][20] ^= 0x10;
  {
    std::vector<std::uint8_t> payload(frames[4].begin() + 3, frames[4].end() - 3);
    payload.resize(payload.size() - 40);  // cut inside the last satellites, DF387 unchanged
    frames[4] = Encoder::frame(payload);
  }
  std::vector<std::uint8_t> bytes;
  std::vector<std::size_t> offsets;
  for (const auto& f : frames) {
    offsets.push_back(bytes.size());
    bytes.insert(bytes.end(), f.begin(), f.end());
  }
  const TempFile file("damaged.rtcm3");
  file.write(bytes);
  const SsrFile got = readSsrFile(file.path(), kEpoch);
  ASSERT_EQ(got.messages.size(), 4u);
  const int kept[] = {0, 1, 3, 5};
  for (int i = 0; i < 4; ++i) {
    SCOPED_TRACE(i);
    expectSameHeader(got.messages[i].header, sent[kept[i]].header);
    gvins::test::expectSameSatellites(got.messages[i].satellites, sent[kept[i]].satellites);
  }
  const testing::ScanResult scan = testing::independentScan(bytes);
  EXPECT_GE(got.stats.framing.crcFailures, 1);
  EXPECT_EQ(got.stats.framing.crcFailures, scan.badCandidates);
  EXPECT_EQ(got.stats.framing.frames, 5);
  EXPECT_GE(got.stats.framing.skippedBytes, static_cast<std::int64_t>(frames[2].size()));
  EXPECT_EQ(got.stats.malformed, 1);
  ASSERT_EQ(got.stats.issues.size(), 1u);
  EXPECT_EQ(got.stats.issues[0].type, 1060);
  EXPECT_EQ(got.stats.issues[0].offset, static_cast<std::int64_t>(offsets[4]));
  EXPECT_EQ(got.stats.ssrMessages, 4);
  std::printf("damaged file: %lld CRC failures, %lld bytes skipped, malformed: %s\n",
              static_cast<long long>(got.stats.framing.crcFailures),
              static_cast<long long>(got.stats.framing.skippedBytes), got.stats.issues[0].what.c_str());
}

}  // namespace
}  // namespace gvins::rtcm
