#include <gtest/gtest.h>

#include "gvins/base/text_fields.hpp"

using namespace gvins;

TEST(TextFields, ColumnsAndNumbers) {
  const TextLocation at{"x.nav", 12};
  const std::string line = "     1.224000000000D+05 3.352761268616E-08 -.5960D-07\r";
  EXPECT_DOUBLE_EQ(parseDouble(column(line, 4, 19), at, "toe"), 122400.0);
  EXPECT_DOUBLE_EQ(parseDouble(column(line, 23, 19), at, "cic"), 3.352761268616e-08);
  EXPECT_DOUBLE_EQ(parseDouble(column(line, 42, 12), at, "x"), -0.596e-7);
  EXPECT_EQ(column(line, 200, 5), "");
  EXPECT_FALSE(parseOptionalDouble(column(line, 200, 5), at, "absent"));
  EXPECT_EQ(parseInt(" -12 ", at, "n"), -12);
  EXPECT_DOUBLE_EQ(parseDoubleOr("   ", 7.0, at, "blank"), 7.0);
}

TEST(TextFields, BadNumbersNameFileLineAndField) {
  const TextLocation at{"broken.nav", 42};
  try {
    parseDouble("1.2.3E5", at, "sqrtA");
    FAIL() << "no exception";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.file(), "broken.nav");
    EXPECT_EQ(e.line(), 42);
    EXPECT_EQ(e.field(), "sqrtA");
    EXPECT_NE(std::string(e.what()).find("broken.nav:42: field 'sqrtA'"), std::string::npos);
  }
  EXPECT_THROW(parseDouble("abc", at, "x"), ParseError);
  EXPECT_THROW(parseDouble("", at, "x"), ParseError);
  EXPECT_THROW(parseDouble("1e999", at, "x"), ParseError);
  EXPECT_THROW(parseDouble("nan", at, "x"), ParseError);
  EXPECT_THROW(parseInt("12a", at, "x"), ParseError);
  EXPECT_THROW(parseInt("-", at, "x"), ParseError);
  EXPECT_THROW(parseInt("99999999999999999999", at, "x"), ParseError);
  EXPECT_THROW(parseDouble(std::string(100, '1'), at, "x"), ParseError);
}
