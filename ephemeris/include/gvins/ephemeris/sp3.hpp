// SP3 precise orbit files, versions c and d: reading and writing.
//
// Format: "The Extended Standard Product 3 Orbit Format (SP3-d)", S. Hilla, IGS, 2016, and
// "The Extended Standard Product 3 Orbit Format (SP3-c)", S. Hilla, 2010. Positions are in km and
// clocks in microseconds in the file; here they are kept in metres and seconds. For IGS products the
// positions are the satellite centre of mass (not the antenna phase centre) in the file's
// terrestrial frame (e.g. IGb20), and the clocks are satellite minus system time WITHOUT the
// periodic relativistic correction.
#pragma once

#include <Eigen/Core>
#include <iosfwd>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "gvins/base/gnss_time.hpp"
#include "gvins/base/parse_error.hpp"
#include "gvins/base/satellite.hpp"

namespace gvins {

/// One satellite at one epoch.
struct Sp3Record {
  SatId sat;
  /// m, ECEF of the epoch; NaN components if missing (0.000000 km in the file).
  Eigen::Vector3d position = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  /// s, satellite - system time as in the file (WITHOUT the periodic relativistic term);
  /// NaN if missing (999999.999999 us or blank in the file).
  double clock = std::numeric_limits<double>::quiet_NaN();
  std::optional<Eigen::Vector3d> velocity;  ///< m/s if a V record was present (NaN comps if missing)
  std::optional<double> clockRate;          ///< s/s if a V record was present (NaN if missing)
};

/// One epoch; `time` is converted from the file's time system to GPST.
struct Sp3Epoch {
  GpsTime time;
  std::vector<Sp3Record> records;
};

struct Sp3Data {
  char version = 'd';            ///< 'c' or 'd'
  std::string timeSystem = "GPS";///< GPS, GLO, GAL, BDT, QZS, TAI or UTC ("ccc" is read as GPS)
  std::string coordinateSystem;  ///< e.g. IGb20
  std::string orbitType, agency; ///< e.g. FIT, IGS
  std::string dataUsed;          ///< e.g. ORBIT, u+U
  double interval = 0.0;         ///< s, from the ## line
  std::vector<SatId> satellites; ///< header list
  std::vector<int> accuracyExponent;  ///< per listed satellite (0 = unknown): 2^exp mm
  std::vector<std::string> comments;  ///< text of the /* lines (without the "/* ")
  std::vector<Sp3Epoch> epochs;       ///< strictly increasing time (the reader rejects otherwise)
};

/// Reads an SP3-c/d file (plain or gzip). Throws ParseError naming file, line and field for any
/// malformed input.
Sp3Data readSp3(const std::string& path);
/// Parses SP3 text held in memory; `name` is used in error messages.
Sp3Data parseSp3(std::string_view text, const std::string& name);
/// Writes SP3-d (or SP3-c if data.version == 'c' and there are at most 85 satellites): positions
/// to 1 mm, clocks to 1e-12 s; velocity records when any record has a velocity. Epoch times are
/// written in data.timeSystem (converted back from GPST).
void writeSp3(std::ostream& out, const Sp3Data& data);

}  // namespace gvins
