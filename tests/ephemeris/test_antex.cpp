// ANTEX reader: a synthetic file (invented antennas and values, laid out as in ANTEX 1.4) with
// satellite antennas of one PRN over two validity periods, multi-frequency blocks, long PCV rows,
// a receiver antenna with azimuth rows and radome lookup; malformed inputs; gzip and file errors.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "gvins/ephemeris/antex.hpp"
#include "parse_error_cases.hpp"

using namespace gvins;

namespace {

// A label record: columns 1-60 body, label from column 61.
std::string rec(std::string body, const std::string& label) {
  body.resize(60, ' ');
  return body + label;
}

// A PCV row: A8 lead ("   NOAZI") or F8.1 azimuth, then F8.2 values.
std::string pcvRow(const std::string& lead, const std::vector<double>& mm) {
  char buf[32];
  std::string s = lead;
  s.resize(8, ' ');
  for (double v : mm) {
    std::snprintf(buf, sizeof buf, "%8.2f", v);
    s += buf;
  }
  return s;
}
std::string noazi(const std::vector<double>& mm) { return pcvRow("   NOAZI", mm); }
std::string azimuthRow(double az, const std::vector<double>& mm) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "%8.1f", az);
  return pcvRow(buf, mm);
}

std::string join(const std::vector<std::string>& ls) {
  std::string s;
  for (const auto& l : ls) s += l + "\n";
  return s;
}

std::vector<double> ramp(int n, double first, double step) {
  std::vector<double> v;
  for (int k = 0; k < n; ++k) v.push_back(first + step * k);
  return v;
}

// Receiver PCV of the synthetic GVI1000.00 antenna: -0.10 mm per 5 deg of zenith, +0.01 mm per
// azimuth step of 10 deg, +0.50 mm on L2.
double receiverPcv(int azIndex, int zenIndex, bool l2) { return -0.10 * zenIndex + 0.01 * azIndex + (l2 ? 0.50 : 0.0); }

std::vector<std::string> receiverBlock(const std::string& code, bool l2, const std::string& neu) {
  std::vector<std::string> ls = {rec("   " + code, "START OF FREQUENCY"), rec(neu, "NORTH / EAST / UP")};
  std::vector<double> no;
  for (int k = 0; k < 19; ++k) no.push_back(-0.10 * k + (l2 ? 0.50 : 0.0));
  ls.push_back(noazi(no));
  for (int i = 0; i <= 36; ++i) {
    std::vector<double> r;
    for (int k = 0; k < 19; ++k) r.push_back(receiverPcv(i, k, l2));
    ls.push_back(azimuthRow(10.0 * i, r));
  }
  ls.push_back(rec("   " + code, "END OF FREQUENCY"));
  return ls;
}

const std::vector<double> kIirmNoazi = {0.00, -0.80, -1.50, -2.10, -2.40, -2.60, -2.40, -1.90, -1.10, 0.10, 1.70};
const std::vector<double> kIiiaG01 = {7.10, 6.30, 4.20, 1.30, -1.60, -4.10, -5.90, -6.80,
                                      -6.70, -5.70, -3.80, -1.20, 2.00, 5.60, 9.40};

