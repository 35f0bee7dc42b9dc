// Bias-SINEX reader: a synthetic file (invented satellites, stations and values, laid out as in
// Bias-SINEX 1.00) with GPS code OSBs over two days, an open-ended OSB, a Galileo OSB, a DSB, station
// biases and a phase bias in cycles; time systems; malformed inputs; gzip and file errors; the
// fuzz seeds.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "gvins/ephemeris/bias_sinex.hpp"
#include "parse_error_cases.hpp"

using namespace gvins;

namespace {

// One BIAS/SOLUTION line in the columns of Bias-SINEX 1.00 (trailing blanks removed).
std::string bias(const char* type, const char* svn, const char* prn, const char* station, const char* obs1,
                 const char* obs2, const char* start, const char* end, const char* unit, const char* value,
                 const char* sigma = "") {
  char buf[160];
  std::snprintf(buf, sizeof buf, " %-4s %-4s %-3s %-9s %-4s %-4s %-14s %-14s %-4s %21s %11s", type, svn, prn, station,
                obs1, obs2, start, end, unit, value, sigma);
  std::string s = buf;
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
}

std::string join(const std::vector<std::string>& ls) {
  std::string s;
  for (const auto& l : ls) s += l + "\n";
  return s;
}

constexpr const char* kDay1 = "2024:100:00000";  // 2024-04-09
constexpr const char* kDay2 = "2024:101:00000";
constexpr const char* kDay3 = "2024:102:00000";
constexpr const char* kOpen = "0000:000:00000";

const std::vector<std::string> kFile = {
    "%=BIA 1.00 GVI 2024:102:03600 GVI 2024:100:00000 2024:102:00000 R 00000016",
    "*-------------------------------------------------------------------------------",
    "+FILE/REFERENCE",
    "*INFO_TYPE_________ INFO________________________________________________________",
    " DESCRIPTION        Invented code and phase biases for unit tests",
    " OUTPUT             Observable-specific signal biases",
    "-FILE/REFERENCE",
    "+BIAS/DESCRIPTION",
    "*KEYWORD________________________________ VALUE(S)_______________________________",
    " OBSERVATION_SAMPLING                    30",
    " TIME_SYSTEM                             G",
    " BIAS_MODE                               ABSOLUTE",
    "-BIAS/DESCRIPTION",
    "+BIAS/SOLUTION",
    "*BIAS SVN_ PRN STATION__ OBS1 OBS2 BIAS_START____ BIAS_END______ UNIT __ESTIMATED_VALUE____ _STD_DEV___",
    bias("OSB", "G050", "G05", "", "C1C", "", kDay1, kDay2, "ns", "-3.1234", "0.0050"),  // line 16
    bias("OSB", "G050", "G05", "", "C1W", "", kDay1, kDay2, "ns", "-4.0000", "0.0060"),
    bias("OSB", "G050", "G05", "", "C2W", "", kDay1, kDay2, "ns", "2.5000", "0.0070"),
    bias("OSB", "G050", "G05", "", "C1C", "", kDay2, kDay3, "ns", "-3.2000", "0.0050"),
    bias("OSB", "G050", "G05", "", "C1W", "", kDay2, kDay3, "ns", "-4.1000", "0.0060"),
    bias("OSB", "G050", "G05", "", "C2W", "", kDay2, kDay3, "ns", "2.6000", "0.0070"),
    bias("OSB", "G071", "G12", "", "C1C", "", kDay1, kDay3, "ns", "1.1111"),
    bias("OSB", "G071", "G12", "", "C1W", "", kDay1, kDay3, "ns", "0.5000"),
    bias("OSB", "G071", "G12", "", "C2W", "", kDay1, kOpen, "ns", "-1.7500", "0.0100"),
    bias("OSB", "E201", "E07", "", "C1C", "", kDay1, kDay3, "ns", "0.8000", "0.0030"),
    bias("DSB", "G071", "G12", "", "C1C", "C1W", kDay1, kDay3, "ns", "0.6500", "0.0200"),
    bias("OSB", "G050", "G05", "", "L1C", "", kDay1, kDay3, "cyc", "0.25000", "0.00100"),
    bias("OSB", "", "", "GVI200ABC", "C1C", "", kDay1, kDay3, "ns", "15.0000", "0.5000"),
    bias("OSB", "", "G05", "GVI200ABC", "C1C", "", kDay1, kDay3, "ns", "99.0000"),
    bias("ISB", "", "G", "GVI200ABC", "C1C", "C1C", kDay1, kDay3, "ns", "-1.0000"),
    "-BIAS/SOLUTION",
    "%=ENDBIA",
};

GpsTime gpst(int day, int hour, int minute = 0, double second = 0.0) {
  return GpsTime::fromCalendar({2024, 4, day, hour, minute, second});
}

const SatId kG05(System::Gps, 5), kG12(System::Gps, 12), kE07(System::Galileo, 7);
constexpr ObsCode k1C('1', 'C'), k1W('1', 'W'), k2W('2', 'W'), k5Q('5', 'Q');

}  // namespace

