// RINEX 3.04 observation writer: a header, then epoch by epoch. A file written here reads back
// with RinexObsReader into the same epochs (values are written with the format's resolution:
// 1 mm / 0.001 cycle / 0.001 Hz / 0.001 dB-Hz, epoch time 0.1 us, clock offset 1 ps).
//
// Usage:
//   RinexObsHeader h;
//   h.station.markerName = "ROVER";  h.station.approxPosition = p;
//   h.types(System::Gps) = {{ObsType::Code, {'1','C'}}, {ObsType::Phase, {'1','C'}}};
//   h.glonassChannels.set(1, 1);  h.firstObs = t0;  h.interval = 1.0;
//   std::ofstream f("rover.obs");
//   RinexObsWriter w(f, h);          // writes the header
//   for (const ObsEpoch& e : epochs) w.write(e);
// When the observation types are not known in advance, RinexObsHeader::addTypesFrom() builds
// them from sample epochs. Signals whose descriptor is not in the header are not written and are
// counted in droppedValues().
#pragma once

#include <cstdint>
#include <iosfwd>
#include <string>
#include <string_view>
#include <vector>

#include "gvins/base/observation.hpp"
#include "gvins/base/rinex_obs_header.hpp"

namespace gvins {

class RinexObsWriter {
 public:
  /// Writes the header at once. `firstObs` defaults to the first epoch written: when it is not set
  /// the header is held back until the first write(). `programName` goes into "PGM / RUN BY / DATE"
  /// when the header's program field is empty.
  RinexObsWriter(std::ostream& out, RinexObsHeader header, std::string_view programName = "SRI-GVINS");
  ~RinexObsWriter();
  RinexObsWriter(const RinexObsWriter&) = delete;
  RinexObsWriter& operator=(const RinexObsWriter&) = delete;

  /// Writes one epoch. Flags 0, 1 and 6 write the satellites; flags 2-5 write `eventRecords`
  /// (header-format lines, e.g. from RinexObsReader::eventRecords(); each padded/cut to 80
  /// characters) and no satellites. Satellites of systems without types in the header are skipped.
  /// Every epoch is written in the columns of this writer's header, so event records that would
  /// redefine the columns (SYS / # / OBS TYPES, SYS / SCALE FACTOR), RINEX 2 records (# / TYPES OF
  /// OBSERV, WAVELENGTH FACT L1/2) and RINEX VERSION / TYPE or END OF HEADER lines are left out
  /// (counted in droppedEventRecords()): copied, they would make a reader parse the following
  /// epochs with other columns than those written.
  void write(const ObsEpoch& epoch, const std::vector<std::string>& eventRecords = {});
  /// Writes the header if no epoch was written yet (a file with a header only) and flushes.
  void finish();

  std::int64_t epochsWritten() const { return epochs_; }
  /// Values not written: descriptor missing from the header, or too large for F14.3.
  std::int64_t droppedValues() const { return dropped_; }
  /// Event records left out (see write()).
  std::int64_t droppedEventRecords() const { return droppedRecords_; }
  const RinexObsHeader& header() const { return header_; }

 private:
  void writeHeader();
  std::ostream& out_;
  RinexObsHeader header_;
  std::string program_;
  bool headerWritten_ = false;
  std::int64_t epochs_ = 0;
  std::int64_t dropped_ = 0;
  std::int64_t droppedRecords_ = 0;
  std::string buf_;
};

/// Convenience: writes a whole file.
void writeRinexObs(const std::string& path, const RinexObsHeader& header, const std::vector<ObsEpoch>& epochs);

}  // namespace gvins