const std::string kAtx = [] {
  std::vector<std::string> ls = {
      rec("     1.4            M", "ANTEX VERSION / SYST"),
      rec("A                   GVI_REF_ANT", "PCV TYPE / REFANT"),
      rec("Synthetic ANTEX file for the gvins tests", "COMMENT"),
      rec("all antennas and values are invented", "COMMENT"),
      rec("", "END OF HEADER"),
      // G05, first satellite.
      rec("", "START OF ANTENNA"),
      rec("BLOCK IIR-M         G05                 G050      2009-901A", "TYPE / SERIAL NO"),
      rec("GVINS TEST          ROBOT                    0    01-JAN-24", "METH / BY / # / DATE"),
      rec("     0.0", "DAZI"),
      rec("     0.0  10.0   1.0", "ZEN1 / ZEN2 / DZEN"),
      rec("     2", "# OF FREQUENCIES"),
      rec("  2009     8    17     0     0    0.0000000", "VALID FROM"),
      rec("  2020     1     1     0     0    0.0000000", "VALID UNTIL"),
      rec("   G01", "START OF FREQUENCY"),
      rec("    101.20     -2.50   1023.50", "NORTH / EAST / UP"),
      noazi(kIirmNoazi),
      rec("   G01", "END OF FREQUENCY"),
      rec("   G02", "START OF FREQUENCY"),
      rec("    101.20     -2.50   1023.50", "NORTH / EAST / UP"),
      noazi(kIirmNoazi),
      rec("   G02", "END OF FREQUENCY"),
      rec("", "END OF ANTENNA"),
      // G05, the PRN moved to a new satellite (with an overlap of the validity periods).
      rec("", "START OF ANTENNA"),
      rec("BLOCK IIIA          G05                 G075      2019-902A", "TYPE / SERIAL NO"),
      rec("GVINS TEST          ROBOT                    0    01-JAN-24", "METH / BY / # / DATE"),
      rec("     0.0", "DAZI"),
      rec("     0.0  14.0   1.0", "ZEN1 / ZEN2 / DZEN"),
      rec("     3", "# OF FREQUENCIES"),
      rec("  2019    12    15    12    30   15.5000000", "VALID FROM"),
      rec("IGS20_0001", "SINEX CODE"),
      rec("invented offsets", "COMMENT"),
      rec("   G01", "START OF FREQUENCY"),
      rec("    394.00      3.10   1561.70", "NORTH / EAST / UP"),
      noazi(kIiiaG01),
      rec("   G01", "END OF FREQUENCY"),
      rec("   G01", "START OF FREQ RMS"),
      rec("      1.00      1.00      2.00", "NORTH / EAST / UP"),
      noazi(ramp(15, 0.30, 0.0)),
      rec("   G01", "END OF FREQ RMS"),
      rec("   G02", "START OF FREQUENCY"),
      rec("    394.00      3.10   1561.70", "NORTH / EAST / UP"),
      noazi(kIiiaG01),
      rec("   G02", "END OF FREQUENCY"),
      rec("   G05", "START OF FREQUENCY"),
      rec("    394.00      3.10   1702.25", "NORTH / EAST / UP"),
      noazi(ramp(15, 3.00, -0.25)),
      rec("   G05", "END OF FREQUENCY"),
      rec("", "END OF ANTENNA"),
      // A Galileo satellite: 21-point rows longer than 80 columns.
      rec("", "START OF ANTENNA"),
      rec("GALILEO-2           E11                 E210      2016-903A", "TYPE / SERIAL NO"),
      rec("GVINS TEST          ROBOT                    0    01-JAN-24", "METH / BY / # / DATE"),
      rec("     0.0", "DAZI"),
      rec("     0.0  20.0   1.0", "ZEN1 / ZEN2 / DZEN"),
      rec("     2", "# OF FREQUENCIES"),
      rec("  2016     5    24     0     0    0.0000000", "VALID FROM"),
      rec("   E01", "START OF FREQUENCY"),
      rec("    150.00      0.00    800.00", "NORTH / EAST / UP"),
      noazi(ramp(21, -2.00, 0.20)),
      rec("   E01", "END OF FREQUENCY"),
      rec("   E05", "START OF FREQUENCY"),
      rec("    150.00      0.00    650.00", "NORTH / EAST / UP"),
      noazi(ramp(21, -1.00, 0.10)),
      rec("   E05", "END OF FREQUENCY"),
      rec("", "END OF ANTENNA"),
      // A receiver antenna with azimuth rows (DAZI 10, 0..90 by 5).
      rec("", "START OF ANTENNA"),
      rec("GVI1000.00      NONE", "TYPE / SERIAL NO"),
      rec("GVINS TEST          ROBOT                    3    01-JAN-24", "METH / BY / # / DATE"),
      rec("    10.0", "DAZI"),
      rec("     0.0  90.0   5.0", "ZEN1 / ZEN2 / DZEN"),
      rec("     2", "# OF FREQUENCIES"),
      rec("GVI1000", "SINEX CODE"),
  };
  for (const auto& l : receiverBlock("G01", false, "      0.60     -0.40     66.30")) ls.push_back(l);
  for (const auto& l : receiverBlock("G02", true, "     -0.20      1.10     61.05")) ls.push_back(l);
  ls.push_back(rec("", "END OF ANTENNA"));
  // The same kind of antenna under a radome, without azimuth dependence.
  for (const std::string& l : {rec("", "START OF ANTENNA"), rec("GVI2000.00      GVR1", "TYPE / SERIAL NO"),
                               rec("GVINS TEST          ROBOT                    3    01-JAN-24", "METH / BY / # / DATE"),
                               rec("     0.0", "DAZI"), rec("     0.0  90.0  10.0", "ZEN1 / ZEN2 / DZEN"),
                               rec("     1", "# OF FREQUENCIES"), rec("   G01", "START OF FREQUENCY"),
                               rec("      1.00      2.00     90.00", "NORTH / EAST / UP"),
                               noazi(ramp(10, 0.00, -0.50)), rec("   G01", "END OF FREQUENCY"),
                               rec("", "END OF ANTENNA")}) {
    ls.push_back(l);
  }
  return join(ls);
}();

GpsTime gpst(int y, int mo, int d, int h = 0, int mi = 0, double s = 0.0) {
  return GpsTime::fromCalendar(CalendarTime{y, mo, d, h, mi, s});
}

}  // namespace