TEST(BiasSinex, ReadsHeaderAndEntries) {
  const BiasSinexData d = parseBiasSinex(join(kFile), "test.bia");
  EXPECT_EQ(d.agency, "GVI");
  EXPECT_EQ(d.timeSystem, "G");
  ASSERT_EQ(d.entries.size(), 15u);
  const BiasEntry& first = d.entries[0];
  EXPECT_EQ(first.type, BiasType::kOsb);
  EXPECT_EQ(first.svn, "G050");
  ASSERT_TRUE(first.satellite);
  EXPECT_EQ(*first.satellite, kG05);
  EXPECT_TRUE(first.station.empty());
  EXPECT_EQ(first.obs1, k1C);
  EXPECT_FALSE(first.phase);
  EXPECT_FALSE(first.obs2);
  EXPECT_EQ(first.start, gpst(9, 0));
  EXPECT_EQ(first.end, gpst(10, 0));
  EXPECT_FALSE(first.openEnd);
  EXPECT_EQ(first.unit, "ns");
  EXPECT_DOUBLE_EQ(first.value, -3.1234e-9);
  EXPECT_DOUBLE_EQ(first.sigma, 0.005e-9);

  EXPECT_TRUE(d.entries[8].openEnd);
  EXPECT_DOUBLE_EQ(d.entries[6].sigma, 0.0);  // no STD_DEV

  const BiasEntry& dsb = d.entries[10];
  EXPECT_EQ(dsb.type, BiasType::kDsb);
  ASSERT_TRUE(dsb.obs2);
  EXPECT_EQ(*dsb.obs2, k1W);

  const BiasEntry& phase = d.entries[11];
  EXPECT_TRUE(phase.phase);
  EXPECT_EQ(phase.obs1, k1C);
  EXPECT_EQ(phase.unit, "cyc");
  EXPECT_DOUBLE_EQ(phase.value, 0.25);
  EXPECT_DOUBLE_EQ(phase.sigma, 0.001);

  const BiasEntry& station = d.entries[12];
  EXPECT_FALSE(station.satellite);
  EXPECT_EQ(station.station, "GVI200ABC");
  EXPECT_DOUBLE_EQ(station.value, 15e-9);
  EXPECT_TRUE(d.entries[13].satellite);
  EXPECT_EQ(d.entries[13].station, "GVI200ABC");
  const BiasEntry& isb = d.entries[14];
  EXPECT_EQ(isb.type, BiasType::kIsb);
  EXPECT_FALSE(isb.satellite);  // a station bias of a whole system ("G")
}

