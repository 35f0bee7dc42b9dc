// Malformed navigation files: every error is a ParseError naming the file, the line and the field.
#include <gtest/gtest.h>

#include <string>

#include "gvins/ephemeris/rinex_nav.hpp"

using namespace gvins;

namespace {

const std::string kHeader3 =
    "     3.04           N: GNSS NAV DATA    M: MIXED            RINEX VERSION / TYPE\n"
    "    18                                                      LEAP SECONDS\n"
    "                                                            END OF HEADER\n";

const std::string kGps =
    "G05 2024 06 24 10 00 00-1.774230040610E-04-1.364242052659E-12 0.000000000000E+00\n"
    "     7.200000000000E+01-9.821875000000E+01 4.293035965037E-09 1.714815412488E+00\n"
    "    -5.291774868965E-06 5.927642923780E-03 1.830980181694E-06 5.153635631561E+03\n"
    "     1.224000000000E+05 3.352761268616E-08 2.520897825810E+00-5.774199962616E-08\n"
    "     9.719266524177E-01 3.536250000000E+02 1.273307347665E+00-8.275344701323E-09\n"
    "    -2.610823036973E-10 1.000000000000E+00 2.320000000000E+03 0.000000000000E+00\n"
    "     2.000000000000E+00 0.000000000000E+00-1.071020960808E-08 7.200000000000E+01\n"
    "     1.152180000000E+05 4.000000000000E+00\n";

const std::string kGlo =
    "R01 2024 06 24 08 15 00 8.934084326029E-05 9.094947017729E-13 1.152000000000E+05\n"
    "    -1.373688769531E+04-1.554378509521E+00 9.313225746155E-10 0.000000000000E+00\n"
    "    -3.309238281250E+03-2.458472251892E+00 1.862645149231E-09 1.000000000000E+00\n"
    "     2.124241259766E+04-1.386628150940E+00-1.862645149231E-09 0.000000000000E+00\n";

struct Expected {
  std::int64_t line;
  std::string field;
};

void expectError(const std::string& text, const Expected& want, const std::string& reasonPart = "") {
  try {
    parseRinexNav(text, "bad.nav");
    ADD_FAILURE() << "no error for input:\n" << text;
  } catch (const ParseError& e) {
    EXPECT_EQ(e.file(), "bad.nav");
    EXPECT_EQ(e.line(), want.line) << e.what();
    EXPECT_EQ(e.field(), want.field) << e.what();
    if (!reasonPart.empty()) {
      EXPECT_NE(std::string(e.what()).find(reasonPart), std::string::npos) << e.what();
    }
    // The message names file, line and field.
    EXPECT_NE(std::string(e.what()).find("bad.nav"), std::string::npos);
  }
}

std::string replaceLine(const std::string& text, int lineIndex, const std::string& with) {
  std::string out;
  std::size_t pos = 0;
  for (int i = 0; pos <= text.size(); ++i) {
    const std::size_t end = text.find('\n', pos);
    const std::string line = text.substr(pos, end == std::string::npos ? std::string::npos : end - pos);
    if (end == std::string::npos && line.empty()) break;
    out += (i == lineIndex ? with : line) + "\n";
    if (end == std::string::npos) break;
    pos = end + 1;
  }
  return out;
}

}  // namespace

TEST(RinexNavErrors, BaselineParses) {
  const NavData nav = parseRinexNav(kHeader3 + kGps + kGlo, "good.nav");
  EXPECT_EQ(nav.kepler.size(), 1u);
  EXPECT_EQ(nav.glonass.size(), 1u);
}

TEST(RinexNavErrors, EmptyFile) {
  expectError("", {0, "RINEX VERSION / TYPE"}, "empty file");
}

TEST(RinexNavErrors, NotRinex) {
  expectError("hello world\n", {1, "RINEX VERSION / TYPE"});
}

TEST(RinexNavErrors, UnknownVersions) {
  expectError("     5.01           N: GNSS NAV DATA    M: MIXED            RINEX VERSION / TYPE\n",
              {1, "RINEX version"}, "unsupported RINEX version");
  expectError("     1.00           N: GPS NAV DATA                         RINEX VERSION / TYPE\n",
              {1, "RINEX version"}, "unsupported RINEX version");
  expectError("      x.y           N: GNSS NAV DATA    M: MIXED            RINEX VERSION / TYPE\n",
              {1, "RINEX version"});
}

