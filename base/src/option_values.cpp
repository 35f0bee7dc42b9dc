#include "gvins/base/option_values.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "gvins/base/geodetic.hpp"

namespace gvins {
namespace {

std::string shown(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

std::string rangeText(double lo, double hi, std::string_view unit) {
  return "[" + shown(lo) + ", " + shown(hi) + "]" + (unit.empty() ? "" : " " + std::string(unit));
}

[[noreturn]] void fail(std::string_view option, const std::string& what) {
  throw OptionError(std::string(option) + ": " + what);
}

double finiteNumber(std::string_view option, std::string_view text) {
  const std::string s(text);
  // strtod accepts leading blanks, "nan", "inf" and hexadecimal; from_chars is stricter but
  // still reads "inf"/"nan": both are rejected below through the finiteness check.
  double v = 0.0;
  const char* first = s.data();
  const char* last = s.data() + s.size();
  if (!s.empty() && s[0] == '+') ++first;  // "+5" is a number to a user
  const auto [ptr, ec] = std::from_chars(first, last, v);
  if (s.empty() || ec == std::errc::invalid_argument || ptr != last) fail(option, "'" + s + "' is not a number");
  if (ec == std::errc::result_out_of_range || !std::isfinite(v)) fail(option, "'" + s + "' is not a finite number");
  return v;
}

std::string_view trimmed(std::string_view s) {
  while (!s.empty() && s.front() == ' ') s.remove_prefix(1);
  while (!s.empty() && s.back() == ' ') s.remove_suffix(1);
  return s;
}

/// Fields separated by commas ("1,2,3", "1, 2, 3"), or by blanks when there is no comma.
std::vector<std::string_view> components(std::string_view text) {
  std::vector<std::string_view> out;
  const char sep = text.find(',') != std::string_view::npos ? ',' : ' ';
  std::size_t i = 0;
  for (;;) {
    const std::size_t j = text.find(sep, i);
    const std::string_view f = trimmed(text.substr(i, j == std::string_view::npos ? std::string_view::npos : j - i));
    if (sep == ',' || !f.empty()) out.push_back(f);
    if (j == std::string_view::npos) break;
    i = j + 1;
  }
  return out;
}

}  // namespace

double optionNumber(std::string_view option, std::string_view text, double lo, double hi, std::string_view unit) {
  const double v = finiteNumber(option, text);
  if (!(v >= lo && v <= hi)) fail(option, shown(v) + " is outside " + rangeText(lo, hi, unit));
  return v;
}

Eigen::Vector3d optionVector3(std::string_view option, std::string_view text, double lo, double hi,
                              std::string_view unit) {
  const auto parts = components(text);
  if (parts.size() != 3) fail(option, "'" + std::string(text) + "' is not X,Y,Z (three numbers)");
  Eigen::Vector3d v;
  for (int k = 0; k < 3; ++k) v[k] = optionNumber(option, parts[static_cast<std::size_t>(k)], lo, hi, unit);
  return v;
}

Eigen::Vector3d optionStationEcef(std::string_view option, std::string_view text) {
  const Eigen::Vector3d p = optionVector3(option, text, -1e8, 1e8, "m");
  const Geodetic g = ecefToGeodetic(p);
  if (!(g.height >= kMinStationHeight && g.height <= kMaxStationHeight)) {
    fail(option, "ECEF " + shown(p.x()) + "," + shown(p.y()) + "," + shown(p.z()) + " m is " + shown(g.height) +
                     " m from the Earth's surface (a station lies within " +
                     rangeText(kMinStationHeight, kMaxStationHeight, "m") + " of the ellipsoid)");
  }
  return p;
}

Eigen::Vector3d optionStationLlh(std::string_view option, std::string_view text) {
  const auto parts = components(text);
  if (parts.size() != 3) fail(option, "'" + std::string(text) + "' is not LAT,LON,H (three numbers)");
  const double lat = optionNumber(option, parts[0], -90.0, 90.0, "deg latitude");
  const double lon = optionNumber(option, parts[1], -180.0, 360.0, "deg longitude");
  const double h = optionNumber(option, parts[2], kMinStationHeight, kMaxStationHeight, "m height");
  return geodeticToEcef(geodeticFromDegrees(lat, lon, h));
}

}  // namespace gvins
