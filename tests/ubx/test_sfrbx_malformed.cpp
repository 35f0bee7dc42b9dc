// Malformed RXM-SFRBX input: payload errors name the field; corrupted bits fail the parity, BCH,
// CRC and Hamming checks (counted, no record); mixed issues of data, truncated and swapped pages
// never give a record. The corruptions are applied to the real messages of the bundled logs.
#include <gtest/gtest.h>

#include "gvins/rtcm/crc24q.hpp"
#include "gvins/ubx/sfrbx_error.hpp"
#include "sfrbx_log.hpp"

namespace gvins::ubx {
namespace {

using testing::dataDir;
using testing::decodeLog;

std::vector<std::uint8_t> payload(std::uint8_t gnss, std::uint8_t numWords, std::size_t bytes, std::uint8_t version = 2) {
  std::vector<std::uint8_t> p(bytes, 0);
  if (bytes > 0) p[0] = gnss;
  if (bytes > 4) p[4] = numWords;
  if (bytes > 6) p[6] = version;
  return p;
}

std::string fieldOf(const std::vector<std::uint8_t>& p) {
  try {
    parseSfrbx(p);
  } catch (const SfrbxError& e) {
    return e.field();
  }
  return "";
}

TEST(SfrbxPayload, HeaderAndWordsDecoded) {
  std::vector<std::uint8_t> p{6, 16, 0, 9, 2, 12, 2, 0, 0x78, 0x56, 0x34, 0x12, 0xff, 0, 0, 0x80};
  const SfrbxMessage m = parseSfrbx(p);
  EXPECT_EQ(m.gnssId, 6);
  EXPECT_EQ(m.svId, 16);
  EXPECT_EQ(m.freqId, 9);
  EXPECT_EQ(m.channel, 12);
  EXPECT_EQ(m.version, 2);
  ASSERT_EQ(m.words.size(), 2u);
  EXPECT_EQ(m.words[0], 0x12345678u);  // little-endian U4
  EXPECT_EQ(m.words[1], 0x800000ffu);
}

TEST(SfrbxPayload, ErrorsNameTheField) {
  EXPECT_EQ(fieldOf({}), "length");
  EXPECT_EQ(fieldOf(payload(0, 0, 7)), "length");
  EXPECT_EQ(fieldOf(payload(0, 10, 8 + 36)), "numWords");   // one word short
  EXPECT_EQ(fieldOf(payload(0, 10, 8 + 44)), "numWords");   // one word too many
  EXPECT_EQ(fieldOf(payload(0, 0, 8, 0)), "version");
  EXPECT_EQ(fieldOf(payload(0, 0, 8, 3)), "version");
  EXPECT_EQ(fieldOf(payload(0, 255, 8 + 1020)), "");
  try {
    parseSfrbx(payload(0, 10, 20));
    FAIL();
  } catch (const SfrbxError& e) {
    EXPECT_NE(std::string(e.what()).find("10 words need 48 bytes, the payload has 20"), std::string::npos) << e.what();
  }
}

// Flips one bit of every message of a system: no record, every message counted as a check failure.
TEST(SfrbxMalformed, OneFlippedBitFailsEveryCheck) {
  struct Case {
    const char* log;
    std::uint8_t gnss;
    int word, bit;
    System system;
    bool crc;
  };
  // GPS: data bit d12 of the HOW; BeiDou: an information bit of word 3; Galileo: a data bit of the
  // even page; GLONASS: a bit of the tb/Bn area of the string.
  const Case cases[] = {{"gnss_1730.ubx", 0, 1, 17, System::Gps, false},
                        {"gnss_1730.ubx", 3, 2, 20, System::BeiDou, false},
                        {"gnss_1730.ubx", 2, 1, 5, System::Galileo, true},
                        {"gpsd_ublox-zed-f9p-sfrbx.log", 6, 0, 20, System::Glonass, false}};
  for (const Case& c : cases) {
    SCOPED_TRACE(std::string(systemName(c.system)));
    std::uint64_t flipped = 0;
    const auto log = decodeLog(dataDir() / "ubx" / c.log, [&](SfrbxMessage& m) {
      const bool decoded = m.gnssId == c.gnss && (c.gnss != 0 || m.sigId == 0) && (c.gnss != 2 || m.sigId == 1 || m.sigId == 5) &&
                           (c.gnss != 3 || m.words.size() == 10);
      if (!decoded || static_cast<int>(m.words.size()) <= c.word) return;
      m.words[static_cast<std::size_t>(c.word)] ^= 1u << c.bit;
      ++flipped;
    });
    const NavigationCounts& n = log.assembler.counts(c.system);
    ASSERT_GT(flipped, 0u);
    EXPECT_EQ(c.crc ? n.crcFailures : n.parityFailures, flipped);
    EXPECT_EQ(n.ephemerides, 0u);
    for (const auto& e : log.kepler) EXPECT_NE(e.sat.system, c.system);
    if (c.system == System::Glonass) {
      EXPECT_TRUE(log.glonass.empty());
    }
  }
}

TEST(SfrbxMalformed, CleanLogsPassEveryCheck) {
  // The same logs untouched: the checks accept every message (parity near zero on good data).
  for (const char* name : {"gnss_1730.ubx", "gpsd_ublox-zed-f9p-sfrbx.log", "gpsd_ublox-x20p.log"}) {
    const auto log = decodeLog(dataDir() / "ubx" / name);
    EXPECT_EQ(log.assembler.total().parityFailures, 0u) << name;
    EXPECT_EQ(log.assembler.total().crcFailures, 0u) << name;
    EXPECT_GT(log.assembler.total().ephemerides, 0u) << name;
  }
}

// Galileo: word type 2 of E21 given another IODnav (CRC recomputed, so the page is valid): the
// words of one set disagree and no record may come out.
TEST(SfrbxMalformed, MixedGalileoIodnavGivesNoRecord) {
  auto setIod = [](SfrbxMessage& m) {
    if (m.gnssId != 2 || m.svId != 21 || m.words.size() < 8) return;
    // Word type: bits 2-7 of the even part.
    const std::uint32_t type = (m.words[0] >> 24) & 0x3f;
    if (type != 2) return;
    // IODnav: the next 10 bits (even part bits 8-17).
    std::uint32_t w0 = m.words[0];
    const std::uint32_t iod = ((w0 >> 14) & 0x3ff) ^ 1u;
    w0 = (w0 & ~(0x3ffu << 14)) | (iod << 14);
    m.words[0] = w0;
    // Recompute the CRC-24Q over even bits 0-113 and odd bits 0-81 (Galileo OS SIS ICD 4.3.2.4).
    std::vector<bool> bits;
    auto get = [&](int word, int bit) { return ((m.words[static_cast<std::size_t>(word + bit / 32)] >> (31 - bit % 32)) & 1u) != 0; };
    for (int k = 0; k < 4; ++k) bits.push_back(false);
    for (int k = 0; k < 114; ++k) bits.push_back(get(0, k));
    for (int k = 0; k < 82; ++k) bits.push_back(get(4, k));
    std::vector<std::uint8_t> bytes(25, 0);
    for (std::size_t k = 0; k < bits.size(); ++k)
      if (bits[k]) bytes[k / 8] |= static_cast<std::uint8_t>(0x80 >> (k % 8));
    const std::uint32_t crc = rtcm::crc24q(bytes);
    for (int k = 0; k < 24; ++k) {
      const int pos = 82 + k;
      std::uint32_t& w = m.words[static_cast<std::size_t>(4 + pos / 32)];
      const std::uint32_t mask = 1u << (31 - pos % 32);
      w = (crc >> (23 - k)) & 1u ? (w | mask) : (w & ~mask);
    }
  };
  const auto clean = decodeLog(dataDir() / "ubx" / "gpsd_ublox-zed-f9p-sfrbx.log");
  const auto mixed = decodeLog(dataDir() / "ubx" / "gpsd_ublox-zed-f9p-sfrbx.log", setIod);
  auto has = [](const testing::DecodedLog& l) {
    for (const auto& e : l.kepler)
      if (e.sat == SatId(System::Galileo, 21)) return true;
    return false;
  };
  EXPECT_TRUE(has(clean));
  EXPECT_FALSE(has(mixed));
  EXPECT_EQ(mixed.assembler.counts(System::Galileo).crcFailures, 0u);  // the pages were valid
  EXPECT_GT(mixed.assembler.counts(System::Galileo).incompleteSets, 0u);
}

TEST(SfrbxMalformed, TruncatedAndSwappedPagesGiveNoRecord) {
  // Galileo pages cut to 7 words, GLONASS strings to 3 words, GPS subframes to 9 words.
  const auto cut = decodeLog(dataDir() / "ubx" / "gpsd_ublox-zed-f9p-sfrbx.log", [](SfrbxMessage& m) {
    if (m.gnssId == 2) m.words.resize(7);
    if (m.gnssId == 6) m.words.resize(3);
    if (m.gnssId == 0) m.words.resize(9);
  });
  EXPECT_TRUE(cut.glonass.empty());
  for (const auto& e : cut.kepler) EXPECT_EQ(e.sat.system, System::BeiDou);
  EXPECT_EQ(cut.assembler.counts(System::Galileo).unknownMessages, 29u);
  EXPECT_EQ(cut.assembler.counts(System::Glonass).unknownMessages, 10u);
  EXPECT_EQ(cut.assembler.counts(System::Gps).unknownMessages, 5u);
  // Galileo odd part first: not an even-odd pair.
  const auto swapped = decodeLog(dataDir() / "ubx" / "gpsd_ublox-zed-f9p-sfrbx.log", [](SfrbxMessage& m) {
    if (m.gnssId == 2) std::rotate(m.words.begin(), m.words.begin() + 4, m.words.begin() + 8);
  });
  EXPECT_EQ(swapped.assembler.counts(System::Galileo).ephemerides, 0u);
  EXPECT_EQ(swapped.assembler.counts(System::Galileo).unknownMessages, 29u);
}

TEST(SfrbxMalformed, UnknownGnssAndSatelliteCounted) {
  NavigationAssembler a;
  SfrbxMessage m;
  m.gnssId = 9;  // not a u-blox GNSS
  m.words.assign(10, 0);
  EXPECT_TRUE(a.add(m, GpsTime::fromWeekTow(2381, 1000.0)).empty());
  m.gnssId = 0;
  m.svId = 40;  // not a GPS PRN
  EXPECT_TRUE(a.add(m, GpsTime::fromWeekTow(2381, 1000.0)).empty());
  m.gnssId = 1;  // SBAS: counted and skipped
  m.svId = 131;
  EXPECT_TRUE(a.add(m, GpsTime::fromWeekTow(2381, 1000.0)).empty());
  EXPECT_EQ(a.total().unknownMessages, 2u);
  EXPECT_EQ(a.counts(System::Sbas).skipped, 1u);
  EXPECT_EQ(a.total().messages, 3u);
}

}  // namespace
}  // namespace gvins::ubx