TEST(BiasSinex, CodeOsbSelectsByTime) {
  const BiasSinexData d = parseBiasSinex(join(kFile), "test.bia");
  EXPECT_DOUBLE_EQ(d.codeOsb(kG05, k1C, gpst(9, 12)).value(), -3.1234e-9);
  EXPECT_DOUBLE_EQ(d.codeOsb(kG05, k1C, gpst(9, 0)).value(), -3.1234e-9);  // start included
  EXPECT_DOUBLE_EQ(d.codeOsb(kG05, k1C, gpst(9, 23, 59, 59.5)).value(), -3.1234e-9);
  EXPECT_DOUBLE_EQ(d.codeOsb(kG05, k1C, gpst(10, 0)).value(), -3.2e-9);  // end excluded: day 2
  EXPECT_DOUBLE_EQ(d.codeOsb(kG05, k1W, gpst(10, 6)).value(), -4.1e-9);
  EXPECT_DOUBLE_EQ(d.codeOsb(kG05, k2W, gpst(9, 6)).value(), 2.5e-9);
  EXPECT_FALSE(d.codeOsb(kG05, k1C, gpst(8, 23, 59, 59)));
  EXPECT_FALSE(d.codeOsb(kG05, k1C, gpst(11, 0)));
  // Open end.
  EXPECT_DOUBLE_EQ(d.codeOsb(kG12, k2W, gpst(9, 0)).value(), -1.75e-9);
  EXPECT_DOUBLE_EQ(d.codeOsb(kG12, k2W, GpsTime::fromCalendar({2030, 1, 1, 0, 0, 0.0})).value(), -1.75e-9);
  EXPECT_FALSE(d.codeOsb(kG12, k2W, gpst(8, 12)));
  EXPECT_DOUBLE_EQ(d.codeOsb(kE07, k1C, gpst(10, 12)).value(), 0.8e-9);
  // Not there: other satellite, other code, a system without entries.
  EXPECT_FALSE(d.codeOsb(SatId(System::Gps, 7), k1C, gpst(9, 12)));
  EXPECT_FALSE(d.codeOsb(kE07, k5Q, gpst(9, 12)));
  EXPECT_FALSE(d.codeOsb(SatId(System::Galileo, 5), k1C, gpst(9, 12)));
}

TEST(BiasSinex, CodeOsbIgnoresPhaseAndStationEntriesAndTakesTheLast) {
  std::vector<std::string> ls = kFile;
  ls.insert(ls.end() - 2, bias("OSB", "G050", "G05", "", "C1C", "", "2024:100:43200", kDay2, "ns", "-3.5"));
  const BiasSinexData d = parseBiasSinex(join(ls), "last.bia");
  // The L1C phase bias (cyc) and the station's G05 C1C bias (99 ns) are not satellite code OSBs.
  EXPECT_DOUBLE_EQ(d.codeOsb(kG05, k1C, gpst(9, 6)).value(), -3.1234e-9);
  EXPECT_DOUBLE_EQ(d.codeOsb(kG05, k1C, gpst(9, 12)).value(), -3.5e-9);  // later in the file
  EXPECT_DOUBLE_EQ(d.codeOsb(kG05, k1C, gpst(10, 12)).value(), -3.2e-9);
}

TEST(BiasSinex, CodeDsb) {
  const BiasSinexData d = parseBiasSinex(join(kFile), "test.bia");
  // From the DSB entry in both orders (it wins over 1.1111 - 0.5 ns from the OSBs).
  EXPECT_DOUBLE_EQ(d.codeDsb(kG12, k1C, k1W, gpst(9, 12)).value(), 0.65e-9);
  EXPECT_DOUBLE_EQ(d.codeDsb(kG12, k1W, k1C, gpst(10, 12)).value(), -0.65e-9);
  // From two OSBs, day 1 and day 2.
  EXPECT_NEAR(d.codeDsb(kG05, k1C, k2W, gpst(9, 12)).value(), (-3.1234 - 2.5) * 1e-9, 1e-20);
  EXPECT_NEAR(d.codeDsb(kG05, k1W, k2W, gpst(10, 12)).value(), (-4.1 - 2.6) * 1e-9, 1e-20);
  EXPECT_NEAR(d.codeDsb(kG05, k2W, k1C, gpst(10, 12)).value(), (2.6 + 3.2) * 1e-9, 1e-20);
  EXPECT_NEAR(d.codeDsb(kG12, k1C, k2W, gpst(9, 12)).value(), (1.1111 + 1.75) * 1e-9, 1e-20);
  // Nothing: one OSB missing, outside the validity, unknown satellite.
  EXPECT_FALSE(d.codeDsb(kG05, k1C, k5Q, gpst(9, 12)));
  EXPECT_FALSE(d.codeDsb(kE07, k1C, k5Q, gpst(9, 12)));
  EXPECT_FALSE(d.codeDsb(kG12, k1C, k1W, gpst(11, 0)));
  EXPECT_FALSE(d.codeDsb(kG05, k1C, k2W, gpst(8, 0)));
  EXPECT_FALSE(d.codeDsb(SatId(System::Gps, 7), k1C, k1W, gpst(9, 12)));
}

