// RINEX clock files, versions 2.00 and 3.00-3.04: reading and writing.
//
// Format: "RINEX Extensions to Handle Clock Information", version 3.04 (IGS/RTCM-SC104, 2017)
// and version 2.00 (J. Ray, W. Gurtner, 1998). Only satellite clock records (AS) are kept; the
// receiver/calibration/discontinuity/monitor records (AR, CR, DR, MS) are checked and counted.
#pragma once

#include <cstddef>
#include <iosfwd>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "gvins/base/gnss_time.hpp"
#include "gvins/base/parse_error.hpp"
#include "gvins/base/satellite.hpp"

namespace gvins {

/// One clock sample: satellite - system time in seconds, WITHOUT the periodic relativistic term
/// (as in IGS clock products). sigma 0 = not given.
struct ClockRecord {
  GpsTime time;  ///< GPST (converted from the file's time system)
  double bias = 0.0;
  double sigma = 0.0;
};

struct ClockData {
  double version = 3.04;
  std::string timeSystem = "GPS";  ///< GPS, GLO, GAL, BDT, QZS, TAI or UTC
  /// Satellites in order of first appearance; their records sorted by time.
  std::vector<std::pair<SatId, std::vector<ClockRecord>>> satellites;
  std::size_t skippedRecords = 0;  ///< AR/CR/DR/MS records
  /// The records of a satellite, or nullptr.
  const std::vector<ClockRecord>* find(SatId sat) const;
};

/// Reads a RINEX clock file (plain or gzip). Throws ParseError naming file, line and field.
ClockData readRinexClock(const std::string& path);
/// Parses RINEX clock text in memory; `name` is used in error messages.
ClockData parseRinexClock(std::string_view text, const std::string& name);
/// Writes the AS records in the 3.04 layout (or 3.00 if data.version < 3.04).
void writeRinexClock(std::ostream& out, const ClockData& data);

}  // namespace gvins