TEST(RinexNavErrors, ObservationFileIsNotNavigation) {
  expectError("     3.04           OBSERVATION DATA    M: MIXED            RINEX VERSION / TYPE\n",
              {1, "RINEX VERSION / TYPE"}, "not a navigation file");
}

TEST(RinexNavErrors, HeaderWithoutEnd) {
  expectError("     3.04           N: GNSS NAV DATA    M: MIXED            RINEX VERSION / TYPE\n"
              "    18                                                      LEAP SECONDS\n",
              {2, "END OF HEADER"});
}

TEST(RinexNavErrors, BadHeaderNumbers) {
  expectError("     3.04           N: GNSS NAV DATA    M: MIXED            RINEX VERSION / TYPE\n"
              "GPSA   1.8626E-08  2.2x52E-08 -1.1921E-07 -5.9605E-08       IONOSPHERIC CORR\n",
              {2, "IONOSPHERIC CORR"});
  expectError("     3.04           N: GNSS NAV DATA    M: MIXED            RINEX VERSION / TYPE\n"
              "XXXX   1.8626E-08  2.2352E-08 -1.1921E-07 -5.9605E-08       IONOSPHERIC CORR\n",
              {2, "IONOSPHERIC CORR"}, "unknown correction type");
  expectError("     3.04           N: GNSS NAV DATA    M: MIXED            RINEX VERSION / TYPE\n"
              "GPUT -9.3132257462E-10-7.993605777E-15 3194x8 2320          TIME SYSTEM CORR\n",
              {2, "TIME SYSTEM CORR T"});
  expectError("     3.04           N: GNSS NAV DATA    M: MIXED            RINEX VERSION / TYPE\n"
              "   -18                                                      LEAP SECONDS\n",
              {2, "LEAP SECONDS"});
}

TEST(RinexNavErrors, TruncatedRecords) {
  // GPS record cut after its fourth orbit line: the missing line is the one after it.
  std::string cut = kHeader3;
  cut += kGps.substr(0, kGps.find("     9.719266524177E-01"));
  expectError(cut, {8, "BROADCAST ORBIT - 4"}, "truncated");
  // Cut followed by the next record.
  expectError(cut + kGlo, {8, "BROADCAST ORBIT - 4"}, "truncated");
  // GLONASS record with two of three orbit lines at the end of the file.
  std::string glo = kHeader3 + kGlo.substr(0, kGlo.find("     2.124241259766E+04"));
  expectError(glo, {7, "BROADCAST ORBIT - 3"}, "truncated");
}

TEST(RinexNavErrors, BadNumbersNameTheField) {
  const std::string text = kHeader3 + kGps;
  // Line 6 of the file (third orbit line) holds sqrt(A) in its last field.
  expectError(replaceLine(text, 5, "    -5.291774868965E-06 5.927642923780E-03 1.830980181694E-06 5.1536x5631561E+03"),
              {6, "sqrt(A)"}, "not a number");
  expectError(replaceLine(text, 3, "G05 2024 06 24 10 00 00-1.774230040610E-04-1.364242052659E-12 0.0000000000Q0E+00"),
              {4, "SV clock drift rate"});
  expectError(replaceLine(text, 4, "     7.200000000000E+01-9.821875000000E+01 4.29303596.037E-09 1.714815412488E+00"),
              {5, "Delta n"});
  // Huge issue of data.
  expectError(replaceLine(text, 4, "     7.200000000000E+31-9.821875000000E+01 4.293035965037E-09 1.714815412488E+00"),
              {5, "IODE"}, "out of range");
}

TEST(RinexNavErrors, BadEpochAndSatellite) {
  const std::string text = kHeader3 + kGps;
  expectError(replaceLine(text, 3, "G05 2024 13 24 10 00 00-1.774230040610E-04-1.364242052659E-12 0.000000000000E+00"),
              {4, "epoch"}, "invalid date");
  expectError(replaceLine(text, 3, "G05 2024 06 2x 10 00 00-1.774230040610E-04-1.364242052659E-12 0.000000000000E+00"),
              {4, "epoch day"});
  expectError(replaceLine(text, 3, "X05 2024 06 24 10 00 00-1.774230040610E-04-1.364242052659E-12 0.000000000000E+00"),
              {4, "satellite system"});
  expectError(replaceLine(text, 3, "G0x 2024 06 24 10 00 00-1.774230040610E-04-1.364242052659E-12 0.000000000000E+00"),
              {4, "satellite number"});
  // An orbit line where a record must start.
  expectError(kHeader3 + kGps.substr(kGps.find('\n') + 1), {4, "SV / EPOCH / SV CLK"});
}

