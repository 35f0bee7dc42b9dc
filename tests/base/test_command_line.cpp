// Command lines of the tools (base/command_line.hpp) and enumeration names (base/enum_names.hpp):
// options in any order, checked values, and usage errors that name the option and end the
// program with exit status 2.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "gvins/base/command_line.hpp"
#include "gvins/base/enum_names.hpp"
#include "gvins/base/yaml_reader.hpp"

using namespace gvins;

namespace {

enum class Colour { Red, Green, Blue };
constexpr EnumName<Colour> kColourNames[] = {{Colour::Red, "red"}, {Colour::Green, "green"}, {Colour::Blue, "blue"}};

/// argv of a command line (the strings outlive the parser).
struct Argv {
  explicit Argv(std::vector<std::string> a) : args(std::move(a)) {
    for (std::string& s : args) ptrs.push_back(s.data());
  }
  int argc() { return static_cast<int>(ptrs.size()); }
  char** argv() { return ptrs.data(); }
  std::vector<std::string> args;
  std::vector<char*> ptrs;
};

struct Parsed {
  double elmask = -1.0;
  long long freq = 0;
  Colour colour = Colour::Red;
  std::vector<double> segments;
  std::vector<std::string> inputs;
  bool quiet = false;
};

Parsed parse(std::vector<std::string> args) {
  args.insert(args.begin(), "tool");
  Argv a(std::move(args));
  Parsed p;
  CommandLine cl("gvins-test", "usage: gvins-test [options] FILE...\n", a.argc(), a.argv());
  while (cl.next()) {
    if (cl.is("--elmask")) p.elmask = cl.number(-10.0, 90.0, "deg");
    else if (cl.is("--freq")) p.freq = cl.integer(1, 3);
    else if (cl.is("--colour")) p.colour = cl.choice(kColourNames);
    else if (cl.is("--segments")) p.segments = cl.numberList(1.0, 1e4, "m");
    else if (cl.is("-q", "--quiet")) p.quiet = true;
    else p.inputs.push_back(cl.operand());
  }
  return p;
}

}  // namespace

TEST(CommandLine, OptionsAndOperandsInAnyOrder) {
  const Parsed p = parse({"a.obs", "--elmask", "15", "-q", "--freq", "2", "b.nav", "--colour", "blue", "--segments",
                          "10,20.5", "-"});
  EXPECT_EQ(p.elmask, 15.0);
  EXPECT_EQ(p.freq, 2);
  EXPECT_EQ(p.colour, Colour::Blue);
  EXPECT_EQ(p.segments, (std::vector<double>{10.0, 20.5}));
  EXPECT_TRUE(p.quiet);
  EXPECT_EQ(p.inputs, (std::vector<std::string>{"a.obs", "b.nav", "-"}));  // "-" is stdin, an operand
}

TEST(CommandLineDeathTest, UsageErrorsNameTheOptionAndExitWith2) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  const auto usage = testing::ExitedWithCode(2);
  EXPECT_EXIT(parse({"a.obs", "--elmask"}), usage, "gvins-test: --elmask needs a value \\(see --help\\)");
  EXPECT_EXIT(parse({"--elmask", "nan"}), usage, "--elmask: 'nan' is not a finite number");
  EXPECT_EXIT(parse({"--elmask", "95"}), usage, "--elmask: 95 is outside \\[-10, 90\\] deg");
  EXPECT_EXIT(parse({"--freq", "2.5"}), usage, "--freq: '2.5' is not an integer");
  EXPECT_EXIT(parse({"--freq", "4"}), usage, "--freq: 4 is outside \\[1, 3\\]");
  EXPECT_EXIT(parse({"--colour", "pink"}), usage, "--colour takes red, green or blue, not 'pink'");
  EXPECT_EXIT(parse({"--segments", "10,0"}), usage, "--segments: 0 is outside \\[1, 10000\\] m");
  EXPECT_EXIT(parse({"--bogus"}), usage, "unknown option '--bogus'");
  EXPECT_EXIT(parse({"a.obs", "--help"}), testing::ExitedWithCode(0), "");
}

TEST(EnumNames, OneTableForNamesParsingAndMessages) {
  EXPECT_STREQ(enumName(kColourNames, Colour::Green), "green");
  EXPECT_EQ(enumFromName(kColourNames, "blue"), Colour::Blue);
  EXPECT_FALSE(enumFromName(kColourNames, "Blue"));
  EXPECT_EQ(enumNameList(kColourNames), "red, green or blue");
  const YamlReader r("c.yaml");
  const YAML::Node root = YamlReader::loadText("colour: green\nbad: pink\n", "c.yaml");
  EXPECT_EQ(r.choice(root["colour"], "colour", kColourNames), Colour::Green);
  try {
    r.choice(root["bad"], "bad", kColourNames);
    ADD_FAILURE() << "pink accepted";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.line(), 2);
    EXPECT_EQ(e.field(), "bad");
    EXPECT_NE(std::string(e.what()).find("'bad' must be red, green or blue, not 'pink'"), std::string::npos) << e.what();
  }
}
