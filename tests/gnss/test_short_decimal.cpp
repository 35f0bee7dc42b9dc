// parseShortDecimal (base/text_fields), the conversion shortcut the RINEX navigation and
// observation readers take for the usual number layouts: the same double as strtod, bit for bit,
// on every number of the navigation files in tests/data and on random numbers of that shape.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include "gvins/base/line_reader.hpp"
#include "gvins/base/text_fields.hpp"

using namespace gvins;

namespace {

std::uint64_t bits(double v) {
  std::uint64_t b;
  std::memcpy(&b, &v, sizeof b);
  return b;
}

// strtod of the text with Fortran 'D' exponents read as 'E' (what parseOptionalDouble gives).
double reference(std::string_view t) {
  std::string s(t);
  for (char& c : s) {
    if (c == 'D' || c == 'd') c = 'E';
  }
  return std::strtod(s.c_str(), nullptr);
}

}  // namespace

TEST(ShortDecimal, NavigationFileNumbersAreStrtodValues) {
  const std::string dir = std::string(GVINS_TEST_DATA) + "/gnss/";
  const std::vector<std::string> files = {
      "nagoya_static_2024/base.nav.gz", "kamakura_static_2021/SEPT078M.21P.gz",
      "kamakura_static_2021/30340780.21q.gz", "geonet_0759_3040_2005/30400920.05n.gz",
      "geonet_0759_3040_2005/07590920.05n.gz"};
  long taken = 0, declined = 0;
  for (const auto& f : files) {
    LineReader in(dir + f);
    std::string_view line;
    bool body = false;
    while (in.next(line)) {
      if (!body) {
        body = line.find("END OF HEADER") != std::string_view::npos;
        continue;
      }
      // Data fields are 19 characters wide, starting at column 4 (RINEX 3/4 continuation lines)
      // or 3 (RINEX 2), after the 23 (22) columns of the epoch on a first line.
      for (std::size_t start : {3, 4, 22, 23}) {
        for (std::size_t pos = start; pos < line.size(); pos += 19) {
          const std::string_view t = trim(line.substr(pos, 19));
          if (t.empty()) continue;
          double v = 12345.0;
          if (parseShortDecimal(t, v)) {
            ASSERT_EQ(bits(v), bits(reference(t))) << f << " line " << in.lineNumber() << ": '" << t << "'";
            ++taken;
          } else {
            EXPECT_EQ(v, 12345.0);
            ++declined;
          }
        }
      }
    }
  }
  // Most fields are numbers of the short form (the declined ones are mostly misaligned windows).
  EXPECT_GT(taken, 55000);  // 60252 numbers
  EXPECT_GT(taken, 2 * declined);
}

TEST(ShortDecimal, RandomNumbersAreStrtodValues) {
  std::mt19937_64 rng(20261201);
  long taken = 0;
  for (int n = 0; n < 300000; ++n) {
    std::string s;
    const int sign = static_cast<int>(rng() % 3);
    if (sign == 1) s += '-';
    if (sign == 2) s += '+';
    const int intDigits = static_cast<int>(rng() % 6);
    const int fracDigits = static_cast<int>(rng() % 17);
    for (int i = 0; i < intDigits; ++i) s += static_cast<char>('0' + rng() % 10);
    if (fracDigits > 0 || rng() % 2) {
      s += '.';
      for (int i = 0; i < fracDigits; ++i) s += static_cast<char>('0' + rng() % 10);
    }
    if (rng() % 4) {
      s += "EeDd"[rng() % 4];
      const int e = static_cast<int>(rng() % 61) - 30;
      if (e < 0) s += '-';
      else if (rng() % 2) s += '+';
      s += std::to_string(std::abs(e));
    }
    double v = 0.0;
    const bool digits = intDigits + fracDigits > 0;
    if (parseShortDecimal(s, v)) {
      ASSERT_TRUE(digits) << s;
      ASSERT_EQ(bits(v), bits(reference(s))) << s;
      ++taken;
    }
  }
  EXPECT_GT(taken, 190000);  // 199301 of the 300000
}

TEST(ShortDecimal, EdgesAndDeclinedForms) {
  double v = 0.0;
  ASSERT_TRUE(parseShortDecimal("-0.000000000000D+00", v));
  EXPECT_EQ(bits(v), bits(-0.0));
  ASSERT_TRUE(parseShortDecimal("9007199254740992", v));  // 2^53
  EXPECT_EQ(v, 9007199254740992.0);
  ASSERT_TRUE(parseShortDecimal(".5", v));
  EXPECT_EQ(v, 0.5);
  ASSERT_TRUE(parseShortDecimal("3.", v));
  EXPECT_EQ(v, 3.0);
  ASSERT_TRUE(parseShortDecimal("0.1", v));
  EXPECT_EQ(bits(v), bits(0.1));
  ASSERT_TRUE(parseShortDecimal("-1.862645149231D-09", v));
  EXPECT_EQ(bits(v), bits(-1.862645149231e-09));
  ASSERT_TRUE(parseShortDecimal("0.0E+999", v));
  EXPECT_EQ(v, 0.0);
  v = 7.0;
  for (const char* s : {"", ".", "-", "+-1", "1.2.3", "1,5", "1.0E", "1.0E+", "1.0E+1234", " 1.0", "1.0 ",
                        "1.23-05", "0x10", "inf", "nan", "9007199254740993", "12345678901234567890",
                        "1.0E-40", "1.0E+30"}) {
    EXPECT_FALSE(parseShortDecimal(s, v)) << s;
    EXPECT_EQ(v, 7.0) << s;
  }
}