TEST(RinexNavErrors, GlonassChannelOutOfRange) {
  const std::string text = kHeader3 + kGlo;
  expectError(replaceLine(text, 5, "    -3.309238281250E+03-2.458472251892E+00 1.862645149231E-09 2.500000000000E+01"),
              {6, "frequency number"});
}

TEST(RinexNavErrors, Rinex2Records) {
  const std::string header =
      "     2.10           N: GPS NAV DATA                         RINEX VERSION / TYPE\n"
      "                                                            END OF HEADER\n";
  const std::string rec =
      " 1 05  4  2  2  0  0.0 3.966595977540D-04 1.705302565820D-12 0.000000000000D+00\n"
      "    1.400000000000D+02-5.218750000000D+01 4.026596389650D-09 2.871534990340D+00\n"
      "   -2.676621079440D-06 5.957618006510D-03 4.174187779430D-06 5.153636478420D+03\n"
      "    5.256000000000D+05 1.061707735060D-07-2.493184817740D+00-9.313225746150D-08\n"
      "    9.833919144490D-01 3.093750000000D+02-1.650496813270D+00-7.889971342930D-09\n"
      "   -8.571785642400D-12 1.000000000000D+00 1.316000000000D+03 0.000000000000D+00\n"
      "    1.000000000000D+00 0.000000000000D+00-3.259629011150D-09 3.960000000000D+02\n"
      "    5.195760000000D+05\n";
  EXPECT_EQ(parseRinexNav(header + rec, "ok.n").kepler.size(), 1u);
  expectError(header + replaceLine(rec, 0, " 1 05  4  2 25  0  0.0 3.966595977540D-04 1.705302565820D-12 0.000000000000D+00"),
              {3, "epoch"});
  expectError(header + rec.substr(0, rec.find("    9.833919144490D-01")), {7, "BROADCAST ORBIT - 4"});
  // Clock file type is not a navigation file.
  expectError("     2.10           C                                       RINEX VERSION / TYPE\n",
              {1, "RINEX VERSION / TYPE"});
}

TEST(RinexNavErrors, Rinex4Records) {
  const std::string header =
      "     4.00           NAVIGATION DATA     M                   RINEX VERSION / TYPE\n"
      "    18                                                      LEAP SECONDS\n"
      "                                                            END OF HEADER\n";
  EXPECT_EQ(parseRinexNav(header + "> EPH G05 LNAV\n" + kGps, "ok.rnx").kepler.size(), 1u);
  // '>' line without a message type; EPH line without data; data line without '>' line.
  expectError(header + "> EPH G05\n" + kGps, {4, "record type"});
  expectError(header + "> EPH G05 LNAV\n> EPH G05 LNAV\n" + kGps, {5, "SV / EPOCH / SV CLK"});
  expectError(header + kGps, {4, "record type"});
  // Blank line where the satellite/epoch line belongs (found by fuzzing).
  expectError(header + "> EPH G05 LNAV\n\n" + kGps.substr(kGps.find('\n') + 1), {5, "satellite"});
  // Satellite of the data line differs from the '>' line.
  expectError(header + "> EPH E05 INAV\n" + kGps, {5, "satellite"});
  // Truncated EPH record before the next '>' line.
  expectError(header + "> EPH G05 LNAV\n" + kGps.substr(0, kGps.find("     9.719266524177E-01")) + "> EPH G05 LNAV\n",
              {9, "BROADCAST ORBIT - 4"});
  // STO with a bad number; ION record cut short.
  expectError(header + "> STO G27 LNAV\n    2022 10 07 19 56 48 GPUT\n     3.177840000000e+05-9.31322574615xe-10\n",
              {6, "STO A0"});
  expectError(header + "> ION G17 LNAV\n    2022 10 05 23 33 54 2.514570951462e-08 1.490116119385e-08-1.192092895508e-07\n",
              {6, "ION beta"});
}

TEST(RinexNavErrors, MissingFile) {
  try {
    readRinexNav("/nonexistent/dir/file.nav");
    ADD_FAILURE();
  } catch (const ParseError& e) {
    EXPECT_EQ(e.line(), 0);
    EXPECT_EQ(e.file(), "/nonexistent/dir/file.nav");
  }
}
