// YamlReader: every rejection is a ParseError naming the file, the 1-based line and the key.
#include "gvins/base/yaml_reader.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

namespace gvins {
namespace {

/// Runs f and returns the ParseError it throws (fails the test if it throws nothing else).
template <class F>
ParseError errorOf(F&& f) {
  try {
    f();
  } catch (const ParseError& e) {
    return e;
  }
  ADD_FAILURE() << "no ParseError";
  return ParseError("", 0, "", "");
}

TEST(YamlReader, ReadsTypedValuesAndRejectsOutOfRangeWithLineAndKey) {
  const YAML::Node root = YamlReader::loadText("a:\n  x: 2.5\n  n: 7\n  b: true\n  s: kinematic\n  v: [1, 2, 3]\n", "t.yaml");
  const YamlReader r("t.yaml");
  EXPECT_DOUBLE_EQ(r.number(root["a"]["x"], "a.x", 0.0, 3.0), 2.5);
  EXPECT_EQ(r.integer(root["a"]["n"], "a.n", 0, 10), 7);
  EXPECT_TRUE(r.boolean(root["a"]["b"], "a.b"));
  EXPECT_EQ(r.choice(root["a"]["s"], "a.s", {"static", "kinematic"}), "kinematic");
  EXPECT_EQ(r.numbers(root["a"]["v"], "a.v", 3, -10, 10), (std::vector<double>{1, 2, 3}));

  const ParseError range = errorOf([&] { r.number(root["a"]["x"], "a.x", 0.0, 1.0); });
  EXPECT_EQ(range.file(), "t.yaml");
  EXPECT_EQ(range.line(), 2);
  EXPECT_EQ(range.field(), "a.x");
  EXPECT_NE(std::string(range.what()).find("outside [0, 1]"), std::string::npos);

  EXPECT_EQ(errorOf([&] { r.integer(root["a"]["s"], "a.s", 0, 1); }).line(), 5);
  EXPECT_EQ(errorOf([&] { r.choice(root["a"]["s"], "a.s", {"static"}); }).field(), "a.s");
  EXPECT_EQ(errorOf([&] { r.numbers(root["a"]["v"], "a.v", 2, -10, 10); }).line(), 6);
  EXPECT_EQ(errorOf([&] { r.numbers(root["a"]["v"], "a.v", 3, 0, 2.5); }).field(), "a.v[2]");
}

TEST(YamlReader, MapRejectsUnknownKeysAndSystemsRejectsUnknownLetters) {
  const YAML::Node root = YamlReader::loadText("top:\n  known: 1\n  typo: 2\nsys: GRX\n", "m.yaml");
  const YamlReader r("m.yaml");
  int seen = 0;
  const ParseError e = errorOf([&] { r.map(root["top"], "top", {"known"}, [&](auto&&...) { ++seen; }); });
  EXPECT_EQ(seen, 1);  // 'known' was handled before 'typo' was refused
  EXPECT_EQ(e.line(), 3);
  EXPECT_EQ(e.field(), "top.typo");
  const ParseError s = errorOf([&] { r.systems(root["sys"], "sys"); });
  EXPECT_EQ(s.line(), 4);
  EXPECT_NE(std::string(s.what()).find("'X'"), std::string::npos);
  const auto g = parseSystemLetters("G, E");
  EXPECT_TRUE(g[systemIndex(System::Gps)]);
  EXPECT_TRUE(g[systemIndex(System::Galileo)]);
  EXPECT_FALSE(g[systemIndex(System::Glonass)]);
}

TEST(YamlReader, SyntaxErrorsAndMissingFilesNameTheFile) {
  const ParseError syntax = errorOf([] { YamlReader::loadText("a: [1, 2\nb: 3\n", "bad.yaml"); });
  EXPECT_EQ(syntax.file(), "bad.yaml");
  EXPECT_GE(syntax.line(), 1);
  const ParseError missing = errorOf([] { YamlReader::loadFile("/nonexistent/dir/x.yaml"); });
  EXPECT_EQ(missing.file(), "/nonexistent/dir/x.yaml");
}

TEST(YamlReader, ConfigFilesMustBeSmallFilesWithKnownSections) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("gvins_yaml_cfg_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  // A folder given as a configuration file is named as such.
  try {
    YamlReader::readFile(dir.string());
    ADD_FAILURE() << "a directory read as a configuration";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.file(), dir.string());
    EXPECT_NE(std::string(e.what()).find("is a directory"), std::string::npos) << e.what();
  }
  // Larger than the limit: rejected before yaml-cpp parses it.
  const fs::path big = dir / "big.yaml";
  {
    std::ofstream f(big);
    f << "spp:\n  list: [";
    for (int i = 0; i < 300000; ++i) f << i << ",";
    f << "0]\n";
  }
  try {
    YamlReader::readFile(big.string());
    ADD_FAILURE() << "a 2 MB configuration accepted";
  } catch (const ParseError& e) {
    EXPECT_NE(std::string(e.what()).find("limit"), std::string::npos) << e.what();
  }
  EXPECT_EQ(YamlReader::readFile(big.string(), 4u << 20).size(), fs::file_size(big));
  // Sections: a misspelled one is named with its line.
  const YamlReader r("c.yaml");
  const YAML::Node good = YamlReader::loadText("spp:\n  a: 1\nrtk:\n  b: 2\n", "c.yaml");
  EXPECT_NO_THROW(r.sections(good, {"spp", "rtk"}));
  const YAML::Node bad = YamlReader::loadText("# comment\nsp:\n  a: 1\n", "c.yaml");
  try {
    r.sections(bad, {"spp", "rtk"});
    ADD_FAILURE() << "section 'sp' accepted";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.line(), 2);
    EXPECT_NE(e.reason().find("unknown section 'sp' (did you mean 'spp'? expected rtk, spp)"), std::string::npos)
        << e.what();
  }
  // A near miss next to a valid section, and a file with only other tools' sections.
  EXPECT_THROW(r.sections(YamlReader::loadText("spp:\n  a: 1\nrkt:\n  b: 2\n", "c.yaml"), {"spp", "rtk"}), ParseError);
  EXPECT_THROW(r.sections(YamlReader::loadText("replay:\n  a: 1\n", "c.yaml"), {"spp", "rtk"}), ParseError);
  // Sections of other tools beside a known one are theirs.
  EXPECT_NO_THROW(r.sections(YamlReader::loadText("rtk:\n  a: 1\nother_tool: [1, 2]\n", "c.yaml"), {"spp", "rtk"}));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace gvins
