#include <gtest/gtest.h>

#include <zlib.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

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

TEST(LineReader, TruncatedGzipAndDirectoriesAreErrors) {
  // A gzip file cut anywhere - inside the deflate data or only its 8-byte trailer (CRC-32 and
  // length, RFC 1952 section 2.3) - is an error naming the file, not a shorter file (`gzip -t`
  // rejects these too). The complete file reads to the end.
  const auto dir = std::filesystem::temp_directory_path();
  const std::string gz = (dir / "gvins_lr_cut.txt.gz").string();
  std::string content;
  for (int i = 0; i < 5000; ++i) content += "row " + std::to_string(i * 7919 % 10007) + "\n";
  {
    gzFile f = gzopen(gz.c_str(), "wb");
    ASSERT_NE(f, nullptr);
    gzwrite(f, content.data(), static_cast<unsigned>(content.size()));
    gzclose(f);
  }
  const auto full = std::filesystem::file_size(gz);
  auto countLines = [&](const std::string& p) {
    LineReader r(p);
    std::string l;
    int n = 0;
    while (r.next(l)) ++n;
    return n;
  };
  EXPECT_EQ(countLines(gz), 5000);
  for (const std::uintmax_t cut : {std::uintmax_t{1}, std::uintmax_t{4}, std::uintmax_t{8}, full / 2}) {
    std::filesystem::resize_file(gz, full - cut);
    try {
      countLines(gz);
      ADD_FAILURE() << "cut " << cut << " bytes: read without error";
    } catch (const ParseError& e) {
      EXPECT_EQ(e.file(), gz);
      EXPECT_NE(std::string(e.what()).find("truncated gzip"), std::string::npos) << e.what();
    }
  }
  std::remove(gz.c_str());
  try {
    LineReader r(dir.string());
    ADD_FAILURE() << "a directory opened as a file";
  } catch (const ParseError& e) {
    EXPECT_NE(std::string(e.what()).find("is a directory"), std::string::npos) << e.what();
  }
}

TEST(LineReader, ViewsAcrossBufferRefillsWithUnreadEverywhere) {
  // Lines of many lengths (0 to 3000 characters, about 70 of them across the 64 KiB refills), CRLF
  // and LF, no final newline: the string_view interface returns the lines, and unread() after any
  // line (one read across a refill, the last one at the end of the file) gives it back.
  const auto dir = std::filesystem::temp_directory_path();
  const std::string plain = (dir / "gvins_lr_views.txt").string();
  const std::string gz = (dir / "gvins_lr_views.txt.gz").string();
  std::vector<std::string> lines;
  std::string content;
  for (int i = 0; i < 3000; ++i) {
    std::string l = std::to_string(i) + ":" + std::string(static_cast<std::size_t>((i * 7919) % 3000), 'a' + i % 26);
    lines.push_back(l);
    content += l + (i % 3 == 0 ? "\r\n" : "\n");
  }
  lines.push_back("tail");
  content += "tail";
  for (const std::string end : {"", "\n"}) {
    const std::string all = content + end;
    { std::ofstream(plain, std::ios::binary) << all; }
    {
      gzFile f = gzopen(gz.c_str(), "wb");
      ASSERT_NE(f, nullptr);
      gzwrite(f, all.data(), static_cast<unsigned>(all.size()));
      gzclose(f);
    }
    for (const auto& p : {plain, gz}) {
      for (int unreadEvery : {0, 1, 5}) {
        LineReader r(p, 8192);
        std::string_view v;
        std::size_t n = 0;
        while (r.next(v)) {
          ASSERT_LT(n, lines.size());
          ASSERT_EQ(v, lines[n]) << p << " line " << n;
          if (unreadEvery && n % unreadEvery == 0) {
            r.unread();
            std::string again;
            ASSERT_TRUE(r.next(again));
            ASSERT_EQ(again, lines[n]);
            EXPECT_EQ(r.lineNumber(), static_cast<std::int64_t>(n + 1));
          }
          ++n;
        }
        EXPECT_EQ(n, lines.size());
        // At the end the last line can still be pushed back.
        r.unread();
        ASSERT_TRUE(r.next(v));
        EXPECT_EQ(v, "tail");
        EXPECT_FALSE(r.next(v));
      }
    }
  }
  // A line across a refill is checked against the limit as a whole.
  {
    std::string text;
    for (int i = 0; i < 650; ++i) text += std::string(99, 'x') + "\n";  // 65000 bytes
    text += std::string(9000, 'y') + "\n";
    { std::ofstream(plain, std::ios::binary) << text; }
    for (std::size_t limit : {9000u, 8999u}) {
      LineReader r(plain, limit);
      std::string_view v;
      for (int i = 0; i < 650; ++i) ASSERT_TRUE(r.next(v));
      if (limit == 9000u) {
        ASSERT_TRUE(r.next(v));
        EXPECT_EQ(v, std::string(9000, 'y'));
      } else {
        EXPECT_THROW(r.next(v), ParseError);
      }
    }
  }
  std::remove(plain.c_str());
  std::remove(gz.c_str());
}