TEST(Antex, Header) {
  const AntexData d = parseAntex(kAtx, "test.atx");
  EXPECT_DOUBLE_EQ(d.version, 1.4);
  EXPECT_EQ(d.system, 'M');
  EXPECT_EQ(d.pcvType, 'A');
  EXPECT_EQ(d.referenceAntenna, "GVI_REF_ANT");
  ASSERT_EQ(d.comments.size(), 2u);
  EXPECT_EQ(d.comments[1], "all antennas and values are invented");
  ASSERT_EQ(d.antennas.size(), 5u);
  EXPECT_EQ(d.antennas[0].type, "BLOCK IIR-M");
  EXPECT_EQ(d.antennas[3].type, "GVI1000.00      NONE");
  EXPECT_FALSE(d.antennas[3].isSatellite());
  EXPECT_TRUE(d.antennas[3].serial.empty());
}

TEST(Antex, SatelliteOffsetsAndNadirGrid) {
  const AntexData d = parseAntex(kAtx, "test.atx");
  const AntexAntenna& a = d.antennas[1];
  ASSERT_TRUE(a.isSatellite());
  EXPECT_EQ(*a.satellite, SatId(System::Gps, 5));
  EXPECT_EQ(a.serial, "G05");
  EXPECT_EQ(a.svn, "G075");
  EXPECT_EQ(a.cospar, "2019-902A");
  EXPECT_EQ(a.sinexCode, "IGS20_0001");
  EXPECT_DOUBLE_EQ(a.dazi, 0.0);
  EXPECT_DOUBLE_EQ(a.zen1, 0.0);
  EXPECT_DOUBLE_EQ(a.zen2, 14.0);
  EXPECT_DOUBLE_EQ(a.dzen, 1.0);
  ASSERT_TRUE(a.validFrom);
  EXPECT_EQ(*a.validFrom, gpst(2019, 12, 15, 12, 30, 15.5));
  EXPECT_FALSE(a.validUntil);
  ASSERT_EQ(a.frequencies.size(), 3u);  // the RMS block is not a frequency

  const AntexFrequency* l1 = a.frequency(System::Gps, '1');
  const AntexFrequency* l5 = a.frequency(System::Gps, '5');
  ASSERT_NE(l1, nullptr);
  ASSERT_NE(l5, nullptr);
  ASSERT_NE(a.frequency(System::Gps, '2'), nullptr);
  EXPECT_EQ(a.frequency(System::Gps, '7'), nullptr);
  EXPECT_EQ(a.frequency(System::Galileo, '1'), nullptr);
  EXPECT_EQ(l1->system, System::Gps);
  EXPECT_EQ(l5->band, '5');
  EXPECT_DOUBLE_EQ(l1->offset.x(), 0.394);
  EXPECT_DOUBLE_EQ(l1->offset.y(), 0.0031);
  EXPECT_DOUBLE_EQ(l1->offset.z(), 1.5617);
  EXPECT_DOUBLE_EQ(l5->offset.z(), 1.70225);
  ASSERT_EQ(l1->noAzimuth.size(), 15u);
  EXPECT_TRUE(l1->byAzimuth.empty());
  for (std::size_t k = 0; k < 15; ++k) EXPECT_NEAR(l1->noAzimuth[k], kIiiaG01[k] / 1000.0, 1e-15) << k;
  EXPECT_NEAR(l1->noAzimuth[0], 0.0071, 1e-15);
  EXPECT_NEAR(l1->noAzimuth[14], 0.0094, 1e-15);
  EXPECT_NEAR(l5->noAzimuth[0], 0.003, 1e-15);
  EXPECT_NEAR(l5->noAzimuth[14], -0.0005, 1e-15);
}

TEST(Antex, MillimetresToMetres) {
  const AntexData d = parseAntex(kAtx, "test.atx");
  const AntexFrequency* f = d.antennas[0].frequency(System::Gps, '1');
  ASSERT_NE(f, nullptr);
  EXPECT_DOUBLE_EQ(f->offset.z(), 1.0235);  // 1023.50 mm
  EXPECT_DOUBLE_EQ(f->offset.x(), 0.1012);  // 101.20 mm
  EXPECT_DOUBLE_EQ(f->offset.y(), -0.0025);
  ASSERT_EQ(f->noAzimuth.size(), 11u);
  EXPECT_DOUBLE_EQ(f->noAzimuth[4], -0.0024);
  EXPECT_DOUBLE_EQ(f->noAzimuth[10], 0.0017);
}

