// Streaming RINEX observation reader for versions 2.10/2.11 and 3.00-3.05 (and 4.0x, whose
// observation records are those of 3.05): plain or gzip files, one epoch at a time, so memory does
// not grow with the file length.
//
// What is read: all systems (GPS, GLONASS, Galileo, BeiDou, QZSS, SBAS, NavIC), every
// code/phase/Doppler/SNR column with its LLI and signal strength indicator, epoch flags 0-6 with
// their special records (in-file header records update header()), receiver clock offsets,
// "SYS / SCALE FACTOR", GLONASS slot/channel records. RINEX 2 types are mapped to RINEX 3 codes
// (rinex2ObsDescriptor), RINEX 3.02 BeiDou "1I" to "2I" (normalizeObsCode), and epoch times in
// GLONASS/BeiDou time to GPST.
//
// Errors: malformed content throws ParseError naming file, line and field. With
// `skipBadEpochs` the reader instead drops a malformed epoch, resynchronises at the next epoch
// line and counts it in stats(); header errors always throw. Observation epochs must increase:
// one at or before the previous one is an error too (skipped and counted with `skipBadEpochs`). Satellites of unknown systems or
// with out-of-range numbers, and satellites of systems without observation types, are skipped and
// counted, never fatal.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "gvins/base/line_reader.hpp"
#include "gvins/base/observation.hpp"
#include "gvins/base/rinex_obs_header.hpp"

namespace gvins {

struct RinexObsReaderOptions {
  /// Return the special records of epoch flags 2-6 from next() too (epochs with flag 2-5 carry no
  /// satellites, their raw lines are in eventRecords(); flag 6 epochs carry cycle-slip records in
  /// observation format). Off: next() returns only flag 0/1 epochs (observations).
  bool returnSpecialRecords = false;
  /// Skip malformed epochs (counted in stats) instead of throwing.
  bool skipBadEpochs = false;
  /// How many skip messages stats() keeps.
  std::size_t maxMessages = 20;
};

struct RinexObsReaderStats {
  std::int64_t epochs = 0;             ///< observation epochs (flag 0/1) returned
  std::int64_t specialRecords = 0;     ///< epochs with flags 2-6 read
  std::int64_t skippedEpochs = 0;      ///< malformed epochs dropped (skipBadEpochs)
  std::int64_t outOfOrderEpochs = 0;   ///< of those, epochs not after the previous one (out of
                                       ///< order, repeated); without skipBadEpochs a ParseError
  std::int64_t skippedSatellites = 0;  ///< satellite records dropped (unknown system/number/types)
  std::int64_t emptyEpochs = 0;        ///< observation epochs without any satellite
  std::vector<std::string> messages;   ///< first few reasons, with file and line
};

class RinexObsReader {
 public:
  /// Opens a file and reads its header; throws ParseError on a missing or malformed header.
  explicit RinexObsReader(const std::string& path, RinexObsReaderOptions options = {});
  /// Reads from memory; `name` appears in error messages.
  RinexObsReader(std::string_view text, std::string name, RinexObsReaderOptions options = {});
  ~RinexObsReader();
  RinexObsReader(RinexObsReader&&) noexcept;
  RinexObsReader& operator=(RinexObsReader&&) noexcept;

  /// The header, including changes made by in-file header records read so far.
  const RinexObsHeader& header() const;
  /// Reads the next epoch into `epoch` (its storage is reused: pass the same object each time for
  /// speed). Satellites appear in file order, and each satellite's signals in the order of the
  /// header's columns, only signals with at least one value present. Returns false at the end.
  bool next(ObsEpoch& epoch);
  /// Raw header lines that followed the last epoch with flag 2-5 (empty otherwise).
  const std::vector<std::string>& eventRecords() const;
  const RinexObsReaderStats& stats() const;
  /// Source name (path) and the line number last read.
  TextLocation location() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Reads a whole file into memory (tests, small files). Throws ParseError like the reader.
std::vector<ObsEpoch> readRinexObs(const std::string& path, RinexObsHeader* header = nullptr,
                                   RinexObsReaderOptions options = {});

}  // namespace gvins
