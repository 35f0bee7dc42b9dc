// RTKLIB stream time-tag files (`FILE.tag` beside a log written by str2str/strsvr with the
// time-tag option): when each part of the log was written, on the logging computer's clock.
//
// Layout (little endian; RTKLIB 2.4.3 stream.c, "TIMETAG RTKLIB" files; facts only):
//   60 bytes  text header ("TIMETAG RTKLIB ..." padded with zeros)
//   u32       tick of the logger at the start (ms, not used: records are relative to it)
//   u32       start time, whole seconds since 1970-01-01 counted on the GPST scale
//   f64       fraction of a second of the start time
//   then records of { u32 tick (ms since the start), u32 file offset (bytes written so far) }.
// The data of a record were on disk `tick` ms after the start: a byte at offset o was received
// at or before the time of the first record whose offset is > o.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace gvins::vio {

struct TimeTagRecord {
  std::uint32_t tick_ms = 0;  ///< ms since the start time
  std::uint32_t offset = 0;   ///< bytes of the log written by then
};

class RtklibTimeTag {
 public:
  /// Reads a tag file; throws gvins::ParseError (file, byte offset, field) for a short or
  /// malformed file, a header that is not "TIMETAG RTKLIB", ticks or offsets that decrease.
  static RtklibTimeTag read(const std::string& path);
  static RtklibTimeTag parse(std::string_view bytes, const std::string& name);

  /// Start time in GPST nanoseconds since 1980-01-06 (the project's time convention).
  std::int64_t startGpst_ns() const { return start_ns_; }
  const std::vector<TimeTagRecord>& records() const { return records_; }
  /// Last offset recorded (the size of the log when the tags were written).
  std::uint32_t finalOffset() const { return records_.empty() ? 0 : records_.back().offset; }

  /// GPST ns by which the bytes [0, end) had been written: the time of the first record whose
  /// offset reaches `end`; nullopt past the last record.
  std::optional<std::int64_t> writtenBy(std::uint64_t end) const;

 private:
  std::int64_t start_ns_ = 0;
  std::vector<TimeTagRecord> records_;
};

}  // namespace gvins::vio