TEST(Antex, SatelliteChosenByValidity) {
  const AntexData d = parseAntex(kAtx, "test.atx");
  const SatId g05(System::Gps, 5);
  EXPECT_EQ(d.satellite(g05, gpst(2008, 1, 1)), nullptr);  // before any VALID FROM
  EXPECT_EQ(d.satellite(g05, gpst(2015, 6, 1)), &d.antennas[0]);
  EXPECT_EQ(d.satellite(g05, gpst(2019, 12, 15, 12, 30, 15.0)), &d.antennas[0]);
  // Both valid in the overlap: the later VALID FROM wins.
  EXPECT_EQ(d.satellite(g05, gpst(2019, 12, 15, 12, 30, 15.5)), &d.antennas[1]);
  EXPECT_EQ(d.satellite(g05, gpst(2019, 12, 20)), &d.antennas[1]);
  EXPECT_EQ(d.satellite(g05, gpst(2030, 1, 1)), &d.antennas[1]);
  EXPECT_TRUE(d.antennas[0].validAt(gpst(2019, 12, 31, 23, 59, 59.9)));
  EXPECT_FALSE(d.antennas[0].validAt(gpst(2020, 1, 1)));  // VALID UNTIL is exclusive
  EXPECT_FALSE(d.antennas[0].validAt(gpst(2009, 8, 16, 23, 59, 59.0)));
  EXPECT_EQ(d.satellite(SatId(System::Gps, 6), gpst(2021, 1, 1)), nullptr);
  const AntexAntenna* e11 = d.satellite(SatId(System::Galileo, 11), gpst(2024, 1, 1));
  ASSERT_NE(e11, nullptr);
  EXPECT_EQ(e11->svn, "E210");
  const AntexFrequency* e5 = e11->frequency(System::Galileo, '5');
  ASSERT_NE(e5, nullptr);
  EXPECT_DOUBLE_EQ(e5->offset.z(), 0.65);
  ASSERT_EQ(e5->noAzimuth.size(), 21u);  // a 176-column row
  EXPECT_NEAR(e5->noAzimuth[20], 0.001, 1e-15);
  // Receiver antennas are not satellites.
  EXPECT_EQ(d.satellite(SatId(System::Gps, 1), gpst(2021, 1, 1)), nullptr);
}

TEST(Antex, ReceiverAzimuthRows) {
  const AntexData d = parseAntex(kAtx, "test.atx");
  const AntexAntenna* r = d.receiver("GVI1000.00      NONE");
  ASSERT_NE(r, nullptr);
  EXPECT_FALSE(r->isSatellite());
  EXPECT_EQ(r->sinexCode, "GVI1000");
  EXPECT_DOUBLE_EQ(r->dazi, 10.0);
  EXPECT_DOUBLE_EQ(r->zen2, 90.0);
  const AntexFrequency* l1 = r->frequency(System::Gps, '1');
  const AntexFrequency* l2 = r->frequency(System::Gps, '2');
  ASSERT_NE(l1, nullptr);
  ASSERT_NE(l2, nullptr);
  EXPECT_DOUBLE_EQ(l1->offset.x(), 0.0006);  // north
  EXPECT_DOUBLE_EQ(l1->offset.y(), -0.0004);  // east
  EXPECT_DOUBLE_EQ(l1->offset.z(), 0.0663);   // up
  EXPECT_DOUBLE_EQ(l2->offset.z(), 0.06105);
  ASSERT_EQ(l1->noAzimuth.size(), 19u);
  ASSERT_EQ(l1->byAzimuth.size(), 37u);  // 0, 10, ..., 360
  for (const auto& row : l1->byAzimuth) EXPECT_EQ(row.size(), 19u);
  EXPECT_NEAR(l1->byAzimuth[3][4], -0.00037, 1e-15);  // azimuth 30, zenith 20: -0.40 + 0.03 mm
  EXPECT_NEAR(l1->byAzimuth[36][18], -0.00144, 1e-15);
  EXPECT_NEAR(l2->byAzimuth[0][0], 0.0005, 1e-15);
  EXPECT_NEAR(l2->noAzimuth[18], -0.0013, 1e-15);
}

TEST(Antex, ReceiverRadomeFallback) {
  const AntexData d = parseAntex(kAtx, "test.atx");
  const AntexAntenna* none = &d.antennas[3];
  const AntexAntenna* gvr1 = &d.antennas[4];
  EXPECT_EQ(d.receiver("GVI1000.00      NONE"), none);
  EXPECT_EQ(d.receiver("GVI1000.00      NONE   "), none);  // trailing blanks ignored
  EXPECT_EQ(d.receiver("GVI1000.00      SCIS"), none);    // unknown radome -> NONE
  EXPECT_EQ(d.receiver("GVI1000.00"), none);              // no radome -> NONE
  EXPECT_EQ(d.receiver("GVI2000.00      GVR1"), gvr1);
  EXPECT_EQ(d.receiver("GVI2000.00      NONE"), nullptr);  // no fallback from NONE to a radome
  EXPECT_EQ(d.receiver("GVI2000.00      XXXX"), nullptr);
  EXPECT_EQ(d.receiver("GVI3000.00      NONE"), nullptr);
  EXPECT_EQ(d.receiver(""), nullptr);
  EXPECT_EQ(d.receiver("BLOCK IIIA"), nullptr);  // satellite antennas are not receivers
}

