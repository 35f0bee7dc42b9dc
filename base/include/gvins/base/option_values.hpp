// Values of command-line options, checked the same way by every tool: the whole text must be a
// finite number (no trailing characters, no nan/inf, no overflow) inside a physical range, and
// errors name the option and the value ("--lever-arm: 1e+06 is outside [-10, 10] m").
#pragma once

#include <stdexcept>
#include <string>
#include <string_view>

#include <Eigen/Core>

namespace gvins {

/// A bad option value; tools print what() and exit with status 2 (usage error).
struct OptionError : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

/// A finite number in [lo, hi]; `unit` is appended to the range in messages ("s", "m", "deg").
double optionNumber(std::string_view option, std::string_view text, double lo, double hi, std::string_view unit = "");
/// "X,Y,Z" (commas, or blanks) with each component a finite number in [lo, hi].
Eigen::Vector3d optionVector3(std::string_view option, std::string_view text, double lo, double hi,
                              std::string_view unit = "");

/// Ellipsoidal heights a ground station can have (m): below the Dead Sea shore (-430 m) with
/// margin, above the highest mountains with margin.
inline constexpr double kMinStationHeight = -1000.0, kMaxStationHeight = 10000.0;

/// An ECEF position (m, "X,Y,Z") of a point near the Earth's surface: its ellipsoidal height must
/// lie in [kMinStationHeight, kMaxStationHeight] (0,0,0 or 1e7,1e7,1e7 are mistakes).
Eigen::Vector3d optionStationEcef(std::string_view option, std::string_view text);
/// A geodetic position "LAT,LON,H" (deg, deg, m) with |lat| <= 90, lon in [-180, 360] and the
/// height as above; returned as ECEF.
Eigen::Vector3d optionStationLlh(std::string_view option, std::string_view text);

}  // namespace gvins