TEST(BiasSinex, TimeSystemsConvertToGpst) {
  auto file = [](const char* ts, const char* start, const char* end) {
    return join({"%=BIA 1.00 GVI 2024:102:03600 GVI 2024:100:00000 2024:102:00000 R 00000001",
                 "+BIAS/DESCRIPTION", std::string(" TIME_SYSTEM                             ") + ts,
                 "-BIAS/DESCRIPTION", "+BIAS/SOLUTION",
                 bias("OSB", "G050", "G05", "", "C1C", "", start, end, "ns", "1.0"), "-BIAS/SOLUTION", "%=ENDBIA"});
  };
  const BiasSinexData utc = parseBiasSinex(file("UTC", kDay1, "2024:100:86400"), "utc.bia");
  EXPECT_EQ(utc.timeSystem, "UTC");
  EXPECT_EQ(utc.entries.at(0).start, gpst(9, 0, 0, 18.0));  // GPST - UTC = 18 s
  EXPECT_EQ(utc.entries.at(0).end, gpst(10, 0, 0, 18.0));   // 86400 s = next day
  EXPECT_EQ(parseBiasSinex(file("C", kDay1, kDay2), "c.bia").entries.at(0).start, gpst(9, 0, 0, 14.0));
  EXPECT_EQ(parseBiasSinex(file("E", kDay1, kDay2), "e.bia").entries.at(0).start, gpst(9, 0));
  EXPECT_EQ(parseBiasSinex(file("G", "2024:100:45296", kDay2), "g.bia").entries.at(0).start, gpst(9, 12, 34, 56.0));
  EXPECT_EQ(parseBiasSinex(file("R", kDay1, kDay2), "r.bia").entries.at(0).start, gpst(8, 21, 0, 18.0));
  // No BIAS/DESCRIPTION: GPST.
  const BiasSinexData none = parseBiasSinex(
      join({"%=BIA 1.00 GVI", "+BIAS/SOLUTION", bias("OSB", "", "G05", "", "C1C", "", kDay1, kOpen, "ns", "1"),
            "-BIAS/SOLUTION", "%=ENDBIA"}),
      "none.bia");
  EXPECT_EQ(none.timeSystem, "G");
  EXPECT_EQ(none.entries.at(0).start, gpst(9, 0));
}

TEST(BiasSinex, ToleratesShiftedValuesSlopesAndCrlf) {
  const std::string text =
      "%=BIA 1.00 GVI 2024:102:03600 GVI 2024:100:00000 2024:102:00000 R 00000003\r\n"
      "+BIAS/SOLUTION\r\n"
      "\r\n"
      " OSB  G050 G05           C1C       2024:100:00000 2024:101:00000 ns    -3.1                  0.02\r\n"
      " OSB  G050 G05           C1W       2024:100:00000 2024:101:00000 ns                      -4         "
      "         0.0001000000000000   0.00000100\r\n"
      " OSB  G050 G05           C2W       2024:100:00000 2024:101:00000 ns  2.5e0 0.1\r\n"
      "-BIAS/SOLUTION\r\n"
      "%=ENDBIA\r\n";
  const BiasSinexData d = parseBiasSinex(text, "tolerant.bia");
  ASSERT_EQ(d.entries.size(), 3u);
  EXPECT_DOUBLE_EQ(d.entries[0].value, -3.1e-9);
  EXPECT_DOUBLE_EQ(d.entries[0].sigma, 0.02e-9);
  EXPECT_DOUBLE_EQ(d.entries[1].value, -4e-9);
  EXPECT_DOUBLE_EQ(d.entries[1].sigma, 0.0);  // the slope columns are not a STD_DEV
  EXPECT_DOUBLE_EQ(d.entries[2].value, 2.5e-9);
  EXPECT_DOUBLE_EQ(d.entries[2].sigma, 0.1e-9);
}