TEST(Antex, ValuesFillingTheirFieldsAndCrLf) {
  // F8.2 values of 8 characters touch their neighbours: read from the fixed columns.
  std::string text = join({
      rec("     1.4            G", "ANTEX VERSION / SYST"),
      rec("R                   GVI_REF_ANT", "PCV TYPE / REFANT"),
      rec("", "END OF HEADER"),
      rec("", "START OF ANTENNA"),
      rec("GVI9000         NONE", "TYPE / SERIAL NO"),
      rec("     0.0", "DAZI"),
      rec("     0.0  20.0  10.0", "ZEN1 / ZEN2 / DZEN"),
      rec("     1", "# OF FREQUENCIES"),
      rec("   G01", "START OF FREQUENCY"),
      rec("  10000.00 -10000.00    100.00", "NORTH / EAST / UP"),
      "   NOAZI-1000.00   12.34-1000.25",
      rec("   G01", "END OF FREQUENCY"),
      rec("", "END OF ANTENNA"),
  });
  std::string crlf;
  for (char c : text) {
    if (c == '\n') crlf += '\r';
    crlf += c;
  }
  for (const std::string& t : {text, crlf}) {
    const AntexData d = parseAntex(t, "fixed.atx");
    EXPECT_EQ(d.pcvType, 'R');
    EXPECT_EQ(d.system, 'G');
    ASSERT_EQ(d.antennas.size(), 1u);
    const AntexFrequency& f = d.antennas[0].frequencies.at(0);
    EXPECT_DOUBLE_EQ(f.offset.x(), 10.0);
    EXPECT_DOUBLE_EQ(f.offset.y(), -10.0);
    ASSERT_EQ(f.noAzimuth.size(), 3u);
    EXPECT_DOUBLE_EQ(f.noAzimuth[0], -1.0);
    EXPECT_DOUBLE_EQ(f.noAzimuth[1], 0.01234);
    EXPECT_DOUBLE_EQ(f.noAzimuth[2], -1.00025);
  }
  EXPECT_NO_THROW(parseAntex(crlf.substr(0, crlf.find("START OF ANTENNA") - 60), "header-only.atx"));
}

namespace {

// The small file the malformed cases edit (1-based line numbers on the right).
const std::vector<std::string> kBase = {
    rec("     1.4            M", "ANTEX VERSION / SYST"),                                    // 1
    rec("A                   GVI_REF_ANT", "PCV TYPE / REFANT"),                             // 2
    rec("", "END OF HEADER"),                                                                 // 3
    rec("", "START OF ANTENNA"),                                                              // 4
    rec("BLOCK IIF           G08                 G072      2015-904A", "TYPE / SERIAL NO"),  // 5
    rec("GVINS TEST          ROBOT                    0    01-JAN-24", "METH / BY / # / DATE"),  // 6
    rec("     0.0", "DAZI"),                                                                  // 7
    rec("     0.0   4.0   2.0", "ZEN1 / ZEN2 / DZEN"),                                       // 8
    rec("     1", "# OF FREQUENCIES"),                                                        // 9
    rec("  2015    10    30     0     0    0.0000000", "VALID FROM"),                        // 10
    rec("   G01", "START OF FREQUENCY"),                                                      // 11
    rec("    394.00      0.00   1500.00", "NORTH / EAST / UP"),                              // 12
    "   NOAZI    1.00    0.50   -0.25",                                                        // 13
    rec("   G01", "END OF FREQUENCY"),                                                        // 14
    rec("", "END OF ANTENNA"),                                                                // 15
    rec("", "START OF ANTENNA"),                                                              // 16
    rec("GVI500.00       NONE", "TYPE / SERIAL NO"),                                         // 17
    rec("GVINS TEST          ROBOT                    3    01-JAN-24", "METH / BY / # / DATE"),  // 18
    rec("   180.0", "DAZI"),                                                                  // 19
    rec("     0.0  90.0  45.0", "ZEN1 / ZEN2 / DZEN"),                                       // 20
    rec("     1", "# OF FREQUENCIES"),                                                        // 21
    rec("   G01", "START OF FREQUENCY"),                                                      // 22
    rec("      1.00      2.00     60.00", "NORTH / EAST / UP"),                              // 23
    "   NOAZI    0.00   -1.00    2.00",                                                        // 24
    "     0.0    0.00   -1.10    2.10",                                                        // 25
    "   180.0    0.00   -1.20    2.20",                                                        // 26
    "   360.0    0.00   -1.10    2.10",                                                        // 27
    rec("   G01", "END OF FREQUENCY"),                                                        // 28
    rec("", "END OF ANTENNA"),                                                                // 29
};

// Edits of kBase by 1-based line number.
std::string replaced(std::size_t line, const std::string& with) {
  auto ls = kBase;
  ls.at(line - 1) = with;
  return join(ls);
}
std::string deleted(std::size_t line) {
  auto ls = kBase;
  ls.erase(ls.begin() + static_cast<long>(line - 1));
  return join(ls);
}
std::string inserted(std::size_t after, const std::vector<std::string>& more) {
  auto ls = kBase;
  ls.insert(ls.begin() + static_cast<long>(after), more.begin(), more.end());
  return join(ls);
}
std::string substituted(std::string text, const std::string& from, const std::string& to) {
  return text.replace(text.find(from), from.size(), to);
}
std::string firstLines(std::size_t n) { return join(std::vector<std::string>(kBase.begin(), kBase.begin() + static_cast<long>(n))); }

using gvins::test::BadCase;

}  // namespace

