#include "gvins/vio/rtklib_time_tag.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>

#include "gvins/base/parse_error.hpp"

namespace gvins::vio {

namespace {
constexpr std::size_t kHeaderBytes = 60;
constexpr std::size_t kStartBytes = 16;  // u32 tick, u32 seconds, f64 fraction
constexpr std::size_t kRecordBytes = 8;
// Seconds from 1970-01-01 to 1980-01-06, both counted on one (leap-second free) scale.
constexpr std::int64_t kGpsEpochUnixSeconds = 315964800;

template <class T>
T readLe(std::string_view b, std::size_t at) {
  T v;
  std::memcpy(&v, b.data() + at, sizeof v);  // the project targets little-endian hosts
  return v;
}
}  // namespace

RtklibTimeTag RtklibTimeTag::read(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ParseError(path, 0, "file", "cannot open the time-tag file");
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return parse(bytes, path);
}

RtklibTimeTag RtklibTimeTag::parse(std::string_view b, const std::string& name) {
  // Errors name the byte offset in the "line" slot, as the binary parsers do.
  if (b.size() < kHeaderBytes + kStartBytes) {
    throw ParseError(name, static_cast<std::int64_t>(b.size()), "header",
                     "time-tag file of " + std::to_string(b.size()) + " bytes is shorter than its 76-byte header");
  }
  if (b.substr(0, 14) != "TIMETAG RTKLIB") {
    throw ParseError(name, 0, "header", "not an RTKLIB time-tag file (no \"TIMETAG RTKLIB\" at the start)");
  }
  RtklibTimeTag t;
  const std::uint32_t seconds = readLe<std::uint32_t>(b, kHeaderBytes + 4);
  const double fraction = readLe<double>(b, kHeaderBytes + 8);
  if (!std::isfinite(fraction) || fraction < 0.0 || fraction >= 1.0) {
    throw ParseError(name, kHeaderBytes + 8, "start fraction", "fraction of a second outside [0, 1)");
  }
  if (seconds < kGpsEpochUnixSeconds) {
    throw ParseError(name, kHeaderBytes + 4, "start time", "start time before 1980-01-06");
  }
  t.start_ns_ = (static_cast<std::int64_t>(seconds) - kGpsEpochUnixSeconds) * 1'000'000'000 +
                static_cast<std::int64_t>(std::llround(fraction * 1e9));
  const std::size_t body = b.size() - kHeaderBytes - kStartBytes;
  if (body % kRecordBytes != 0) {
    throw ParseError(name, static_cast<std::int64_t>(b.size()), "record",
                     "file ends inside a record (" + std::to_string(body % kRecordBytes) + " extra bytes)");
  }
  t.records_.reserve(body / kRecordBytes);
  for (std::size_t at = kHeaderBytes + kStartBytes; at < b.size(); at += kRecordBytes) {
    const TimeTagRecord r{readLe<std::uint32_t>(b, at), readLe<std::uint32_t>(b, at + 4)};
    if (!t.records_.empty()) {
      const TimeTagRecord& p = t.records_.back();
      if (r.tick_ms < p.tick_ms) {
        throw ParseError(name, static_cast<std::int64_t>(at), "tick",
                         "tick " + std::to_string(r.tick_ms) + " before the previous " + std::to_string(p.tick_ms));
      }
      if (r.offset < p.offset) {
        throw ParseError(name, static_cast<std::int64_t>(at + 4), "offset",
                         "file offset " + std::to_string(r.offset) + " before the previous " + std::to_string(p.offset));
      }
    }
    t.records_.push_back(r);
  }
  return t;
}

std::optional<std::int64_t> RtklibTimeTag::writtenBy(std::uint64_t end) const {
  const auto it = std::lower_bound(records_.begin(), records_.end(), end,
                                   [](const TimeTagRecord& r, std::uint64_t e) { return r.offset < e; });
  if (it == records_.end()) return std::nullopt;
  return start_ns_ + static_cast<std::int64_t>(it->tick_ms) * 1'000'000;
}

}  // namespace gvins::vio
