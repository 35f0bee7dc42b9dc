// Shared pieces of the parser tests: a table of malformed inputs with the ParseError each must
// give (file, line, field, a piece of the message), and plain/gzip copies of a text for the
// readers that take both.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "gvins/base/parse_error.hpp"

namespace gvins::test {

struct BadCase {
  std::string name;
  std::string text;
  std::int64_t line;
  std::string field;
  std::string reason = {};  ///< a substring of the message (empty: not checked)
};

/// Every case must throw a ParseError naming `file`, the case's line and field (also in the
/// message) and containing its reason; `parse(text, file)` is the parser under test.
template <typename Parse>
void expectParseErrors(const std::vector<BadCase>& cases, const std::string& file, Parse&& parse) {
  for (const BadCase& c : cases) {
    SCOPED_TRACE(c.name);
    try {
      parse(c.text, file);
      ADD_FAILURE() << "no error for " << c.name;
    } catch (const ParseError& e) {
      EXPECT_EQ(e.file(), file);
      EXPECT_EQ(e.line(), c.line) << e.what();
      EXPECT_EQ(e.field(), c.field) << e.what();
      const std::string what = e.what();
      EXPECT_NE(what.find(c.reason), std::string::npos) << what;
      // The message itself names the place: "file:line: field ...".
      EXPECT_NE(what.find(file), std::string::npos) << what;
      if (c.line > 0) {
        EXPECT_NE(what.find(":" + std::to_string(c.line) + ":"), std::string::npos) << what;
      }
      EXPECT_NE(what.find(c.field), std::string::npos) << what;
    }
  }
}

/// `text` written to a temporary file named after `stem` (with `extension`) and a gzip copy of it
/// (the same name + ".gz"); both removed when the object goes.
class PlainAndGzipFiles {
 public:
  PlainAndGzipFiles(const std::string& stem, const std::string& extension, const std::string& text)
      : plain_((std::filesystem::temp_directory_path() / (stem + "_" + std::to_string(::getpid()) + extension))
                   .string()),
        gz_(plain_ + ".gz") {
    std::ofstream(plain_, std::ios::binary) << text;
    ok_ = std::system(("gzip -c '" + plain_ + "' > '" + gz_ + "'").c_str()) == 0;
  }
  ~PlainAndGzipFiles() {
    std::error_code ec;
    std::filesystem::remove(plain_, ec);
    std::filesystem::remove(gz_, ec);
  }
  PlainAndGzipFiles(const PlainAndGzipFiles&) = delete;
  PlainAndGzipFiles& operator=(const PlainAndGzipFiles&) = delete;
  bool ok() const { return ok_; }
  const std::string& plain() const { return plain_; }
  const std::string& gz() const { return gz_; }

 private:
  std::string plain_, gz_;
  bool ok_ = false;
};

}  // namespace gvins::test