TEST(Antex, BaseOfMalformedCasesParses) {
  const AntexData d = parseAntex(join(kBase), "base.atx");
  ASSERT_EQ(d.antennas.size(), 2u);
  EXPECT_EQ(d.antennas[1].frequencies.at(0).byAzimuth.size(), 3u);
  EXPECT_DOUBLE_EQ(d.antennas[1].frequencies.at(0).byAzimuth[1][2], 0.0022);
}

TEST(Antex, MalformedInputs) {
  const std::string freq2 = rec("   G02", "START OF FREQUENCY");
  const std::vector<std::string> g02Block = {freq2, kBase[11], kBase[12], rec("   G02", "END OF FREQUENCY")};
  const std::vector<BadCase> cases = {
      {"empty", "", 0, "ANTEX VERSION / SYST", "empty file"},
      {"not antex", "hello\n", 1, "ANTEX VERSION / SYST", "not an ANTEX file"},
      {"bad version", replaced(1, rec("     x.4            M", "ANTEX VERSION / SYST")), 1, "ANTEX VERSION / SYST",
       "not a number"},
      {"version 3", replaced(1, rec("     3.0            M", "ANTEX VERSION / SYST")), 1, "ANTEX VERSION / SYST",
       "unsupported"},
      {"unknown system", replaced(1, rec("     1.4            X", "ANTEX VERSION / SYST")), 1, "ANTEX VERSION / SYST",
       "unknown satellite system"},
      {"pcv type", replaced(2, rec("X                   GVI_REF_ANT", "PCV TYPE / REFANT")), 2, "PCV TYPE / REFANT",
       "absolute"},
      {"no pcv type", deleted(2), 2, "PCV TYPE / REFANT", "missing"},
      {"no end of header", firstLines(2), 2, "END OF HEADER", "missing"},
      {"antenna in the header", deleted(3), 3, "END OF HEADER", "before"},
      {"record outside an antenna", inserted(15, {rec("a comment", "COMMENT")}), 16, "START OF ANTENNA",
       "outside an antenna"},
      {"junk between antennas", inserted(15, {"junk"}), 16, "START OF ANTENNA", "outside an antenna"},
      {"START OF FREQUENCY outside an antenna", inserted(15, g02Block), 16, "START OF ANTENNA", "outside an antenna"},
      {"nested START OF ANTENNA", deleted(15), 15, "START OF ANTENNA", "missing END OF ANTENNA"},
      {"truncated in the NOAZI row", firstLines(12), 12, "NOAZI", "end of file"},
      {"truncated before END OF ANTENNA", firstLines(14), 14, "END OF ANTENNA", "end of file"},
      {"truncated in the azimuth rows", firstLines(26), 26, "azimuth row", "end of file"},
      {"no TYPE / SERIAL NO", deleted(5), 5, "TYPE / SERIAL NO", "expected"},
      {"empty antenna type", replaced(5, rec("                    G08", "TYPE / SERIAL NO")), 5, "TYPE / SERIAL NO",
       "empty"},
      {"second TYPE / SERIAL NO", inserted(5, {kBase[4]}), 6, "TYPE / SERIAL NO", "duplicate"},
      {"DZEN 0", replaced(8, rec("     0.0   4.0   0.0", "ZEN1 / ZEN2 / DZEN")), 8, "ZEN1 / ZEN2 / DZEN", "positive"},
      {"DZEN negative", replaced(8, rec("     0.0   4.0  -2.0", "ZEN1 / ZEN2 / DZEN")), 8, "ZEN1 / ZEN2 / DZEN",
       "positive"},
      {"ZEN2 < ZEN1", replaced(8, rec("    10.0   4.0   2.0", "ZEN1 / ZEN2 / DZEN")), 8, "ZEN1 / ZEN2 / DZEN",
       "ZEN1 < ZEN2"},
      {"huge grid", replaced(8, rec("     0.0 180.0 0.001", "ZEN1 / ZEN2 / DZEN")), 8, "ZEN1 / ZEN2 / DZEN",
       "at most 1000"},
      {"grid not a multiple of DZEN", replaced(8, rec("     0.0   4.0   1.5", "ZEN1 / ZEN2 / DZEN")), 8,
       "ZEN1 / ZEN2 / DZEN", "not a multiple"},
      {"ZEN with two values", replaced(8, rec("     0.0   4.0", "ZEN1 / ZEN2 / DZEN")), 8, "ZEN1 / ZEN2 / DZEN",
       "expected 3 values"},
      {"DAZI not dividing 360", replaced(19, rec("     7.0", "DAZI")), 19, "DAZI", "does not divide 360"},
      {"DAZI negative", replaced(19, rec("    -5.0", "DAZI")), 19, "DAZI", "out of range"},
      {"DAZI tiny", replaced(19, rec("    0.01", "DAZI")), 19, "DAZI", "below 0.1"},
      {"DAZI nan", replaced(19, rec("     nan", "DAZI")), 19, "DAZI", "not a number"},
      {"NEU inf", replaced(12, rec("    394.00       inf   1500.00", "NORTH / EAST / UP")), 12, "NORTH / EAST / UP",
       "not a number"},
      {"NEU overflow", replaced(12, rec("    394.00    1e999   1500.00", "NORTH / EAST / UP")), 12,
       "NORTH / EAST / UP", "out of range"},
      {"NEU two values", replaced(12, rec("    394.00      0.00", "NORTH / EAST / UP")), 12, "NORTH / EAST / UP",
       "expected 3 values"},
      {"NEU missing", deleted(12), 12, "NORTH / EAST / UP", "expected"},
      {"bad # OF FREQUENCIES", replaced(9, rec("     x", "# OF FREQUENCIES")), 9, "# OF FREQUENCIES",
       "not an integer"},
      {"zero frequencies", replaced(9, rec("     0", "# OF FREQUENCIES")), 9, "# OF FREQUENCIES", "out of range"},
      {"fewer blocks than declared", replaced(9, rec("     2", "# OF FREQUENCIES")), 15, "# OF FREQUENCIES",
       "1 frequency blocks but 2 declared"},
      {"more blocks than declared", inserted(14, g02Block), 15, "# OF FREQUENCIES", "more frequency blocks"},
      {"unknown system letter", replaced(11, rec("   X01", "START OF FREQUENCY")), 11, "START OF FREQUENCY",
       "unknown satellite system"},
      {"bad band", replaced(11, rec("   G0A", "START OF FREQUENCY")), 11, "START OF FREQUENCY",
       "bad frequency number"},
      {"duplicate frequency block",
       substituted(inserted(14, {kBase[10], kBase[11], kBase[12], kBase[13]}), kBase[8],
                   rec("     2", "# OF FREQUENCIES")),
       15, "START OF FREQUENCY", "duplicate frequency block G01"},
      {"END OF FREQUENCY of another code", replaced(14, rec("   G02", "END OF FREQUENCY")), 14, "END OF FREQUENCY",
       "differs"},
      {"END OF FREQUENCY outside a block", inserted(14, {kBase[13]}), 15, "END OF FREQUENCY",
       "outside a frequency block"},
      {"RMS of a missing frequency", inserted(14, {rec("   G02", "START OF FREQ RMS")}), 15, "START OF FREQ RMS",
       "without a preceding frequency block"},
      {"VALID FROM 30 February", replaced(10, rec("  2015     2    30     0     0    0.0000000", "VALID FROM")), 10,
       "VALID FROM", "invalid date"},
      {"VALID FROM month 13", replaced(10, rec("  2015    13     1     0     0    0.0000000", "VALID FROM")), 10,
       "VALID FROM", "invalid date"},
      {"VALID FROM cut", replaced(10, rec("  2015    10    30", "VALID FROM")), 10, "VALID FROM", "expected year"},
      {"VALID UNTIL before FROM", inserted(10, {rec("  2014     1     1     0     0    0.0000000", "VALID UNTIL")}), 11,
       "VALID UNTIL", "not after"},
      {"NOAZI too short", replaced(13, "   NOAZI    1.00    0.50"), 13, "NOAZI", "expected 3 values"},
      {"NOAZI too long", replaced(13, "   NOAZI    1.00    0.50   -0.25    0.00"), 13, "NOAZI", "expected 3 values"},
      {"NOAZI bad number", replaced(13, "   NOAZI    1.00    x.50   -0.25"), 13, "NOAZI", "not a number"},
      {"NOAZI row missing", deleted(13), 13, "NOAZI", "END OF FREQUENCY"},
      {"azimuth row instead of NOAZI", replaced(13, "     0.0    1.00    0.50   -0.25"), 13, "NOAZI",
       "expected the NOAZI row"},
      {"azimuth rows with DAZI 0", inserted(13, {"     0.0    1.00    0.50   -0.25"}), 14, "END OF FREQUENCY",
       "DAZI = 0"},
      {"azimuth row missing", deleted(27), 27, "azimuth row", "after 2 of 3 azimuth rows"},
      {"wrong azimuth", replaced(26, "    90.0    0.00   -1.20    2.20"), 26, "azimuth row", "180 was expected"},
      {"azimuth row too short", replaced(26, "   180.0    0.00   -1.20"), 26, "azimuth row", "expected 3 values"},
      {"unknown label in an antenna", replaced(10, rec("", "FOO BAR")), 10, "antenna record", "unknown record"},
      {"unlabelled line in an antenna", replaced(10, "junk"), 10, "antenna record", "without a label"},
      {"DAZI after the frequencies", inserted(14, {kBase[6]}), 15, "DAZI", "after the frequency blocks"},
      {"missing DAZI", deleted(7), 10, "DAZI", "missing"},
      {"missing ZEN", deleted(8), 10, "ZEN1 / ZEN2 / DZEN", "missing"},
      {"duplicate DAZI", inserted(7, {kBase[6]}), 8, "DAZI", "duplicate"},
  };
  ASSERT_GE(cases.size(), 20u);
  gvins::test::expectParseErrors(cases, "bad.atx", [](const std::string& t, const std::string& f) { parseAntex(t, f); });
}

