// BeiDou D2 (GEO) ephemerides from RXM-SFRBX. No bundled UBX log holds a D2 subframe, so the
// pages are built here: every BeiDou GEO record of the Nagoya navigation file (Septentrio, broadcast
// D2 ephemerides of C01-C05, C59, C60, C62) is turned back into its broadcast integers, encoded into
// subframe 1 pages 1-10 laid out as BDS-SIS-ICD-B1I 3.0 figure 5-12 draws them (fields in
// transmission order with the 8 parity bits of each word in place), protected with BCH(15,11,1)
// computed by the shift register of 5.1.3 (g(x) = x^4 + x + 1), delivered as u-blox does (22
// information bits, then the 4 + 4 parity bits of each word), and decoded by NavigationAssembler.
// Every field must come back as the RINEX file has it, and as RTKLIB's convbin decodes the same
// pages (an independent decoder checking the encoder's layout). Malformed pages are counted, never
// a record.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>

#include "gvins/ephemeris/rinex_nav.hpp"
#include "gvins/rtcm/accuracy_tables.hpp"
#include "gvins/ubx/navigation_assembler.hpp"
#include "gvins/ubx/sfrbx.hpp"
#include "sfrbx_log.hpp"

namespace gvins::ubx {
namespace {

using testing::dataDir;

// The broadcast fields of subframe 1 pages 1-10 and their total lengths (figure 5-12).
enum Field { SatH1, Aodc, Urai, Wn, Toc, Tgd1, Tgd2, Alpha0, Alpha1, Alpha2, Alpha3, Beta0, Beta1, Beta2, Beta3,
             Rev, A0, A1, A2, Aode, DeltaN, Cuc, M0, Cus, Ecc, SqrtA, Cic, Cis, Toe, I0, Crc, Crs, OmegaDot,
             Omega0, Omega, Idot, Parity, kFields };
constexpr int kLength[kFields] = {1, 5, 4, 13, 17, 10, 10, 8, 8, 8, 8, 8, 8, 8, 8, 38, 24, 22, 11, 5, 16, 18, 32, 18,
                                  32, 32, 18, 18, 17, 32, 18, 18, 24, 32, 32, 14, 8};
struct Piece {
  Field f;
  int bits;  ///< the next `bits` bits of the field, most significant first
};
constexpr Piece P{Parity, 8};
// Each page from bit 46 of the 300-bit subframe (after Pre, Rev, FraID, SOW, parity, SOW, Pnum).
const std::vector<Piece> kPages[10] = {
    {{SatH1, 1}, {Aodc, 5}, P, {Urai, 4}, {Wn, 13}, {Toc, 5}, P, {Toc, 12}, {Tgd1, 10}, P, {Tgd2, 10}},
    {{Alpha0, 6}, P, {Alpha0, 2}, {Alpha1, 8}, {Alpha2, 8}, {Alpha3, 4}, P, {Alpha3, 4}, {Beta0, 8}, {Beta1, 8},
     {Beta2, 2}, P, {Beta2, 6}, {Beta3, 8}},
    {{Rev, 6}, P, {Rev, 22}, P, {Rev, 10}, {A0, 12}, P, {A0, 12}, {A1, 4}},
    {{A1, 6}, P, {A1, 12}, {A2, 10}, P, {A2, 1}, {Aode, 5}, {DeltaN, 16}, P, {Cuc, 14}},
    {{Cuc, 4}, {M0, 2}, P, {M0, 22}, P, {M0, 8}, {Cus, 14}, P, {Cus, 4}, {Ecc, 10}},
    {{Ecc, 6}, P, {Ecc, 16}, {SqrtA, 6}, P, {SqrtA, 22}, P, {SqrtA, 4}, {Cic, 10}},
    {{Cic, 6}, P, {Cic, 2}, {Cis, 18}, {Toe, 2}, P, {Toe, 15}, {I0, 7}, P, {I0, 14}},
    {{I0, 6}, P, {I0, 5}, {Crc, 17}, P, {Crc, 1}, {Crs, 18}, {OmegaDot, 3}, P, {OmegaDot, 16}},
    {{OmegaDot, 5}, {Omega0, 1}, P, {Omega0, 22}, P, {Omega0, 9}, {Omega, 13}, P, {Omega, 14}},
    {{Omega, 5}, {Idot, 1}, P, {Idot, 13}},
};

/// BCH(15,11,1) parity of 11 information bits: the 4-stage shift register dividing by x^4 + x + 1.
std::uint32_t bchParity(std::uint32_t info) {
  std::uint32_t reg = 0;
  for (int i = 10; i >= 0; --i) {
    const std::uint32_t feedback = ((info >> i) & 1u) ^ ((reg >> 3) & 1u);
    reg = ((reg << 1) & 0xfu) ^ (feedback ? 0x3u : 0u);
  }
  return reg;
}

struct Subframe {
  std::array<std::uint8_t, 300> bit{};
  void set(int pos, int len, std::uint64_t v) {
    for (int k = 0; k < len; ++k) bit[static_cast<std::size_t>(pos + k)] = (v >> (len - 1 - k)) & 1u;
  }
  std::uint32_t get(int pos, int len) const {
    std::uint32_t v = 0;
    for (int k = 0; k < len; ++k) v = (v << 1) | bit[static_cast<std::size_t>(pos + k)];
    return v;
  }
  /// Fills the parity bits and returns the ten words as u-blox delivers them (two zero pad bits).
  std::vector<std::uint32_t> words() {
    set(26, 4, bchParity(get(15, 11)));
    for (int w = 1; w < 10; ++w) {
      set(30 * w + 22, 4, bchParity(get(30 * w, 11)));
      set(30 * w + 26, 4, bchParity(get(30 * w + 11, 11)));
    }
    std::vector<std::uint32_t> out;
    for (int w = 0; w < 10; ++w) out.push_back(get(30 * w, 30));
    return out;
  }
};

using Values = std::array<std::int64_t, kFields>;

/// The ten page messages of one 30-s cycle starting at BDT second `sow1` of satellite C`prn`.
std::vector<SfrbxMessage> encodeD2(const Values& v, int prn, std::uint32_t sow1) {
  std::array<int, kFields> used{};
  std::vector<SfrbxMessage> out;
  for (int k = 0; k < 10; ++k) {
    Subframe s;
    s.set(0, 11, 0x712);  // preamble 11100010010
    s.set(15, 3, 1);      // FraID 1
    const std::uint32_t sow = sow1 + 3u * static_cast<std::uint32_t>(k);
    s.set(18, 8, sow >> 12);
    s.set(30, 12, sow & 0xfffu);
    s.set(42, 4, static_cast<std::uint64_t>(k + 1));  // Pnum
    int pos = 46;
    for (const Piece& p : kPages[k]) {
      if (p.f == Parity) {
        EXPECT_EQ(pos % 30, 22) << "page " << k + 1;  // the figure's parity slots end each word
        pos += 8;
        continue;
      }
      const int len = kLength[p.f];
      const std::uint64_t raw = static_cast<std::uint64_t>(v[p.f]) & ((std::uint64_t{1} << len) - 1);
      s.set(pos, p.bits, raw >> (len - used[p.f] - p.bits));
      used[p.f] += p.bits;
      pos += p.bits;
    }
    SfrbxMessage m;
    m.gnssId = 3;
    m.svId = static_cast<std::uint8_t>(prn);
    m.sigId = 1;  // B1I D2
    m.version = 2;
    m.words = s.words();
    out.push_back(m);
  }
  for (int f = 0; f < Parity; ++f) EXPECT_EQ(used[static_cast<std::size_t>(f)], kLength[f]) << "field " << f;
  return out;
}

constexpr double kPi = 3.1415926535898;  // the ICD value of pi (semicircles)
const std::array<std::int64_t, 4> kAlpha{20, 3, -2, -1}, kBeta{63, 10, -3, -4};

/// The broadcast integers of a RINEX record (and the largest distance of a scaled value from an
/// integer: the file must hold exactly representable values).
Values broadcastOf(const KeplerEphemeris& r, double& worst) {
  auto q = [&](double x, double scale) {
    const double n = x / scale;
    worst = std::max(worst, std::fabs(n - std::round(n)));
    return static_cast<std::int64_t>(std::llround(n));
  };
  Values v{};
  int week = 0;
  double tocSow = 0.0;
  gpstToBdt(r.toc, week, tocSow);
  v[SatH1] = r.health;
  v[Aodc] = r.iodc;
  v[Urai] = rtcm::uraIndex(r.ura);
  v[Wn] = r.week;
  v[Toc] = q(tocSow, 8.0);
  v[Tgd1] = q(r.tgd[0], 1e-10);
  v[Tgd2] = q(r.tgd[1], 1e-10);
  for (int i = 0; i < 4; ++i) {
    v[Alpha0 + i] = kAlpha[static_cast<std::size_t>(i)];
    v[Beta0 + i] = kBeta[static_cast<std::size_t>(i)];
  }
  v[A0] = q(r.af0, std::ldexp(1.0, -33));
  v[A1] = q(r.af1, std::ldexp(1.0, -50));
  v[A2] = q(r.af2, std::ldexp(1.0, -66));
  v[Aode] = r.iode;
  v[DeltaN] = q(r.deltaN, kPi * std::ldexp(1.0, -43));
  v[Cuc] = q(r.cuc, std::ldexp(1.0, -31));
  v[M0] = q(r.m0, kPi * std::ldexp(1.0, -31));
  v[Cus] = q(r.cus, std::ldexp(1.0, -31));
  v[Ecc] = q(r.e, std::ldexp(1.0, -33));
  v[SqrtA] = q(r.sqrtA, std::ldexp(1.0, -19));
  v[Cic] = q(r.cic, std::ldexp(1.0, -31));
  v[Cis] = q(r.cis, std::ldexp(1.0, -31));
  v[Toe] = q(r.toeSeconds, 8.0);
  v[I0] = q(r.i0, kPi * std::ldexp(1.0, -31));
  v[Crc] = q(r.crc, std::ldexp(1.0, -6));
  v[Crs] = q(r.crs, std::ldexp(1.0, -6));
  v[OmegaDot] = q(r.omegaDot, kPi * std::ldexp(1.0, -43));
  v[Omega0] = q(r.omega0, kPi * std::ldexp(1.0, -31));
  v[Omega] = q(r.omega, kPi * std::ldexp(1.0, -31));
  v[Idot] = q(r.iDot, kPi * std::ldexp(1.0, -43));
  return v;
}

/// Page 1 SOW: the 30-s cycle start before the record's transmission time (BDT).
std::uint32_t cycleStart(const KeplerEphemeris& r) {
  int week = 0;
  double sow = 0.0;
  gpstToBdt(r.ttr, week, sow);
  return static_cast<std::uint32_t>(std::floor(sow / 30.0)) * 30u;
}

std::vector<KeplerEphemeris> geoRecords() {
  std::vector<KeplerEphemeris> out;
  for (const auto& e : readRinexNav((dataDir() / "gnss" / "nagoya_static_2024" / "base.nav.gz").string()).kepler)
    if (isBeiDouGeo(e.sat)) out.push_back(e);
  return out;
}

void expectPrinted(double ours, double ref, const char* field, SatId sat) {
  // RINEX D19.12: 12 significant digits.
  EXPECT_LE(std::fabs(ours - ref), 5e-12 * std::fabs(ref) + 1e-300)
      << field << " of C" << static_cast<int>(sat.prn) << ": ours " << ours << ", RINEX " << ref;
}

/// Every field of a decoded record against a reference (RINEX: 12 significant digits).
void expectSameRecord(const KeplerEphemeris& e, const KeplerEphemeris& ref) {
  EXPECT_EQ(e.sat, ref.sat);
  EXPECT_EQ(e.message, NavMessage::BeiDouD2);
  EXPECT_EQ(e.toc, ref.toc);
  EXPECT_EQ(e.toe, ref.toe);
  EXPECT_EQ(e.toeSeconds, ref.toeSeconds);
  EXPECT_EQ(e.week, ref.week);
  EXPECT_EQ(e.iode, ref.iode);
  EXPECT_EQ(e.iodc, ref.iodc);
  EXPECT_EQ(e.health, ref.health);
  EXPECT_EQ(e.ura, ref.ura);
  expectPrinted(e.sqrtA, ref.sqrtA, "sqrtA", ref.sat);
  expectPrinted(e.e, ref.e, "e", ref.sat);
  expectPrinted(e.i0, ref.i0, "i0", ref.sat);
  expectPrinted(e.omega0, ref.omega0, "OMEGA0", ref.sat);
  expectPrinted(e.omega, ref.omega, "omega", ref.sat);
  expectPrinted(e.m0, ref.m0, "M0", ref.sat);
  expectPrinted(e.deltaN, ref.deltaN, "Delta n", ref.sat);
  expectPrinted(e.omegaDot, ref.omegaDot, "OMEGA DOT", ref.sat);
  expectPrinted(e.iDot, ref.iDot, "IDOT", ref.sat);
  expectPrinted(e.cuc, ref.cuc, "Cuc", ref.sat);
  expectPrinted(e.cus, ref.cus, "Cus", ref.sat);
  expectPrinted(e.crc, ref.crc, "Crc", ref.sat);
  expectPrinted(e.crs, ref.crs, "Crs", ref.sat);
  expectPrinted(e.cic, ref.cic, "Cic", ref.sat);
  expectPrinted(e.cis, ref.cis, "Cis", ref.sat);
  expectPrinted(e.af0, ref.af0, "a0", ref.sat);
  expectPrinted(e.af1, ref.af1, "a1", ref.sat);
  expectPrinted(e.af2, ref.af2, "a2", ref.sat);
  expectPrinted(e.tgd[0], ref.tgd[0], "TGD1", ref.sat);
  expectPrinted(e.tgd[1], ref.tgd[1], "TGD2", ref.sat);
}

TEST(SfrbxD2, EveryGeoRecordOfARinexFileSurvivesEncodeAndDecode) {
  const std::vector<KeplerEphemeris> records = geoRecords();
  ASSERT_EQ(records.size(), 8u);  // one record each of C01-C05, C59, C60, C62 (measured)
  double worst = 0.0;
  int prns = 0;
  std::array<bool, 64> seen{};
  for (const KeplerEphemeris& r : records) {
    SCOPED_TRACE("C" + std::to_string(r.sat.prn) + " toe " + std::to_string(r.toeSeconds));
    ASSERT_EQ(r.message, NavMessage::BeiDouD2);
    const Values v = broadcastOf(r, worst);
    const std::uint32_t sow1 = cycleStart(r);
    NavigationAssembler a;
    std::vector<KeplerEphemeris> got;
    NavDataUpdate last;
    for (const SfrbxMessage& m : encodeD2(v, r.sat.prn, sow1)) {
      last = a.add(m, GpsTime{});
      got.insert(got.end(), last.kepler.begin(), last.kepler.end());
    }
    ASSERT_EQ(got.size(), 1u);
    const KeplerEphemeris& e = got[0];
    expectSameRecord(e, r);
    EXPECT_EQ(e.ttr, bdtToGpst(r.week, sow1));
    // Page 2: the Klobuchar parameters with the ICD scale factors.
    ASSERT_TRUE(last.ionosphere.beidou.has_value());
    const int ae[4] = {-30, -27, -24, -24}, be[4] = {11, 14, 16, 16};
    for (std::size_t i = 0; i < 4; ++i) {
      EXPECT_EQ(last.ionosphere.beidou->alpha[i], std::ldexp(static_cast<double>(kAlpha[i]), ae[i]));
      EXPECT_EQ(last.ionosphere.beidou->beta[i], std::ldexp(static_cast<double>(kBeta[i]), be[i]));
    }
    EXPECT_EQ(a.counts(System::BeiDou).parityFailures, 0u);
    if (!seen[r.sat.prn]) ++prns;
    seen[r.sat.prn] = true;
  }
  EXPECT_EQ(prns, 8);
  EXPECT_LT(worst, 2e-3);  // the RINEX values are the broadcast integers times the ICD scales
  std::cerr << records.size() << " GEO records of " << prns << " satellites; largest distance of a scaled value "
            << "from an integer " << worst << "\n";
}

TEST(SfrbxD2, OneBitErrorInAnyWordOfAnyPageIsCaught) {
  const KeplerEphemeris r = geoRecords().front();
  double worst = 0.0;
  const std::vector<SfrbxMessage> pages = encodeD2(broadcastOf(r, worst), r.sat.prn, cycleStart(r));
  for (std::size_t page = 0; page < 10; ++page) {
    for (std::size_t word = 0; word < 10; ++word) {
      for (int bit = 0; bit < 30; ++bit) {
        // Word 1 delivers the 15 uncoded bits (preamble, Rev) in bits 29-15: a preamble error is
        // an unknown message, the Rev bits are protected by nothing.
        const bool uncoded = word == 0 && bit >= 15;
        if (uncoded && bit < 19) continue;
        NavigationAssembler a;
        std::size_t records = 0;
        for (std::size_t k = 0; k < 10; ++k) {
          SfrbxMessage m = pages[k];
          if (k == page) m.words[word] ^= 1u << bit;
          records += a.add(m, GpsTime{}).kepler.size();
        }
        const NavigationCounts& c = a.counts(System::BeiDou);
        ASSERT_EQ(uncoded ? c.unknownMessages : c.parityFailures, 1u) << "page " << page + 1 << " word " << word << " bit " << bit;
        // Page 2 (ionosphere) is not needed for the ephemeris.
        ASSERT_EQ(records, page == 1 ? 1u : 0u) << "page " << page + 1;
      }
    }
  }
}

TEST(SfrbxD2, PagesOfTwoCyclesOrBadPageNumbersGiveNoRecord) {
  const std::vector<KeplerEphemeris> records = geoRecords();
  const KeplerEphemeris& r = records.front();
  double worst = 0.0;
  const Values v = broadcastOf(r, worst);
  const std::uint32_t sow1 = cycleStart(r);
  const std::vector<SfrbxMessage> now = encodeD2(v, r.sat.prn, sow1), next = encodeD2(v, r.sat.prn, sow1 + 30);
  {  // page 6 missing in this cycle: pages 7-10 of it and 1-5 of the next never make a set
    NavigationAssembler a;
    std::size_t got = 0;
    for (std::size_t k = 0; k < 10; ++k)
      if (k != 5) got += a.add(now[k], GpsTime{}).kepler.size();
    for (std::size_t k = 0; k < 5; ++k) got += a.add(next[k], GpsTime{}).kepler.size();
    EXPECT_EQ(got, 0u);
    EXPECT_EQ(a.counts(System::BeiDou).incompleteSets, 1u);
    // The rest of the next cycle completes it: one record.
    for (std::size_t k = 5; k < 10; ++k) got += a.add(next[k], GpsTime{}).kepler.size();
    EXPECT_EQ(got, 1u);
    // The same set again in the cycle after: not emitted twice.
    for (const SfrbxMessage& m : encodeD2(v, r.sat.prn, sow1 + 60)) got += a.add(m, GpsTime{}).kepler.size();
    EXPECT_EQ(got, 1u);
    EXPECT_EQ(a.counts(System::BeiDou).ephemerides, 1u);
  }
  {  // Page numbers 0 and 11-15 (with valid BCH): counted as unknown, never stored.
    NavigationAssembler a;
    for (std::uint32_t pnum : {0u, 11u, 15u}) {
      SfrbxMessage m = now[0];
      // Pnum: bits 42-45 of the subframe (word 2); its parity recomputed.
      Subframe s;
      for (int w = 0; w < 10; ++w) s.set(30 * w, 30, m.words[static_cast<std::size_t>(w)]);
      s.set(42, 4, pnum);
      m.words = s.words();
      EXPECT_TRUE(a.add(m, GpsTime{}).kepler.empty());
    }
    EXPECT_EQ(a.counts(System::BeiDou).unknownMessages, 3u);
    EXPECT_EQ(a.counts(System::BeiDou).parityFailures, 0u);
  }
  {  // A D2 page sent for a non-GEO PRN goes to the D1 decoder, which stores nothing from it.
    NavigationAssembler a;
    std::size_t got = 0;
    for (SfrbxMessage m : now) {
      m.svId = 30;
      got += a.add(m, GpsTime{}).kepler.size();
    }
    EXPECT_EQ(got, 0u);
  }
}

/// An RXM-SFRBX payload (u-blox interface description: 8-byte header, little-endian U4 words).
std::vector<std::uint8_t> payloadOf(const SfrbxMessage& m) {
  std::vector<std::uint8_t> p{m.gnssId, m.svId, m.sigId, 0, static_cast<std::uint8_t>(m.words.size()), 0, 2, 0};
  for (std::uint32_t w : m.words)
    for (int b = 0; b < 4; ++b) p.push_back(static_cast<std::uint8_t>(w >> (8 * b)));
  return p;
}

void writeIfAsked(const char* variable, const std::vector<std::uint8_t>& bytes) {
  if (const char* out = std::getenv(variable)) {
    std::ofstream(out, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  }
}

// tests/data/ubx_synthetic/beidou_d2_nagoya_geo.ubx: the pages of every GEO record as a UBX log of
// RXM-SFRBX frames (written when GVINS_WRITE_D2_UBX names an output file, checked against the
// committed file otherwise). RTKLIB's convbin decodes the same frames independently
// (reference/rtklib-2.4.3/ubx_beidou_d2_nagoya_geo_convbin.nav): every record equal, every field.
TEST(SfrbxD2, PagesLogDecodedAsConvbinDecodesIt) {
  std::vector<std::uint8_t> bytes;
  double worst = 0.0;
  for (const KeplerEphemeris& r : geoRecords()) {
    for (const SfrbxMessage& m : encodeD2(broadcastOf(r, worst), r.sat.prn, cycleStart(r))) {
      const std::vector<std::uint8_t> f = testing::makeFrame(0x02, 0x13, payloadOf(m));
      bytes.insert(bytes.end(), f.begin(), f.end());
    }
  }
  writeIfAsked("GVINS_WRITE_D2_UBX", bytes);
  const auto path = dataDir() / "ubx_synthetic" / "beidou_d2_nagoya_geo.ubx";
  EXPECT_EQ(testing::readBytes(path), bytes);
  const auto log = testing::decodeLog(path);
  const NavData ref =
      readRinexNav((dataDir() / "reference" / "rtklib-2.4.3" / "ubx_beidou_d2_nagoya_geo_convbin.nav").string());
  ASSERT_EQ(ref.kepler.size(), 8u);
  EXPECT_EQ(log.kepler.size(), 8u);
  for (const KeplerEphemeris& r : ref.kepler) {
    SCOPED_TRACE("C" + std::to_string(r.sat.prn));
    const KeplerEphemeris* e = nullptr;
    for (const auto& o : log.kepler)
      if (o.sat == r.sat && o.toe == r.toe) e = &o;
    ASSERT_NE(e, nullptr);
    expectSameRecord(*e, r);
    EXPECT_NEAR(e->ttr - r.ttr, 0.0, 1e-6);  // both: the SOW of page 1
  }
  EXPECT_EQ(log.assembler.counts(System::BeiDou).parityFailures, 0u);
  EXPECT_EQ(log.assembler.counts(System::BeiDou).messages, 80u);
}

// The fuzz seed tests/data/fuzz/sfrbx/geo_beidou_d2.bin: the pages of the first GEO record in the
// fuzz target's input format (mode byte, then 2-byte length + SFRBX payload records). Written when
// GVINS_WRITE_D2_SEED names an output file; checked against the committed file otherwise.
TEST(SfrbxD2, FuzzSeedHoldsTheEncodedPages) {
  const KeplerEphemeris r = geoRecords().front();
  double worst = 0.0;
  std::vector<std::uint8_t> seed{0};  // mode 0: no receive time
  for (const SfrbxMessage& m : encodeD2(broadcastOf(r, worst), r.sat.prn, cycleStart(r))) {
    const std::vector<std::uint8_t> p = payloadOf(m);
    EXPECT_EQ(parseSfrbx(p).words, m.words);
    seed.push_back(static_cast<std::uint8_t>(p.size() & 0xff));
    seed.push_back(static_cast<std::uint8_t>(p.size() >> 8));
    seed.insert(seed.end(), p.begin(), p.end());
  }
  writeIfAsked("GVINS_WRITE_D2_SEED", seed);
  EXPECT_EQ(testing::readBytes(dataDir() / "fuzz" / "sfrbx" / "geo_beidou_d2.bin"), seed);
}

}  // namespace
}  // namespace gvins::ubx
