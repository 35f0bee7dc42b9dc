// Command-line parsing shared by the gvins-<verb> tools: options and operands in any order, an
// option's value in the next argument, values checked by option_values.hpp. Every usage error is
// printed as "TOOL: MESSAGE (see --help)" and ends the program with exit status 2; -h/--help
// prints the usage text and exits with 0.
//
//   CommandLine cl("gvins-spp", kUsage, argc, argv);
//   while (cl.next()) {
//     if (cl.is("-o")) out = cl.value();
//     else if (cl.is("--elmask")) elmask = cl.number(-10.0, 90.0, "deg");
//     else if (cl.is("-q", "--quiet")) quiet = true;
//     else inputs.push_back(cl.operand());  // a usage error for an unknown option
//   }
#pragma once

#include <cstdint>
#include <initializer_list>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "gvins/base/enum_names.hpp"

namespace gvins {

/// Prints "TOOL: MESSAGE (see --help)" to stderr and exits with 2 (usage error).
[[noreturn]] void usageError(std::string_view tool, const std::string& message);

class CommandLine {
 public:
  /// Parses argv[first..argc). `tool` prefixes messages, `usage` is printed for -h/--help.
  CommandLine(std::string tool, std::string_view usage, int argc, char** argv, int first = 1);

  /// Moves to the next argument; false at the end. -h and --help print the usage and exit.
  bool next();
  /// The current argument.
  const std::string& arg() const { return arg_; }
  bool is(std::string_view name) const { return arg_ == name; }
  bool is(std::string_view name, std::string_view alias) const { return arg_ == name || arg_ == alias; }
  /// The current argument starts with '-' and is longer than "-" ("-" alone is stdin/stdout).
  bool isOption() const { return arg_.size() > 1 && arg_[0] == '-'; }
  /// The current argument as an operand: a usage error if it is an (unknown) option.
  const std::string& operand() const;

  /// The value of the current option (the next argument): "OPT needs a value" if there is none.
  std::string value();
  /// The value as a finite number in [lo, hi] (optionNumber; `unit` in the message).
  double number(double lo, double hi, std::string_view unit = "");
  /// The value as a comma-separated list of finite numbers, each in [lo, hi] ("10,20,50").
  std::vector<double> numberList(double lo, double hi, std::string_view unit = "");
  /// The value as an integer in [lo, hi].
  long long integer(long long lo, long long hi);
  /// The value as an unsigned integer in [lo, hi] (seeds: up to 2^64 - 1).
  std::uint64_t unsignedInteger(std::uint64_t lo, std::uint64_t hi);
  /// The value, which must be one of `choices` ("--iono takes off, broadcast or dual-frequency").
  std::string choice(std::initializer_list<std::string_view> choices);
  /// The value as one of the named values of an enumeration (enum_names.hpp).
  template <class E, std::size_t N>
  E choice(const EnumName<E> (&names)[N]) {
    const std::string o = arg_, v = value();
    if (const auto e = enumFromName(names, v)) return *e;
    error(o + " takes " + enumNameList(names) + ", not '" + v + "'");
  }
  /// on/off as a boolean.
  bool onOff();
  /// "X,Y,Z" with components in [lo, hi] (optionVector3).
  Eigen::Vector3d vector3(double lo, double hi, std::string_view unit = "");
  /// An ECEF station position "X,Y,Z" (optionStationEcef) or "LAT,LON,H" (optionStationLlh).
  Eigen::Vector3d stationEcef();
  Eigen::Vector3d stationLlh();

  /// Prints "TOOL: MESSAGE (see --help)" and exits with 2.
  [[noreturn]] void error(const std::string& message) const;
  const std::string& tool() const { return tool_; }

 private:
  std::string tool_;
  std::string_view usage_;
  int argc_;
  char** argv_;
  int i_;
  std::string arg_;
};

}  // namespace gvins
