// Shared pieces of the gvins-rtcm commands: input reading, reference time, the summary table.
#pragma once

#include <cstdio>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "gvins/base/command_line.hpp"
#include "gvins/base/gnss_time.hpp"
#include "gvins/base/rinex_obs_header.hpp"
#include "gvins/rtcm/decoder.hpp"

namespace gvins::rtcm_app {

/// Thrown by parseDate for a malformed date; dateOption turns it into a usage error of its
/// CommandLine (exit 2).
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// "YYYY-MM-DD" to 12:00 GPST of that day; throws UsageError.
GpsTime parseDate(const std::string& text);
/// The value of a --date option (parseDate); a usage error of `cl` if it is not a date.
GpsTime dateOption(CommandLine& cl);

/// Opens FILE or "-" (stdin); throws std::runtime_error naming the file.
std::FILE* openInput(const std::string& path);

/// Opens the input for a second reading: a file again, or stdin spooled to a temporary file.
/// (Shared with gvins-ubx.)
std::FILE* reopenable(const std::string& path);

/// Sorts each system's observation types for a RINEX header: by band, attribute, then C L D S.
/// (Shared with gvins-ubx.)
void sortTypes(RinexObsHeader& h);

/// Reference time for a file: the --date option, else the first absolute time found in the file
/// (1020 with N4, 1042, 1045/1046), else nullopt (the decoder then uses the host clock).
/// Prints what it chose to stderr.
std::optional<GpsTime> referenceFor(const std::string& path, const std::optional<GpsTime>& date);

/// Feeds a whole input through the decoder in chunks; `onItem` gets every decoded item.
template <class F>
void decodeAll(std::FILE* in, rtcm::Decoder& dec, F&& onItem) {
  std::vector<std::uint8_t> buf(1 << 16);
  for (;;) {
    const std::size_t n = std::fread(buf.data(), 1, buf.size(), in);
    if (n > 0) dec.feed({buf.data(), n});
    while (auto item = dec.poll()) onItem(*item);
    if (n < buf.size()) break;
  }
  dec.finish();
  while (auto item = dec.poll()) onItem(*item);
}

/// Per-message table, time span, station, ephemerides, errors.
void printSummary(std::ostream& out, const rtcm::Decoder& dec, const std::string& name);

}  // namespace gvins::rtcm_app
