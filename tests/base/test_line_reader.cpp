#include <gtest/gtest.h>

#include <zlib.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "gvins/base/line_reader.hpp"

using namespace gvins;

TEST(LineReader, MemoryLinesWithCrLfAndNoFinalNewline) {
  LineReader r(std::string_view("a\r\nbb\n\nlast"), "mem");
  std::string l;
  ASSERT_TRUE(r.next(l));
  EXPECT_EQ(l, "a");
  ASSERT_TRUE(r.next(l));
  EXPECT_EQ(l, "bb");
  EXPECT_EQ(r.lineNumber(), 2);
  r.unread();
  ASSERT_TRUE(r.next(l));
  EXPECT_EQ(l, "bb");
  EXPECT_EQ(r.lineNumber(), 2);
  ASSERT_TRUE(r.next(l));
  EXPECT_EQ(l, "");
  ASSERT_TRUE(r.next(l));
  EXPECT_EQ(l, "last");
  EXPECT_FALSE(r.next(l));
}

TEST(LineReader, OverlongLineIsAnErrorWithLineNumber) {
  const std::string text = "ok\n" + std::string(100, 'x') + "\n";
  LineReader r(std::string_view(text), "long.txt", 50);
  std::string l;
  ASSERT_TRUE(r.next(l));
  try {
    r.next(l);
    FAIL();
  } catch (const ParseError& e) {
    EXPECT_EQ(e.line(), 2);
    EXPECT_EQ(e.file(), "long.txt");
  }
}

TEST(LineReader, PlainAndGzipFilesReadTheSame) {
  const auto dir = std::filesystem::temp_directory_path();
  const std::string plain = (dir / "gvins_lr_plain.txt").string();
  const std::string gz = (dir / "gvins_lr.txt.gz").string();
  std::string content;
  for (int i = 0; i < 20000; ++i) content += "line " + std::to_string(i) + "\n";
  { std::ofstream(plain) << content; }
  {
    gzFile f = gzopen(gz.c_str(), "wb");
    ASSERT_NE(f, nullptr);
    gzwrite(f, content.data(), static_cast<unsigned>(content.size()));
    gzclose(f);
  }
  for (const auto& p : {plain, gz}) {
    LineReader r(p);
    std::string l;
    int n = 0;
    while (r.next(l)) {
      ASSERT_EQ(l, "line " + std::to_string(n));
      ++n;
    }
    EXPECT_EQ(n, 20000);
  }
  EXPECT_THROW(LineReader("/nonexistent/file.obs"), ParseError);
  std::remove(plain.c_str());
  std::remove(gz.c_str());
}
