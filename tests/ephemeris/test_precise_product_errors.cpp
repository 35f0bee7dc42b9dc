// Malformed SP3 and RINEX clock files: every error is a ParseError naming the file, the line and
// the field (and none crashes, hangs or allocates according to an absurd header count).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "gvins/ephemeris/rinex_clock.hpp"
#include "gvins/ephemeris/sp3.hpp"
#include "parse_error_cases.hpp"

using namespace gvins;

namespace {

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::size_t pos = 0;
  while (pos < text.size()) {
    const std::size_t end = text.find('\n', pos);
    out.push_back(text.substr(pos, end - pos));
    pos = end == std::string::npos ? text.size() : end + 1;
  }
  return out;
}

std::string join(const std::vector<std::string>& ls) {
  std::string s;
  for (const auto& l : ls) s += l + "\n";
  return s;
}

// Replaces line i (0-based) with `with`; an empty optional-like marker "<del>" deletes it.
std::string edit(const std::string& text, std::size_t i, const std::string& with) {
  auto ls = lines(text);
  if (with == "<del>") {
    ls.erase(ls.begin() + static_cast<long>(i));
  } else {
    ls.at(i) = with;
  }
  return join(ls);
}

const std::string kSp3 = [] {
  std::string h;
  h += "#dP2024  6 24  0  0  0.00000000       2 ORBIT IGb20 FIT  IGS\n";    // 1
  h += "## 2320  86400.00000000   900.00000000 60485 0.0000000000000\n";     // 2
  h += "+    2   G01R02  0  0  0  0  0  0  0  0  0  0  0  0  0  0  0\n";     // 3
  for (int i = 0; i < 4; ++i) h += "+          0  0  0  0  0  0  0  0  0  0  0  0  0  0  0  0  0\n";  // 4-7
  h += "++         2  3  0  0  0  0  0  0  0  0  0  0  0  0  0  0  0\n";    // 8
  for (int i = 0; i < 4; ++i) h += "++         0  0  0  0  0  0  0  0  0  0  0  0  0  0  0  0  0\n";  // 9-12
  h += "%c M  cc GPS ccc cccc cccc cccc cccc ccccc ccccc ccccc ccccc\n";   // 13
  h += "/* comment\n";                                                      // 14
  h += "*  2024  6 24  0  0  0.00000000\n";                                 // 15
  h += "PG01 -11044.805800 -10475.672350  21929.418200    189.163300\n";    // 16
  h += "PR02  12000.000001  13000.000002  14000.000003     12.000000\n";    // 17
  h += "*  2024  6 24  0 15  0.00000000\n";                                 // 18
  h += "PG01 -11260.155700  -8372.384600  22588.022400    189.163700\n";    // 19
  h += "EOF\n";                                                             // 20
  return h;
}();

std::string label(std::string body, const std::string& text) {
  body.resize(60, ' ');
  return body + text;
}

const std::string kClk = join({
    label("     3.00           C                   G", "RINEX VERSION / TYPE"),  // 1
    label("   GPS", "TIME SYSTEM ID"),                                          // 2
    label("     2    AS    AR", "# / TYPES OF DATA"),                           // 3
    label("", "END OF HEADER"),                                                 // 4
    "AS G16  2024 06 24 00 00 30.000000  2   -0.123456789012E-03  0.123456789012E-10",  // 5
    "AR AREQ 2024 06 24 00 00  0.000000  3   -0.123456789012E+00  0.123456789012E+01",  // 6
    "-0.123456789012E+02",                                                              // 7
    "AS G16  2024 06 24 00 01  0.000000  1   -0.123456789012E-03",                      // 8
});

using Case = gvins::test::BadCase;
using gvins::test::expectParseErrors;

}  // namespace

TEST(PreciseProductErrors, BaselinesParse) {
  EXPECT_EQ(parseSp3(kSp3, "good.sp3").epochs.size(), 2u);
  EXPECT_EQ(parseRinexClock(kClk, "good.clk").find(SatId(System::Gps, 16))->size(), 2u);
}