namespace {

// A small valid file for the malformed cases (1-based line numbers in the comments).
const std::vector<std::string> kBase = {
    "%=BIA 1.00 GVI 2024:102:03600 GVI 2024:100:00000 2024:102:00000 R 00000003",  // 1
    "+BIAS/DESCRIPTION",                                                             // 2
    " TIME_SYSTEM                             G",                                    // 3
    "-BIAS/DESCRIPTION",                                                             // 4
    "+BIAS/SOLUTION",                                                                // 5
    bias("OSB", "G050", "G05", "", "C1C", "", kDay1, kDay2, "ns", "-3.1234", "0.0050"),         // 6
    bias("DSB", "G050", "G05", "", "C1C", "C1W", kDay1, kDay2, "ns", "0.8766", "0.0100"),      // 7
    bias("OSB", "G050", "G05", "", "L1C", "", kDay1, kDay2, "cyc", "0.25000", "0.00100"),      // 8
    "-BIAS/SOLUTION",                                                                // 9
    "%=ENDBIA",                                                                      // 10
};

std::string replaced(std::size_t n, const std::string& line) {
  std::vector<std::string> ls = kBase;
  ls.at(n - 1) = line;
  return join(ls);
}
std::string deleted(std::size_t n) {
  std::vector<std::string> ls = kBase;
  ls.erase(ls.begin() + static_cast<long>(n - 1));
  return join(ls);
}
std::string inserted(std::size_t after, const std::vector<std::string>& more) {
  std::vector<std::string> ls = kBase;
  ls.insert(ls.begin() + static_cast<long>(after), more.begin(), more.end());
  return join(ls);
}
std::string firstLines(std::size_t n) {
  return join(std::vector<std::string>(kBase.begin(), kBase.begin() + static_cast<long>(n)));
}
// Line 6 with one field changed.
std::string osb(const char* prn, const char* obs1, const char* start, const char* end, const char* unit,
                const char* value, const char* sigma = "0.0050", const char* type = "OSB", const char* obs2 = "") {
  return replaced(6, bias(type, "G050", prn, "", obs1, obs2, start, end, unit, value, sigma));
}

using gvins::test::BadCase;

}  // namespace

TEST(BiasSinex, BaseOfMalformedCasesParses) {
  const BiasSinexData d = parseBiasSinex(join(kBase), "base.bia");
  ASSERT_EQ(d.entries.size(), 3u);
  EXPECT_DOUBLE_EQ(d.codeDsb(kG05, k1W, k1C, gpst(9, 1)).value(), -0.8766e-9);
}

