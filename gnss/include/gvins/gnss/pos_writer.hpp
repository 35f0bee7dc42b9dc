// Writer of RTKLIB-compatible solution files (.pos): header lines starting with '%', then one
// row per epoch with GPST time, position (geodetic degrees/height or ECEF), quality, number of
// satellites, standard deviations with signed square roots of the covariances, age, ratio and,
// optionally, velocity with its standard deviations (RTKLIB's "out-outvel" columns; nan where an
// epoch has no velocity) and the residual-test column. Fields keep printf's widths; a value that
// fills or overflows its field is preceded by one blank more, so columns never run together.
// The layout and its additions: docs/pos_format.md.
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

#include "gvins/gnss/position_solution.hpp"

namespace gvins {

enum class PosCoordinates {
  Llh,  ///< latitude/longitude (deg), ellipsoidal height (m); sd in the local n/e/u frame
  Xyz,  ///< ECEF x/y/z (m); sd in ECEF
};

struct PosWriterOptions {
  PosCoordinates coordinates = PosCoordinates::Llh;
  bool velocity = true;    ///< velocity columns (nan for epochs without a velocity)
  /// A last column "test": the epoch's residual (RAIM) test, PositionSolution::residualTest
  /// (0 passed, 1 failed, 2 not testable; 2 when not set). RTKLIB's readers ignore it.
  bool testColumn = false;
  int timeDecimals = 3;    ///< decimals of the seconds, 0-9
  bool header = true;
  std::string program = "SRI-GVINS";
  /// Extra "% key : value" header lines (input files, options), written after the program line.
  std::vector<std::pair<std::string, std::string>> headerFields;
  /// Extra "% (note)" lines after the column legend (e.g. why the velocity is absent).
  std::vector<std::string> notes;
};

class PosWriter {
 public:
  PosWriter(std::ostream& out, PosWriterOptions options = {});
  /// Writes the header on the first call, then the row.
  void write(const PositionSolution& s);
  /// Writes the header if nothing was written yet.
  void finish();

 private:
  void writeHeader();
  std::ostream& out_;
  PosWriterOptions opt_;
  bool headerDone_ = false;
  std::string buf_;
};

/// Signed square root of a covariance: sign(c) sqrt(|c|) (RTKLIB's convention for the sdxy... columns).
double signedSqrt(double c);

}  // namespace gvins
