// Writes the GNSS truth of a simulated run into <dataset>/gnss/truth/ (format in
// docs/dataset_format.md, "gnss/"): per-epoch antenna positions and receiver clocks of rover and
// base, ambiguity arcs, cycle slips, event intervals, optionally every error term of every
// measurement, and gnss_truth.yaml with the constants of the run.
//
// Times are integer GPST nanoseconds since 1980-01-06 00:00:00 (the sensor-stamp convention of
// the dataset): `tag_ns` is the receiver time tag of the epoch (the RINEX epoch), `gpst_ns` the
// true time of the measurement (tag - clock bias).
#pragma once

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "gvins/sim/gnss_sim_epoch.hpp"

namespace gvins::sim {

/// GPST nanoseconds since the GPS epoch, rounded to the nearest nanosecond.
std::int64_t gpstNanoseconds(const GpsTime& t);

class GnssTruthWriter {
 public:
  /// Creates `dir` and opens the per-epoch files. Throws std::runtime_error if a file cannot be
  /// created.
  GnssTruthWriter(const std::filesystem::path& dir, bool withBase, bool errorTerms);

  void add(const GnssSimEpoch& epoch);
  /// Writes the arc, slip and event files.
  void finish(const std::vector<GnssAmbiguityArc>& arcs, const std::vector<GnssSlipEvent>& slips,
              const std::vector<GnssEventInterval>& events);
  /// Files written so far.
  const std::vector<std::filesystem::path>& files() const { return files_; }

 private:
  std::ofstream open(const std::string& name);
  std::filesystem::path dir_;
  bool errorTerms_;
  std::ofstream roverAntenna_, roverClock_, baseClock_, roverErrors_, baseErrors_;
  std::vector<std::filesystem::path> files_;
  std::string buf_;
};

}  // namespace gvins::sim