TEST(BiasSinex, MalformedInputs) {
  const std::string line6 = kBase[5];
  const std::vector<BadCase> cases = {
      {"empty", "", 0, "%=BIA", "empty file"},
      {"not bias-sinex", replaced(1, "%=SNX 2.02 GVI 2024:102:03600"), 1, "%=BIA", "not a Bias-SINEX file"},
      {"version 2", replaced(1, "%=BIA 2.00 GVI 2024:102:03600"), 1, "%=BIA", "unsupported format version"},
      {"version not a number", replaced(1, "%=BIA x.00 GVI"), 1, "%=BIA", "unsupported format version"},
      {"no version", replaced(1, "%=BIA"), 1, "%=BIA", "missing format version"},
      {"unknown bias type", osb("G05", "C1C", kDay1, kDay2, "ns", "1", "", "XSB"), 6, "BIAS", "unknown bias type"},
      {"line not starting with a blank", replaced(6, line6.substr(1)), 6, "BIAS", "starting with a blank"},
      {"PRN out of range", osb("G99", "C1C", kDay1, kDay2, "ns", "1"), 6, "PRN", "bad satellite 'G99'"},
      {"PRN unknown system", osb("X01", "C1C", kDay1, kDay2, "ns", "1"), 6, "PRN", "bad satellite"},
      {"PRN without system", osb("05", "C1C", kDay1, kDay2, "ns", "1"), 6, "PRN", "bad satellite"},
      {"neither PRN nor station", osb("", "C1C", kDay1, kDay2, "ns", "1"), 6, "PRN", "neither PRN nor STATION"},
      {"PRN shifted", replaced(6, line6.substr(0, 11) + " " + line6.substr(11, 3) + line6.substr(15)), 6, "PRN",
       "column 15"},
      {"OBS1 unknown type", osb("G05", "X1C", kDay1, kDay2, "ns", "1"), 6, "OBS1", "bad observable 'X1C'"},
      {"OBS1 bad band", osb("G05", "CXC", kDay1, kDay2, "ns", "1"), 6, "OBS1", "bad observable"},
      {"OBS1 two characters", osb("G05", "C1", kDay1, kDay2, "ns", "1"), 6, "OBS1", "bad observable"},
      {"OBS1 missing", osb("G05", "", kDay1, kDay2, "ns", "1"), 6, "OBS1", "missing observable"},
      {"OBS2 for an OSB", osb("G05", "C1C", kDay1, kDay2, "ns", "1", "", "OSB", "C1W"), 6, "OBS2", "given for an OSB"},
      {"DSB without OBS2", replaced(7, bias("DSB", "G050", "G05", "", "C1C", "", kDay1, kDay2, "ns", "1")), 7, "OBS2",
       "missing observable"},
      {"DSB code and phase", replaced(7, bias("DSB", "G050", "G05", "", "C1C", "L1C", kDay1, kDay2, "ns", "1")), 7,
       "OBS2", "not of the type of OBS1"},
      {"2-digit year", osb("G05", "C1C", "24:100:00000", kDay2, "ns", "1"), 6, "BIAS_START", "not 4 digits"},
      {"2-digit year in the end", osb("G05", "C1C", kDay1, "24:101:00000", "ns", "1"), 6, "BIAS_END", "not 4 digits"},
      {"day of year 367", osb("G05", "C1C", "2024:367:00000", kOpen, "ns", "1"), 6, "BIAS_START", "day of year 367"},
      {"day 366 of 2023", osb("G05", "C1C", "2023:366:00000", kOpen, "ns", "1"), 6, "BIAS_START", "[1, 365]"},
      {"day of year 0", osb("G05", "C1C", "2024:000:00000", kOpen, "ns", "1"), 6, "BIAS_START", "day of year 0"},
      {"second of day 86401", osb("G05", "C1C", "2024:100:86401", kOpen, "ns", "1"), 6, "BIAS_START",
       "second of day"},
      {"year 1900", osb("G05", "C1C", "1900:100:00000", kOpen, "ns", "1"), 6, "BIAS_START", "out of range"},
      {"time not a number", osb("G05", "C1C", "2024:1x0:00000", kOpen, "ns", "1"), 6, "BIAS_START", "bad time"},
      {"time without seconds", osb("G05", "C1C", "2024:100", kOpen, "ns", "1"), 6, "BIAS_START", "bad time"},
      {"time with four parts", osb("G05", "C1C", "2024:100:0:0", kOpen, "ns", "1"), 6, "BIAS_START", "bad time"},
      {"negative time", osb("G05", "C1C", "-2024:100:000", kOpen, "ns", "1"), 6, "BIAS_START", "bad time"},
      {"open start", osb("G05", "C1C", kOpen, kDay2, "ns", "1"), 6, "BIAS_START", "start time 0000:000:00000"},
      {"end before start", osb("G05", "C1C", kDay2, kDay1, "ns", "1"), 6, "BIAS_END", "not after start"},
      {"end equal to start", osb("G05", "C1C", kDay1, kDay1, "ns", "1"), 6, "BIAS_END", "not after start"},
      {"line cut after the start", replaced(6, line6.substr(0, 49)), 6, "BIAS_END", "missing time"},
      {"line cut after the end", replaced(6, line6.substr(0, 64)), 6, "UNIT", "missing unit"},
      {"unit m", osb("G05", "C1C", kDay1, kDay2, "m", "1"), 6, "UNIT", "unknown unit 'm'"},
      {"unit cyc for code", osb("G05", "C1C", kDay1, kDay2, "cyc", "1"), 6, "UNIT", "cyc for the code observable"},
      {"value missing", replaced(6, line6.substr(0, 68)), 6, "ESTIMATED_VALUE", "missing value"},
      {"value not a number", osb("G05", "C1C", kDay1, kDay2, "ns", "-3.1x"), 6, "ESTIMATED_VALUE", "not a number"},
      {"value nan", osb("G05", "C1C", kDay1, kDay2, "ns", "nan"), 6, "ESTIMATED_VALUE", "nan"},
      {"value inf", osb("G05", "C1C", kDay1, kDay2, "ns", "-inf"), 6, "ESTIMATED_VALUE", "inf"},
      {"value overflow", osb("G05", "C1C", kDay1, kDay2, "ns", "1e999"), 6, "ESTIMATED_VALUE", "1e999"},
      {"std dev negative", osb("G05", "C1C", kDay1, kDay2, "ns", "1", "-0.01"), 6, "STD_DEV", "negative"},
      {"std dev not a number", osb("G05", "C1C", kDay1, kDay2, "ns", "1", "0.0x"), 6, "STD_DEV", "not a number"},
      {"too many values", replaced(6, line6 + " 1 2 3"), 6, "ESTIMATED_VALUE", "too many values"},
      {"slope not a number", replaced(6, line6 + "                    abc"), 6, "ESTIMATED_SLOPE", "not a number"},
      {"data line outside a block", inserted(4, {line6}), 5, "BIAS/SOLUTION", "outside a block"},
      {"nested block", inserted(5, {"+FILE/COMMENT"}), 6, "BIAS/SOLUTION", "inside the block opened on line 5"},
      {"%=ENDBIA inside a block", deleted(9), 9, "BIAS/SOLUTION", "missing -BIAS/SOLUTION"},
      {"end of file inside a block", firstLines(8), 8, "BIAS/SOLUTION", "end of file inside the block of line 5"},
      {"%=ENDBIA inside an unknown block", inserted(9, {"+GVI/OTHER", " x"}), 12, "GVI/OTHER", "missing -GVI/OTHER"},
      {"missing %=ENDBIA", firstLines(9), 9, "%=ENDBIA", "missing %=ENDBIA"},
      {"wrong block closed", replaced(9, "-BIAS/DESCRIPTION"), 9, "BIAS/SOLUTION", "closes the block +BIAS/SOLUTION"},
      {"close without open", inserted(9, {"-FILE/COMMENT"}), 10, "FILE/COMMENT", "without a preceding +FILE/COMMENT"},
      {"block without name", inserted(4, {"+"}), 5, "block", "without a block name"},
      {"content after %=ENDBIA", inserted(10, {line6}), 11, "%=ENDBIA", "content after %=ENDBIA"},
      {"second header line", inserted(9, {kBase[0]}), 10, "%=BIA", "unexpected line"},
      {"unknown time system", replaced(3, " TIME_SYSTEM                             X"), 3, "TIME_SYSTEM",
       "unknown time system 'X'"},
      {"time system without value", replaced(3, " TIME_SYSTEM"), 3, "TIME_SYSTEM", "missing value"},
      {"time system changed after bias lines",
       inserted(9, {"+BIAS/DESCRIPTION", " TIME_SYSTEM UTC", "-BIAS/DESCRIPTION"}), 11, "TIME_SYSTEM",
       "after bias lines"},
      {"description line not indented", replaced(3, "TIME_SYSTEM G"), 3, "BIAS/DESCRIPTION", "keyword line"},
      {"line too long", replaced(6, line6 + std::string(600, ' ')), 6, "", "longer than"},
  };
  ASSERT_GE(cases.size(), 20u);
  gvins::test::expectParseErrors(cases, "bad.bia",
                                 [](const std::string& t, const std::string& f) { parseBiasSinex(t, f); });
}