TEST(PreciseProductErrors, Sp3) {
  const std::vector<Case> cases = {
      {"empty", "", 0, "#c/#d line"},
      {"not sp3", "hello\n", 1, "#c/#d line"},
      {"version a", edit(kSp3, 0, "#aP2024  6 24  0  0  0.00000000       2 ORBIT IGb20 FIT  IGS"), 1, "version"},
      {"flag", edit(kSp3, 0, "#dX2024  6 24  0  0  0.00000000       2 ORBIT IGb20 FIT  IGS"), 1,
       "position/velocity flag"},
      {"bad month", edit(kSp3, 0, "#dP2024 13 24  0  0  0.00000000       2 ORBIT IGb20 FIT  IGS"), 1, "first epoch"},
      {"truncated first line", edit(kSp3, 0, "#dP2024  6 24"), 1, "first epoch"},
      {"epoch count text", edit(kSp3, 0, "#dP2024  6 24  0  0  0.00000000      2x ORBIT IGb20 FIT  IGS"), 1,
       "number of epochs"},
      {"absurd epoch count", edit(kSp3, 0, "#dP2024  6 24  0  0  0.00000000 9999999 ORBIT IGb20 FIT  IGS"), 20,
       "number of epochs"},
      {"too few epochs declared", edit(kSp3, 0, "#dP2024  6 24  0  0  0.00000000       1 ORBIT IGb20 FIT  IGS"), 18,
       "number of epochs"},
      {"missing ##", edit(kSp3, 1, "<del>"), 2, "##"},
      {"bad interval", edit(kSp3, 1, "## 2320  86400.00000000  -900.00000000 60485 0.0000000000000"), 2,
       "epoch interval"},
      {"bad sow", edit(kSp3, 1, "## 2320  86400.0000000x   900.00000000 60485 0.0000000000000"), 2,
       "seconds of week"},
      {"sat count", edit(kSp3, 2, "+    3   G01R02  0  0  0  0  0  0  0  0  0  0  0  0  0  0  0"), 8,
       "number of satellites"},
      {"sat count text", edit(kSp3, 2, "+  x2    G01R02"), 3, "number of satellites"},
      {"absurd sat count", edit(kSp3, 2, "+  999   G01R02"), 8, "number of satellites"},
      {"unknown sat in list", edit(kSp3, 2, "+    2   G01X02  0  0  0  0  0  0  0  0  0  0  0  0  0  0  0"), 3,
       "satellite list"},
      {"duplicate sat in list", edit(kSp3, 2, "+    2   G01G01  0  0  0  0  0  0  0  0  0  0  0  0  0  0  0"), 3,
       "satellite list"},
      {"missing ++ line", edit(kSp3, 11, "<del>"), 12, "++"},
      {"bad accuracy", edit(kSp3, 7, "++         2  x  0  0  0  0  0  0  0  0  0  0  0  0  0  0  0"), 8,
       "accuracy exponent"},
      {"time system", edit(kSp3, 12, "%c M  cc XYZ ccc cccc cccc cccc cccc ccccc ccccc ccccc ccccc"), 13,
       "time system"},
      {"missing %c", edit(kSp3, 12, "<del>"), 14, "%c"},
      {"junk in header", edit(kSp3, 13, "junk"), 14, "header"},
      {"bad epoch", edit(kSp3, 14, "*  2024  6 24  0  0  x.00000000"), 15, "epoch"},
      {"truncated epoch", edit(kSp3, 14, "*  2024  6 24"), 15, "epoch"},
      {"epoch before first", edit(kSp3, 14, "*  2024  6 23 23 45  0.00000000"), 15, "epoch"},
      {"duplicate epoch", edit(kSp3, 17, "*  2024  6 24  0  0  0.00000000"), 18, "epoch"},
      {"epochs out of order", edit(edit(kSp3, 14, "*  2024  6 24  0 30  0.00000000"), 17, "*  2024  6 24  0 15  0.00000000"),
       18, "epoch"},
      {"unknown satellite", edit(kSp3, 15, "PX01 -11044.805800 -10475.672350  21929.418200    189.163300"), 16,
       "satellite"},
      {"satellite not listed", edit(kSp3, 15, "PE01 -11044.805800 -10475.672350  21929.418200    189.163300"), 16,
       "satellite"},
      {"satellite twice", edit(kSp3, 16, "PG01 -11044.805800 -10475.672350  21929.418200    189.163300"), 17,
       "satellite"},
      {"bad x", edit(kSp3, 15, "PG01 -11044.8x5800 -10475.672350  21929.418200    189.163300"), 16, "x"},
      {"truncated P line", edit(kSp3, 15, "PG01 -11044.805800 -10475.672350"), 16, "z"},
      {"bad clock", edit(kSp3, 15, "PG01 -11044.805800 -10475.672350  21929.418200    1x9.163300"), 16, "clock"},
      {"nan", edit(kSp3, 15, "PG01           nan -10475.672350  21929.418200    189.163300"), 16, "x"},
      {"V in P file", edit(kSp3, 16, "VG01  20298.880364 -18462.044804   1381.387685     -4.534317"), 17, "V record"},
      {"record before epoch", edit(kSp3, 14, "PG01 -11044.805800 -10475.672350  21929.418200    189.163300"), 15,
       "header"},
      {"unknown record", edit(kSp3, 16, "Q junk"), 17, "record type"},
      {"missing EOF", edit(kSp3, 19, "<del>"), 19, "EOF"},
  };
  expectParseErrors(cases, "bad.sp3", [](const std::string& t, const std::string& n) { parseSp3(t, n); });
  // A V record must follow its own P record.
  std::string v = edit(kSp3, 0, "#dV2024  6 24  0  0  0.00000000       2 ORBIT IGb20 FIT  IGS");
  expectParseErrors({{"V of another satellite", edit(v, 16, "VR02  20298.880364 -18462.044804   1381.387685     -4.534317"),
                 17, "V record"}},
               "bad.sp3", [](const std::string& t, const std::string& n) { parseSp3(t, n); });
  // SP3-c needs exactly five '+' lines.
  std::string c = edit(kSp3, 0, "#cP2024  6 24  0  0  0.00000000       2 ORBIT IGb20 FIT  IGS");
  c = edit(c, 6, "<del>");
  c = edit(c, 10, "<del>");
  expectParseErrors({{"sp3-c with 4 + lines", c, 7, "+"}}, "bad.sp3",
               [](const std::string& t, const std::string& n) { parseSp3(t, n); });
}

