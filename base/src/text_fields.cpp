#include "gvins/base/text_fields.hpp"

#include <charconv>
#include <cstdint>
#include <cmath>
#include <cstdlib>

namespace gvins {

std::string_view column(std::string_view line, std::size_t pos, std::size_t len) {
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  if (pos >= line.size()) return {};
  return line.substr(pos, len);
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '\r')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r' || s.back() == '\n')) {
    s.remove_suffix(1);
  }
  return s;
}

std::string_view trimmedColumn(std::string_view line, std::size_t pos, std::size_t len) {
  return trim(column(line, pos, len));
}

void throwParseError(const TextLocation& where, std::string_view field, const std::string& what) {
  throw ParseError(std::string(where.file), where.line, std::string(field), what);
}

bool parseShortDecimal(std::string_view text, double& v) {
  // Exact powers of ten (10^22 is the largest one a double holds exactly).
  static constexpr double kPow10[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                      1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                      1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
  const char* p = text.data();
  const char* const end = p + text.size();
  bool neg = false;
  if (p != end && (*p == '-' || *p == '+')) {
    neg = *p == '-';
    ++p;
  }
  // Digits accumulate into m (it wraps past 19 digits, which are declined below).
  auto isDigit = [](char c) { return static_cast<unsigned>(c - '0') < 10u; };
  std::uint64_t m = 0;
  const char* const int0 = p;
  for (; p != end && isDigit(*p); ++p) m = m * 10 + static_cast<std::uint64_t>(*p - '0');
  const long intDigits = p - int0;
  long fraction = 0;  // digits after the point
  if (p != end && *p == '.') {
    const char* const frac0 = ++p;
    for (; p != end && isDigit(*p); ++p) m = m * 10 + static_cast<std::uint64_t>(*p - '0');
    fraction = p - frac0;
  }
  if (intDigits + fraction == 0 || intDigits + fraction > 19) return false;
  long exp10 = 0;
  if (p != end) {
    if (*p != 'E' && *p != 'e' && *p != 'D' && *p != 'd') return false;
    ++p;
    bool eneg = false;
    if (p != end && (*p == '-' || *p == '+')) {
      eneg = *p == '-';
      ++p;
    }
    const char* const exp0 = p;
    for (; p != end && isDigit(*p) && p - exp0 < 3; ++p) exp10 = exp10 * 10 + (*p - '0');
    if (p == exp0 || p != end) return false;  // no digits, more than 3, or more text
    if (eneg) exp10 = -exp10;
  }
  if (m > (std::uint64_t{1} << 53)) return false;
  const long k = exp10 - fraction;
  double r;
  if (m == 0) {
    r = 0.0;
  } else if (k >= 0 && k <= 22) {
    r = static_cast<double>(m) * kPow10[k];
  } else if (k < 0 && k >= -22) {
    r = static_cast<double>(m) / kPow10[-k];
  } else {
    return false;
  }
  v = neg ? -r : r;
  return true;
}

std::optional<double> parseOptionalDouble(std::string_view text, const TextLocation& where,
                                          std::string_view field) {
  text = trim(text);
  if (text.empty()) return std::nullopt;
  if (double v; text.size() < 64 && parseShortDecimal(text, v)) return v;
  char buf[64];
  if (text.size() >= sizeof buf) throwParseError(where, field, "number too long: '" + std::string(text) + "'");
  for (std::size_t i = 0; i < text.size(); ++i) {
    char c = text[i];
    if (c == 'D' || c == 'd') c = 'E';
    // Only characters that can appear in a decimal floating-point literal.
    if (!((c >= '0' && c <= '9') || c == '.' || c == '+' || c == '-' || c == 'E' || c == 'e')) {
      throwParseError(where, field, "not a number: '" + std::string(text) + "'");
    }
    buf[i] = c;
  }
  buf[text.size()] = '\0';
  const char* const last = buf + text.size();
  // std::from_chars rounds correctly like strtod (same value) and is several times faster; it
  // does not take the leading '+' strtod accepts, so that is skipped here (but not "+-1").
  const char* first = buf;
  if (*first == '+') ++first;
  double v = 0.0;
  const auto [ptr, ec] = std::from_chars(first, last, v);
  if ((ec != std::errc() && ec != std::errc::result_out_of_range) || ptr != last ||
      (first != buf && (*first == '-' || *first == '+'))) {
    throwParseError(where, field, "not a number: '" + std::string(text) + "'");
  }
  // Overflow is an error below; strtod's treatment of underflow (0 or a subnormal) is kept.
  if (ec == std::errc::result_out_of_range) v = std::strtod(buf, nullptr);
  if (!std::isfinite(v)) throwParseError(where, field, "number out of range: '" + std::string(text) + "'");
  return v;
}

double parseDouble(std::string_view text, const TextLocation& where, std::string_view field) {
  const auto v = parseOptionalDouble(text, where, field);
  if (!v) throwParseError(where, field, "missing value");
  return *v;
}

double parseFiniteDouble(std::string_view text, const TextLocation& where, std::string_view field) {
  const double v = parseDouble(text, where, field);
  if (!std::isfinite(v)) throwParseError(where, field, "not a finite number '" + std::string(trim(text)) + "'");
  return v;
}

double parseDoubleOr(std::string_view text, double blankValue, const TextLocation& where,
                     std::string_view field) {
  return parseOptionalDouble(text, where, field).value_or(blankValue);
}

std::optional<long> parseOptionalInt(std::string_view text, const TextLocation& where,
                                     std::string_view field) {
  text = trim(text);
  if (text.empty()) return std::nullopt;
  long v = 0;
  std::size_t i = 0;
  bool neg = false;
  if (text[0] == '-' || text[0] == '+') {
    neg = text[0] == '-';
    i = 1;
  }
  if (i >= text.size()) throwParseError(where, field, "not an integer: '" + std::string(text) + "'");
  for (; i < text.size(); ++i) {
    const char c = text[i];
    if (c < '0' || c > '9') throwParseError(where, field, "not an integer: '" + std::string(text) + "'");
    if (v > 100000000000L) throwParseError(where, field, "integer out of range: '" + std::string(text) + "'");
    v = v * 10 + (c - '0');
  }
  return neg ? -v : v;
}

long parseInt(std::string_view text, const TextLocation& where, std::string_view field) {
  const auto v = parseOptionalInt(text, where, field);
  if (!v) throwParseError(where, field, "missing value");
  return *v;
}

}  // namespace gvins