TEST(BiasSinex, ReadsGzipFileAndNamesMissingFiles) {
  const auto dir = std::filesystem::temp_directory_path();
  const gvins::test::PlainAndGzipFiles files("gvins_bias_sinex", ".bia", join(kFile));
  ASSERT_TRUE(files.ok());
  const BiasSinexData a = readBiasSinex(files.plain());
  const BiasSinexData b = readBiasSinex(files.gz());
  EXPECT_EQ(a.entries.size(), 15u);
  ASSERT_EQ(b.entries.size(), a.entries.size());
  EXPECT_DOUBLE_EQ(b.codeOsb(kG05, k1C, gpst(10, 12)).value(), -3.2e-9);
  EXPECT_DOUBLE_EQ(b.codeDsb(kG12, k1W, k1C, gpst(9, 12)).value(), -0.65e-9);

  const std::string missing = (dir / "gvins_bias_sinex_does_not_exist.bia").string();
  try {
    readBiasSinex(missing);
    ADD_FAILURE() << "no error for a missing file";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.file(), missing);
    EXPECT_NE(std::string(e.what()).find(missing), std::string::npos) << e.what();
  }
}

// The fuzz seeds are valid files.
TEST(BiasSinex, FuzzSeedsParse) {
  const std::string dir = std::string(GVINS_TEST_DATA) + "/fuzz/bias_sinex/";
  const BiasSinexData g = readBiasSinex(dir + "valid_gps_galileo.bia");
  EXPECT_EQ(g.agency, "GVI");
  ASSERT_EQ(g.entries.size(), 9u);
  const GpsTime t1 = GpsTime::fromCalendar({2024, 6, 24, 12, 0, 0.0});  // 2024:176
  const GpsTime t2 = GpsTime::fromCalendar({2024, 6, 25, 12, 0, 0.0});
  EXPECT_DOUBLE_EQ(g.codeOsb(SatId(System::Gps, 1), k1C, t1).value(), -2.5e-9);
  EXPECT_DOUBLE_EQ(g.codeOsb(SatId(System::Gps, 1), k1C, t2).value(), -2.6e-9);
  EXPECT_DOUBLE_EQ(g.codeDsb(SatId(System::Gps, 2), k1W, k1C, t2).value(), -0.75e-9);
  EXPECT_DOUBLE_EQ(g.codeOsb(SatId(System::Galileo, 5), k1C, t1).value(), 1e-9);

  const BiasSinexData u = readBiasSinex(dir + "valid_utc_crlf.bia");
  EXPECT_EQ(u.agency, "XYZ");
  EXPECT_EQ(u.timeSystem, "UTC");
  ASSERT_EQ(u.entries.size(), 4u);
  EXPECT_EQ(u.entries[0].start, GpsTime::fromCalendar({2023, 1, 1, 0, 0, 18.0}));
  EXPECT_DOUBLE_EQ(u.entries[0].sigma, 0.01e-9);
  EXPECT_EQ(u.entries[1].end, GpsTime::fromCalendar({2023, 1, 2, 0, 0, 18.0}));
  EXPECT_DOUBLE_EQ(u.entries[2].value, -11.1e-9);
  EXPECT_DOUBLE_EQ(u.entries[2].sigma, 0.2e-9);
  EXPECT_TRUE(u.entries[3].openEnd);

  const BiasSinexData c = readBiasSinex(dir + "valid_beidou_two_blocks.bia");
  EXPECT_EQ(c.timeSystem, "C");
  ASSERT_EQ(c.entries.size(), 5u);
  const SatId c30(System::BeiDou, 30);
  const GpsTime t = GpsTime::fromCalendar({2024, 1, 10, 6, 0, 0.0});
  EXPECT_EQ(c.entries[0].start, GpsTime::fromCalendar({2024, 1, 10, 0, 0, 14.0}));
  EXPECT_DOUBLE_EQ(c.codeDsb(c30, ObsCode('6', 'I'), ObsCode('2', 'I'), t).value(), 5.5e-9);
  EXPECT_DOUBLE_EQ(c.codeOsb(c30, ObsCode('6', 'I'), t).value(), 6.5e-9);
  EXPECT_FALSE(c.codeOsb(c30, ObsCode('2', 'I'), GpsTime::fromCalendar({2024, 1, 10, 0, 0, 13.0})));
}
