#include "gvins/base/text_fields.hpp"

#include <charconv>
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

std::optional<double> parseOptionalDouble(std::string_view text, const TextLocation& where,
                                          std::string_view field) {
  text = trim(text);
  if (text.empty()) return std::nullopt;
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
