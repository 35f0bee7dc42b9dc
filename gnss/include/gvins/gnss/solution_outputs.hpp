// The optional side outputs of the positioning tools (gvins-spp, gvins-rtk, gvins-replay): an
// NMEA 0183 GGA/RMC file (nmea_writer.hpp) and a KML track (kml_writer.hpp) of the valid
// solutions. Post-processing writes both under temporary names and renames them when the run
// succeeds (OutputTarget); live runs write the NMEA file as solutions come (flushed per epoch).
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "gvins/base/atomic_output_file.hpp"
#include "gvins/base/geodetic.hpp"
#include "gvins/gnss/nmea_writer.hpp"

namespace gvins {

class SolutionOutputs {
 public:
  /// Empty paths: that output is off. "-" is standard output. Throws std::runtime_error naming
  /// the path if a file cannot be created.
  SolutionOutputs(const std::string& nmeaPath, const std::string& kmlPath, std::string kmlName,
                  NmeaOptions nmea = {});
  bool any() const { return nmea_ != nullptr || kml_.has_value(); }
  /// One epoch's solution; invalid ones give an NMEA epoch with quality 0 and no KML point.
  void add(const PositionSolution& s, const NmeaExtras& extras = {});
  /// Writes the KML and commits both files (success) or discards them.
  void finish(bool success);

 private:
  std::optional<OutputTarget> nmeaFile_, kml_;
  std::unique_ptr<NmeaWriter> nmea_;
  std::string kmlName_;
  std::vector<Geodetic> track_;
};

}  // namespace gvins
