#include "ubx_summary.hpp"

#include <iomanip>
#include <map>
#include <sstream>

#include "gvins/ubx/ubx_signals.hpp"

namespace gvins::ubx_app {

std::string_view messageName(int type) {
  // u-blox interface descriptions, "UBX messages overview".
  static const std::map<int, std::string_view> kNames{
      {0x0101, "NAV-POSECEF"}, {0x0102, "NAV-POSLLH"},  {0x0103, "NAV-STATUS"},   {0x0104, "NAV-DOP"},
      {0x0106, "NAV-SOL"},     {0x0107, "NAV-PVT"},     {0x0111, "NAV-VELECEF"},  {0x0112, "NAV-VELNED"},
      {0x0114, "NAV-HPPOSLLH"}, {0x0120, "NAV-TIMEGPS"}, {0x0121, "NAV-TIMEUTC"}, {0x0122, "NAV-CLOCK"},
      {0x0124, "NAV-TIMEBDS"}, {0x0125, "NAV-TIMEGAL"}, {0x0126, "NAV-TIMELS"},   {0x0130, "NAV-SVINFO"},
      {0x0132, "NAV-SBAS"},    {0x0135, "NAV-SAT"},     {0x013C, "NAV-RELPOSNED"}, {0x0143, "NAV-SIG"},
      {0x0161, "NAV-EOE"},     {0x0213, "RXM-SFRBX"},   {0x0214, "RXM-MEASX"},    {0x0215, "RXM-RAWX"},
      {0x0232, "RXM-RTCM"},    {0x0A04, "MON-VER"},     {0x0A09, "MON-HW"},       {0x0D01, "TIM-TP"},
      {0x1002, "ESF-MEAS"},    {0x1003, "ESF-RAW"},     {0x1010, "ESF-STATUS"},   {0x0501, "ACK-ACK"},
      {0x0500, "ACK-NAK"},     {0x0B02, "AID/MGA"}};
  const auto it = kNames.find(type);
  return it == kNames.end() ? std::string_view() : it->second;
}

void printNavigationSources(std::ostream& out, const ubx::NavigationAssembler& nav) {
  if (nav.countsBySource().empty()) return;
  out << "  gnssId/sigId  signal             message                     messages  records  check fail  unknown\n";
  for (const auto& [src, c] : nav.countsBySource()) {
    const ubx::NavigationSourceInfo info = ubx::navigationSourceInfo(src);
    char ids[16];
    std::snprintf(ids, sizeof ids, "%d/%d", src.gnssId, src.sigId);
    out << "  " << std::left << std::setw(14) << ids << std::setw(19) << ubx::signalName(src.gnssId, src.sigId)
        << std::setw(26) << info.message << std::right << std::setw(10) << c.messages;
    if (info.decoded) {
      out << std::setw(9) << c.ephemerides + c.groupDelays << std::setw(12) << c.parityFailures + c.crcFailures << std::setw(9)
          << c.unknownMessages;
    }
    out << "\n";
  }
}

void printSummary(std::ostream& out, const ubx::Decoder& dec, const SummaryExtras& ex, const std::string& name) {
  const ubx::DecoderStats& st = dec.stats();
  out << "UBX stream " << name << ": " << st.stream.bytes << " bytes\n";
  out << "  class-id   count  name\n";
  std::int64_t total = 0;
  for (const auto& [type, count] : st.messages) {
    char id[16];
    std::snprintf(id, sizeof id, "0x%02X-0x%02X", (type >> 8) & 0xFF, type & 0xFF);
    out << "  " << id << std::setw(8) << count << "  " << messageName(type) << "\n";
    total += count;
  }
  out << "  total    " << std::setw(8) << total << "\n";
  out << "other          " << st.stream.nmeaSentences << " NMEA sentences, " << st.stream.rtcmFrames
      << " RTCM 3 frames\n";
  if (st.firstEpoch) {
    out << "time span      " << st.firstEpoch->toString(3) << " - " << st.lastEpoch->toString(3) << " GPST ("
        << st.epochs << " epochs, " << std::fixed << std::setprecision(1) << (*st.lastEpoch - *st.firstEpoch)
        << " s)\n";
  } else {
    out << "time span      no RXM-RAWX epochs\n";
  }
  if (st.leapSeconds) out << "leap seconds   " << *st.leapSeconds << " (GPST - UTC, from the receiver)\n";
  // Signals per system.
  std::map<int, std::vector<std::pair<int, std::int64_t>>> perSystem;
  for (const auto& [ids, n] : st.signalIds) perSystem[ids.first].push_back({ids.second, n});
  out << "signals        " << st.signalsDelivered << " in epochs\n";
  for (const auto& [gnss, list] : perSystem) {
    const auto sys = ubx::systemOfGnssId(static_cast<std::uint8_t>(gnss));
    std::ostringstream row;
    row << "  " << std::left << std::setw(8) << (sys ? std::string(systemName(*sys)) : std::to_string(gnss)) << std::right;
    for (const auto& [sig, n] : list) {
      const auto code = ubx::obsCodeOf(static_cast<std::uint8_t>(gnss), static_cast<std::uint8_t>(sig));
      row << "  " << ubx::signalName(static_cast<std::uint8_t>(gnss), static_cast<std::uint8_t>(sig)) << " ("
          << (code ? code->str() : "?") << ") " << n;
    }
    out << row.str() << "\n";
  }
  if (st.unknownSatellites + st.unknownSignals > 0) {
    out << "dropped        " << st.unknownSatellites << " measurements of unknown satellites, " << st.unknownSignals
        << " of unknown signals";
    for (const auto& [ids, n] : st.unknownSignalIds) out << " [gnssId " << ids.first << " sigId " << ids.second << ": " << n << "]";
    out << "\n";
  }
  out << "lock           " << st.slips << " phases flagged lost lock, " << st.halfCycleUnresolved
      << " with unresolved half cycle, " << st.clockResets << " receiver clock resets\n";
  const ubx::NavigationCounts nc = dec.navigationCounts();
  out << "SFRBX          " << st.sfrbx << " navigation messages: " << st.ephemerides << " ephemerides, "
      << nc.groupDelays << " CNAV group delay sets, " << nc.parityFailures << " parity and " << nc.crcFailures << " CRC failures, " << nc.skipped
      << " of systems not decoded, " << st.sfrbxUndated << " before the first RAWX epoch (no receive time)\n";
  printNavigationSources(out, dec.navigationAssembler());
  if (ex.navPvt > 0) {
    out << "NAV-PVT        " << ex.navPvt << " (" << ex.navPvtFixes << " with gnssFixOK)";
    if (ex.lastPvt) {
      out << std::setprecision(8) << ", last lat " << ex.lastPvt->latDeg << " lon " << ex.lastPvt->lonDeg
          << std::setprecision(3) << " h " << ex.lastPvt->height << " m";
    }
    out << "\n";
  }
  if (ex.lastClock) {
    out << "NAV-CLOCK      last bias " << std::setprecision(3) << ex.lastClock->biasS * 1e9 << " ns, drift "
        << ex.lastClock->driftSps * 1e9 << " ns/s\n";
  }
  if (st.imuSamples > 0) out << "ESF            " << st.imuSamples << " IMU samples\n";
  out << "checksum fail  " << st.stream.ubxChecksumFailures << " UBX (oversize lengths " << st.stream.ubxOversize
      << "), " << st.stream.rtcmCrcFailures << " RTCM CRC, " << st.stream.nmeaChecksumFailures
      << " NMEA; truncated " << st.stream.truncatedFrames << ", bytes skipped " << st.stream.skippedBytes << "\n";
  out << "malformed      " << st.malformed << "\n";
  for (const auto& issue : st.issues) {
    out << "  byte " << issue.offset << ": " << issue.what << "\n";
  }
}

}  // namespace gvins::ubx_app
