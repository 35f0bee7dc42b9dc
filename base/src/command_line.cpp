#include "gvins/base/command_line.hpp"

#include <charconv>
#include <cstdio>
#include <cstdlib>

#include "gvins/base/option_values.hpp"

namespace gvins {

CommandLine::CommandLine(std::string tool, std::string_view usage, int argc, char** argv, int first)
    : tool_(std::move(tool)), usage_(usage), argc_(argc), argv_(argv), i_(first - 1) {}

bool CommandLine::next() {
  if (++i_ >= argc_) return false;
  arg_ = argv_[i_];
  if (arg_ == "-h" || arg_ == "--help") {
    std::fwrite(usage_.data(), 1, usage_.size(), stdout);
    std::exit(0);
  }
  return true;
}

const std::string& CommandLine::operand() const {
  if (isOption()) error("unknown option '" + arg_ + "'");
  return arg_;
}

std::string CommandLine::value() {
  if (i_ + 1 >= argc_) error(arg_ + " needs a value");
  return argv_[++i_];
}

void usageError(std::string_view tool, const std::string& message) {
  std::fprintf(stderr, "%.*s: %s (see --help)\n", static_cast<int>(tool.size()), tool.data(), message.c_str());
  std::exit(2);
}

void CommandLine::error(const std::string& message) const { usageError(tool_, message); }

namespace {
template <class F>
auto checked(const CommandLine& cl, F&& parse) {
  try {
    return parse();
  } catch (const OptionError& e) {
    cl.error(e.what());
  }
}
}  // namespace

double CommandLine::number(double lo, double hi, std::string_view unit) {
  const std::string o = arg_, v = value();
  return checked(*this, [&] { return optionNumber(o, v, lo, hi, unit); });
}

std::vector<double> CommandLine::numberList(double lo, double hi, std::string_view unit) {
  const std::string o = arg_, v = value();
  std::vector<double> out;
  std::size_t start = 0;
  for (;;) {
    const std::size_t c = v.find(',', start);
    const std::string tok = v.substr(start, c == std::string::npos ? std::string::npos : c - start);
    out.push_back(checked(*this, [&] { return optionNumber(o, tok, lo, hi, unit); }));
    if (c == std::string::npos) break;
    start = c + 1;
  }
  return out;
}

long long CommandLine::integer(long long lo, long long hi) {
  const std::string o = arg_, v = value();
  long long x = 0;
  const char* first = v.data() + (!v.empty() && v[0] == '+' ? 1 : 0);
  const auto [ptr, ec] = std::from_chars(first, v.data() + v.size(), x);
  if (v.empty() || ec != std::errc() || ptr != v.data() + v.size())
    error(o + ": '" + v + "' is not an integer");
  if (x < lo || x > hi) error(o + ": " + v + " is outside [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return x;
}

std::uint64_t CommandLine::unsignedInteger(std::uint64_t lo, std::uint64_t hi) {
  const std::string o = arg_, v = value();
  std::uint64_t x = 0;
  const auto [ptr, ec] = std::from_chars(v.data(), v.data() + v.size(), x);
  if (v.empty() || ec != std::errc() || ptr != v.data() + v.size())
    error(o + ": '" + v + "' is not a non-negative integer");
  if (x < lo || x > hi) error(o + ": " + v + " is outside [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return x;
}

std::string CommandLine::choice(std::initializer_list<std::string_view> choices) {
  const std::string o = arg_, v = value();
  std::string list;
  std::size_t k = 0;
  for (std::string_view c : choices) {
    if (v == c) return v;
    list += (k == 0 ? "" : (k + 1 == choices.size() ? " or " : ", ")) + std::string(c);
    ++k;
  }
  error(o + " takes " + list + ", not '" + v + "'");
}

bool CommandLine::onOff() { return choice({"on", "off"}) == "on"; }

Eigen::Vector3d CommandLine::vector3(double lo, double hi, std::string_view unit) {
  const std::string o = arg_, v = value();
  return checked(*this, [&] { return optionVector3(o, v, lo, hi, unit); });
}

Eigen::Vector3d CommandLine::stationEcef() {
  const std::string o = arg_, v = value();
  return checked(*this, [&] { return optionStationEcef(o, v); });
}

Eigen::Vector3d CommandLine::stationLlh() {
  const std::string o = arg_, v = value();
  return checked(*this, [&] { return optionStationLlh(o, v); });
}

}  // namespace gvins
