#include "stream_summary.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <tuple>

#include "gvins/base/constants.hpp"
#include "gvins/base/geodetic.hpp"
#include "gvins/rtcm/message_types.hpp"

namespace gvins::rtcm_app {

GpsTime parseDate(const std::string& text) {
  CalendarTime c;
  char extra = 0;
  if (std::sscanf(text.c_str(), "%d-%d-%d%c", &c.year, &c.month, &c.day, &extra) != 3 || !isValidCalendar(c)) {
    throw UsageError("--date must be YYYY-MM-DD, got '" + text + "'");
  }
  // GPS time starts on 1980-01-06 (IS-GPS-200 section 3.3.4); RTCM 3 carries times of week only,
  // so a date outside GPS time would place every epoch before the start of GPS time.
  if (c.year < 1980 || (c.year == 1980 && (c.month == 1 && c.day < 6)) || c.year > 2099) {
    throw UsageError("--date " + text + " is outside GPS time (1980-01-06 to 2099-12-31)");
  }
  c.hour = 12;
  return GpsTime::fromCalendar(c);
}

GpsTime dateOption(CommandLine& cl) {
  const std::string text = cl.value();
  try {
    return parseDate(text);
  } catch (const UsageError& e) {
    cl.error(e.what());
  }
}

std::FILE* openInput(const std::string& path) {
  if (path == "-") return stdin;
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw std::runtime_error("'" + path + "' is a directory, not a file");
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) throw std::runtime_error("cannot open '" + path + "': " + std::strerror(errno));
  return f;
}

std::FILE* reopenable(const std::string& path) {
  if (path != "-") return openInput(path);
  std::FILE* tmp = std::tmpfile();
  if (!tmp) throw std::runtime_error(std::string("cannot create a temporary file: ") + std::strerror(errno));
  std::vector<char> buf(1 << 16);
  std::size_t n;
  while ((n = std::fread(buf.data(), 1, buf.size(), stdin)) > 0) std::fwrite(buf.data(), 1, n, tmp);
  std::rewind(tmp);
  return tmp;
}

void sortTypes(RinexObsHeader& h) {
  auto rank = [](ObsType t) { return t == ObsType::Code ? 0 : t == ObsType::Phase ? 1 : t == ObsType::Doppler ? 2 : 3; };
  for (auto& list : h.obsTypes) {
    std::stable_sort(list.begin(), list.end(), [&](const ObsDescriptor& a, const ObsDescriptor& b) {
      return std::make_tuple(a.code.band, a.code.attr, rank(a.type)) < std::make_tuple(b.code.band, b.code.attr, rank(b.type));
    });
  }
}

std::optional<GpsTime> referenceFor(const std::string& path, const std::optional<GpsTime>& date) {
  if (date) return date;
  if (path == "-") {
    std::cerr << "note: no --date: times are resolved against the host clock until the stream gives an absolute date\n";
    return std::nullopt;
  }
  std::FILE* f = openInput(path);
  rtcm::Decoder scan;
  std::vector<std::uint8_t> buf(1 << 16);
  std::optional<GpsTime> found;
  for (;;) {
    const std::size_t n = std::fread(buf.data(), 1, buf.size(), f);
    if (n > 0) scan.feed({buf.data(), n});
    while (scan.poll()) {
    }
    if (scan.referenceIsAbsolute()) {
      found = scan.referenceTime();
      break;
    }
    if (n < buf.size()) break;
  }
  std::fclose(f);
  if (found) {
    std::cerr << "note: no --date: using the absolute time found in the stream, " << found->toString(0) << " GPST\n";
  } else {
    std::cerr << "note: no --date and no absolute date in the stream (1020 with N4, 1042, 1045/1046): "
                 "weeks are resolved against the host clock; pass --date for old recordings\n";
  }
  return found;
}

void printSummary(std::ostream& out, const rtcm::Decoder& dec, const std::string& name) {
  const rtcm::DecoderStats& st = dec.stats();
  out << "RTCM 3 stream " << name << ": " << st.framing.bytes << " bytes\n";
  out << "  type     count  description\n";
  std::int64_t total = 0;
  for (const auto& [type, count] : st.messages) {
    std::ostringstream row;
    row << "  " << std::setw(4) << (type < 0 ? std::string("-") : std::to_string(type)) << "  " << std::setw(8) << count
        << "  " << (type < 0 ? std::string_view("empty frame") : rtcm::messageDescription(type))
        << (type >= 0 && !rtcm::isDecodedType(type) ? " (not decoded)" : "");
    out << row.str() << "\n";
    total += count;
  }
  out << "  total " << std::setw(8) << total << "\n";
  if (st.firstEpoch) {
    out << "time span      " << st.firstEpoch->toString(3) << " - " << st.lastEpoch->toString(3) << " GPST ("
        << st.epochs << " epochs, " << std::fixed << std::setprecision(1) << (*st.lastEpoch - *st.firstEpoch)
        << " s)\n";
  } else {
    out << "time span      no observation epochs\n";
  }
  if (const auto& p = dec.stationPosition()) {
    const Geodetic g = ecefToGeodetic(p->arp);
    out << std::fixed << std::setprecision(4) << "station        ID " << p->stationId << ": ARP ECEF " << p->arp.x() << " "
        << p->arp.y() << " " << p->arp.z() << " m (lat " << std::setprecision(8) << g.lat * constants::kRadToDeg << " lon "
        << g.lon * constants::kRadToDeg << " h " << std::setprecision(3) << g.height << " m)";
    if (p->antennaHeight) out << ", antenna height " << std::setprecision(4) << *p->antennaHeight << " m";
    out << "\n";
  } else {
    out << "station        no 1005/1006\n";
  }
  const StationInfo& si = dec.station();
  if (!si.antennaType.empty()) out << "antenna        " << si.antennaType << (si.antennaNumber.empty() ? "" : " #" + si.antennaNumber) << "\n";
  if (!si.receiverType.empty()) out << "receiver       " << si.receiverType << " " << si.receiverVersion << (si.receiverNumber.empty() ? "" : " #" + si.receiverNumber) << "\n";
  out << "ephemerides    " << st.ephemerides << "\n";
  if (st.beidouGpstEpochs > 0) {
    out << "BeiDou MSM     " << st.beidouGpstEpochs << " messages stamped in GPS time instead of BDT (read as GPST)\n";
  }
  out << "CRC failures   " << st.framing.crcFailures << " (good frames " << st.framing.frames << ", bad headers "
      << st.framing.badHeaders << ", truncated " << st.framing.truncatedFrames << ", bytes skipped "
      << st.framing.skippedBytes << ")\n";
  out << "malformed      " << st.malformed << "\n";
  for (const auto& issue : st.issues) out << "  " << issue.what << "\n";
  if (st.unknownSatellites + st.unknownSignals + st.glonassNoChannel + st.unresolvedRanges > 0) {
    out << "dropped cells  " << st.unknownSatellites << " unknown satellites, " << st.unknownSignals
        << " reserved signals, " << st.glonassNoChannel << " GLONASS phases without channel, "
        << st.unresolvedRanges << " MSM1-3 ranges without whole milliseconds\n";
  }
}

}  // namespace gvins::rtcm_app