TEST(Antex, ReadsGzipFileAndNamesMissingFiles) {
  const auto dir = std::filesystem::temp_directory_path();
  const gvins::test::PlainAndGzipFiles files("gvins_antex", ".atx", kAtx);
  ASSERT_TRUE(files.ok());
  const AntexData a = readAntex(files.plain());
  const AntexData b = readAntex(files.gz());
  ASSERT_EQ(b.antennas.size(), 5u);
  EXPECT_EQ(b.antennas.size(), a.antennas.size());
  const AntexAntenna* r = b.receiver("GVI1000.00");
  ASSERT_NE(r, nullptr);
  EXPECT_NEAR(r->frequencies.at(0).byAzimuth.at(3).at(4), -0.00037, 1e-15);

  const std::string missing = (dir / "gvins_antex_does_not_exist.atx").string();
  try {
    readAntex(missing);
    ADD_FAILURE() << "no error for a missing file";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.file(), missing);
    EXPECT_NE(std::string(e.what()).find(missing), std::string::npos) << e.what();
  }
}

// The fuzz seeds are valid files.
TEST(Antex, FuzzSeedsParse) {
  const std::string dir = std::string(GVINS_TEST_DATA) + "/fuzz/antex/";
  EXPECT_EQ(readAntex(dir + "valid_satellites.atx").antennas.size(), 3u);
  const AntexData r = readAntex(dir + "valid_receiver.atx");
  ASSERT_NE(r.receiver("GVI1000.00      NONE"), nullptr);
  EXPECT_EQ(r.receiver("GVI1000.00      NONE")->frequencies.at(1).byAzimuth.size(), 13u);
  const AntexData m = readAntex(dir + "valid_crlf_mixed.atx");
  ASSERT_EQ(m.antennas.size(), 4u);
  EXPECT_NE(m.satellite(SatId(System::BeiDou, 20), GpsTime::fromCalendar({2024, 1, 1, 0, 0, 0.0})), nullptr);
}