TEST(PreciseProductErrors, RinexClock) {
  const std::vector<Case> cases = {
      {"empty", "", 0, "RINEX VERSION / TYPE"},
      {"not rinex", "hello\n", 1, "RINEX VERSION / TYPE"},
      {"not a clock file", edit(kClk, 0, label("     3.00           N                   G", "RINEX VERSION / TYPE")), 1,
       "file type"},
      {"bad version", edit(kClk, 0, label("     3.x0           C                   G", "RINEX VERSION / TYPE")), 1,
       "RINEX version"},
      {"version 4", edit(kClk, 0, label("     4.00           C                   G", "RINEX VERSION / TYPE")), 1,
       "RINEX version"},
      {"time system", edit(kClk, 1, label("   XYZ", "TIME SYSTEM ID")), 2, "TIME SYSTEM ID"},
      {"types of data", edit(kClk, 2, label("     2    AS    XX", "# / TYPES OF DATA")), 3, "# / TYPES OF DATA"},
      {"no end of header", join({lines(kClk)[0], lines(kClk)[1]}), 2, "END OF HEADER"},
      {"record type", edit(kClk, 4, "XX G16  2024 06 24 00 00 30.000000  2   -0.123456789012E-03  0.1E-10"), 5,
       "record type"},
      {"unknown satellite", edit(kClk, 4, "AS X16  2024 06 24 00 00 30.000000  2   -0.123456789012E-03  0.1E-10"), 5,
       "satellite"},
      {"bad month", edit(kClk, 4, "AS G16  2024 13 24 00 00 30.000000  2   -0.123456789012E-03  0.1E-10"), 5,
       "epoch month"},
      {"bad second", edit(kClk, 4, "AS G16  2024 06 24 00 00 3x.000000  2   -0.123456789012E-03  0.1E-10"), 5,
       "epoch second"},
      {"truncated record", edit(kClk, 4, "AS G16  2024 06 24 00 00"), 5, "epoch"},
      {"count too large", edit(kClk, 4, "AS G16  2024 06 24 00 00 30.000000 99   -0.123456789012E-03  0.1E-10"), 5,
       "number of data values"},
      {"count vs values", edit(kClk, 4, "AS G16  2024 06 24 00 00 30.000000  2   -0.123456789012E-03"), 5,
       "data values"},
      {"bad bias", edit(kClk, 4, "AS G16  2024 06 24 00 00 30.000000  2   -0.12345678x012E-03  0.1E-10"), 5,
       "clock bias"},
      {"negative sigma", edit(kClk, 4, "AS G16  2024 06 24 00 00 30.000000  2   -0.123456789012E-03 -0.1E-10"), 5,
       "bias sigma"},
      {"missing continuation", edit(kClk, 6, "<del>"), 7, "data values"},
      {"continuation cut at the end", join({lines(kClk)[0], lines(kClk)[3], lines(kClk)[5]}), 3, "data values"},
      {"duplicate record", edit(kClk, 7, "AS G16  2024 06 24 00 00 30.000000  1   -0.123456789012E-03"), 8, "epoch"},
  };
  expectParseErrors(cases, "bad.clk", [](const std::string& t, const std::string& n) { parseRinexClock(t, n); });
  // 3.04 layout: a record written with the old A4 name field.
  const std::string v304 = edit(kClk, 0, label("     3.04           C                   G", "RINEX VERSION / TYPE"));
  expectParseErrors({{"A4 name in a 3.04 file", edit(v304, 4, "AS G16  2024 06 24 00 00 30.000000  1   -0.1E-03"), 5, "name"},
                {"3.04 ok but missing year", edit(v304, 4, "AS G16       "), 5, "epoch"}},
               "bad.clk", [](const std::string& t, const std::string& n) { parseRinexClock(t, n); });
}

