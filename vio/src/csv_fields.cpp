#include "csv_fields.hpp"

#include <limits>
#include <string>

namespace gvins::vio::detail {

void splitFields(std::string_view line, bool whitespace, std::vector<std::string_view>& out) {
  out.clear();
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  if (whitespace) {
    std::size_t i = 0;
    while (i < line.size()) {
      while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
      if (i >= line.size()) break;
      const std::size_t start = i;
      while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
      out.push_back(line.substr(start, i - start));
    }
    return;
  }
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = line.find(',', start);
    if (comma == std::string_view::npos) {
      out.push_back(trim(line.substr(start)));
      return;
    }
    out.push_back(trim(line.substr(start, comma - start)));
    start = comma + 1;
  }
}

bool isCommentOrBlank(std::string_view line) {
  const std::string_view t = trim(line);
  return t.empty() || t.front() == '#';
}

namespace {
constexpr std::int64_t kMax = std::numeric_limits<std::int64_t>::max();

// Digits [begin, end) appended to v; false on overflow.
bool accumulate(std::string_view digits, std::int64_t& v) {
  for (const char c : digits) {
    const int d = c - '0';
    if (v > (kMax - d) / 10) return false;
    v = v * 10 + d;
  }
  return true;
}

bool allDigits(std::string_view s) {
  for (const char c : s) {
    if (c < '0' || c > '9') return false;
  }
  return true;
}

// Splits "123.456" into integer and fractional digit strings; false if not of that form.
bool splitDecimal(std::string_view t, std::string_view& ip, std::string_view& fp) {
  const std::size_t dot = t.find('.');
  ip = t.substr(0, dot);
  fp = dot == std::string_view::npos ? std::string_view{} : t.substr(dot + 1);
  return !ip.empty() && allDigits(ip) && allDigits(fp) && (dot == std::string_view::npos || !fp.empty());
}
}  // namespace

std::int64_t parseNanoseconds(std::string_view text, const TextLocation& where, std::string_view field) {
  const std::string_view t = trim(text);
  if (t.empty()) throwParseError(where, field, "missing time stamp");
  std::string_view ip, fp;
  if (!splitDecimal(t, ip, fp)) {
    throwParseError(where, field, "not a non-negative time stamp in nanoseconds: '" + std::string(t) + "'");
  }
  std::int64_t v = 0;
  if (!accumulate(ip, v)) throwParseError(where, field, "time stamp out of range: '" + std::string(t) + "'");
  if (!fp.empty() && fp[0] >= '5') {
    if (v == kMax) throwParseError(where, field, "time stamp out of range: '" + std::string(t) + "'");
    ++v;
  }
  return v;
}

std::int64_t parseSecondsToNanoseconds(std::string_view text, const TextLocation& where,
                                       std::string_view field) {
  const std::string_view t = trim(text);
  if (t.empty()) throwParseError(where, field, "missing time stamp");
  std::string_view ip, fp;
  if (!splitDecimal(t, ip, fp)) {
    throwParseError(where, field, "not a non-negative time in seconds: '" + std::string(t) + "'");
  }
  std::int64_t sec = 0;
  if (!accumulate(ip, sec) || sec > kMax / 1000000000 - 1) {
    throwParseError(where, field, "time out of range: '" + std::string(t) + "'");
  }
  std::int64_t ns = 0;
  for (std::size_t i = 0; i < 9; ++i) ns = ns * 10 + (i < fp.size() ? fp[i] - '0' : 0);
  if (fp.size() > 9 && fp[9] >= '5') ++ns;
  return sec * 1000000000 + ns;
}

}  // namespace gvins::vio::detail