// writeAntex: every seed file written and read again gives the same antennas, offsets, grids and
// validity times (to the 0.01 mm of the format).
TEST(Antex, WriterRoundTrip) {
  const std::string dir = std::string(GVINS_TEST_DATA) + "/fuzz/antex/";
  for (const char* name : {"valid_satellites.atx", "valid_receiver.atx", "valid_crlf_mixed.atx"}) {
    const AntexData a = readAntex(dir + name);
    std::ostringstream out;
    writeAntex(out, a);
    const AntexData b = parseAntex(out.str(), std::string("written-") + name);
    ASSERT_EQ(a.antennas.size(), b.antennas.size()) << name;
    EXPECT_EQ(a.system, b.system);
    EXPECT_EQ(a.pcvType, b.pcvType);
    for (std::size_t i = 0; i < a.antennas.size(); ++i) {
      const AntexAntenna &x = a.antennas[i], &y = b.antennas[i];
      EXPECT_EQ(x.type, y.type);
      EXPECT_EQ(x.serial, y.serial);
      EXPECT_EQ(x.satellite, y.satellite);
      EXPECT_EQ(x.svn, y.svn);
      EXPECT_EQ(x.validFrom, y.validFrom) << name << " " << i;
      EXPECT_EQ(x.validUntil, y.validUntil);
      EXPECT_DOUBLE_EQ(x.dazi, y.dazi);
      EXPECT_DOUBLE_EQ(x.dzen, y.dzen);
      ASSERT_EQ(x.frequencies.size(), y.frequencies.size());
      for (std::size_t f = 0; f < x.frequencies.size(); ++f) {
        const AntexFrequency &p = x.frequencies[f], &q = y.frequencies[f];
        EXPECT_EQ(p.system, q.system);
        EXPECT_EQ(p.band, q.band);
        EXPECT_LT((p.offset - q.offset).norm(), 1e-8);
        ASSERT_EQ(p.noAzimuth.size(), q.noAzimuth.size());
        for (std::size_t k = 0; k < p.noAzimuth.size(); ++k) EXPECT_NEAR(p.noAzimuth[k], q.noAzimuth[k], 1e-8);
        ASSERT_EQ(p.byAzimuth.size(), q.byAzimuth.size());
        for (std::size_t r = 0; r < p.byAzimuth.size(); ++r)
          for (std::size_t k = 0; k < p.byAzimuth[r].size(); ++k) EXPECT_NEAR(p.byAzimuth[r][k], q.byAzimuth[r][k], 1e-8);
      }
    }
  }
}
