// Reader of RTKLIB-compatible solution files (.pos) in either coordinate layout: geodetic
// ("latitude(deg) longitude(deg) height(m)" with optional n/e/u sd and velocity columns) or ECEF
// ("x-ecef(m) ..."), GPST times as "yyyy/mm/dd hh:mm:ss.sss" or "week tow". Velocity columns that
// are nan (our writer) or all zero, values and sd alike (RTKLIB's convention), mean "no velocity".
// A last column titled "test" is our residual-test flag (PositionSolution::residualTest). Used to compare our
// solutions with RTKLIB's and to evaluate any stored result against a truth.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "gvins/gnss/position_solution.hpp"

namespace gvins {

struct PosFile {
  bool ecef = false;  ///< columns were ECEF
  std::vector<PositionSolution> solutions;
};

/// Reads a file (plain or gzip). Throws ParseError (file, line, column name) for malformed rows,
/// unknown layouts and times not in GPST.
PosFile readPosFile(const std::string& path);
/// Parses text in memory; `name` is used in errors.
PosFile parsePosText(std::string_view text, std::string_view name);

}  // namespace gvins