// The fuzz seed corpora hold valid_* files that must parse (from disk, through readSp3 /
// readRinexClock) and broken_* files that must fail with a ParseError naming the file.
TEST(PreciseProductErrors, SeedCorporaFromDisk) {
  const std::string dir = std::string(GVINS_TEST_DATA) + "/fuzz/";
  for (const std::string f : {"valid_sp3d_pos", "valid_sp3c_vel", "valid_sp3d_bdt_missing"}) {
    EXPECT_NO_THROW(readSp3(dir + "sp3/" + f)) << f;
  }
  EXPECT_EQ(readSp3(dir + "sp3/valid_sp3c_vel").epochs.size(), 6u);
  for (const std::string f : {"broken_truncated", "broken_epoch_order", "broken_absurd_counts"}) {
    try {
      readSp3(dir + "sp3/" + f);
      ADD_FAILURE() << f;
    } catch (const ParseError& e) {
      EXPECT_NE(std::string(e.what()).find(f), std::string::npos) << e.what();
    }
  }
  for (const std::string f : {"valid_v200", "valid_v300", "valid_v304_utc"}) {
    EXPECT_NO_THROW(readRinexClock(dir + "rinex_clock/" + f)) << f;
  }
  EXPECT_EQ(readRinexClock(dir + "rinex_clock/valid_v300").skippedRecords, 6u);
  for (const std::string f : {"broken_duplicate", "broken_no_end_of_header", "broken_truncated_continuation"}) {
    try {
      readRinexClock(dir + "rinex_clock/" + f);
      ADD_FAILURE() << f;
    } catch (const ParseError& e) {
      EXPECT_NE(std::string(e.what()).find(f), std::string::npos) << e.what();
    }
  }
}
