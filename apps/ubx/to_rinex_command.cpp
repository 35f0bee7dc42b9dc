// gvins-ubx to-rinex FILE|- -o PREFIX [--max-phase-sigma CYC]
// Two passes over the stream (stdin is spooled to a temporary file first): the first collects
// the observation types, GLONASS channels, epoch span and approximate position for the header,
// the second writes PREFIX.obs (RINEX 3.04) epoch by epoch with every signal of RXM-RAWX.
// PREFIX.nav (RINEX 3.04) holds every distinct ephemeris assembled from RXM-SFRBX and the
// ionosphere parameters last broadcast. A log with SFRBX but no RAWX gives PREFIX.nav only.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <tuple>

#include "commands.hpp"
#include "gvins/base/atomic_output_file.hpp"
#include "gvins/base/constants.hpp"
#include "gvins/base/geodetic.hpp"
#include "gvins/base/rinex_obs_writer.hpp"
#include "gvins/ephemeris/rinex_nav.hpp"
#include "stream_summary.hpp"
#include "ubx_summary.hpp"

namespace gvins::ubx_app {

int runToRinex(CommandLine& cl) {
  std::string path, prefix;
  ubx::DecoderOptions opt;
  while (cl.next()) {
    if (cl.is("-o")) {
      prefix = cl.value();
    } else if (cl.is("--max-phase-sigma")) {
      const double v = cl.number(0.0, 1.0, "cycles");
      if (!(v > 0.0)) cl.error("--max-phase-sigma must be a number of cycles in (0, 1]");
      opt.maxPhaseStdDev = v;
    } else {
      const std::string& a = cl.operand();
      if (!path.empty()) cl.error("to-rinex: more than one input");
      path = a;
    }
  }
  if (path.empty()) cl.error("to-rinex: no input (FILE or -)");
  if (prefix.empty()) cl.error("to-rinex: no output prefix (-o PREFIX)");
  const std::string name = path == "-" ? "<stdin>" : path;
  opt.streamName = name;

  std::FILE* in = rtcm_app::reopenable(path);
  // Pass 1: header contents.
  RinexObsHeader header;
  std::map<std::int64_t, int> spacing;  // epoch spacing in ms -> count
  std::optional<GpsTime> prev;
  std::optional<ubx::NavPvt> fix;
  NavData nav;
  std::map<std::tuple<int, int, std::int64_t, int>, bool> seen;  // sat index, message, toe, iode
  ubx::Decoder scan(opt);
  decodeAll(in, scan, [&](const ubx::Decoded& item) {
    if (const auto* e = std::get_if<ObsEpoch>(&item)) {
      header.addTypesFrom(*e);
      if (prev && e->time > *prev) ++spacing[std::llround((e->time - *prev) * 1000.0)];
      prev = e->time;
    } else if (const auto* p = std::get_if<ubx::NavPvt>(&item)) {
      if (!fix && p->fixOk() && p->fixType >= 3) fix = *p;
    } else if (const auto* u = std::get_if<ubx::NavDataUpdate>(&item)) {
      for (const KeplerEphemeris& k : u->kepler) {
        const auto key = std::make_tuple(satIndex(k.sat), static_cast<int>(k.message), k.toe.wholeSeconds(), k.iode);
        if (!seen[key]) nav.kepler.push_back(k);
        seen[key] = true;
      }
      for (const GlonassEphemeris& g : u->glonass) {
        const auto key = std::make_tuple(satIndex(g.sat), -1, g.toe.wholeSeconds(), g.iode);
        if (!seen[key]) nav.glonass.push_back(g);
        seen[key] = true;
      }
      if (u->ionosphere.gps) nav.iono.gps = u->ionosphere.gps;
      if (u->ionosphere.qzss) nav.iono.qzss = u->ionosphere.qzss;
      if (u->ionosphere.beidou) nav.iono.beidou = u->ionosphere.beidou;
      if (u->ionosphere.galileo) nav.iono.galileo = u->ionosphere.galileo;
    }
  });
  const ubx::DecoderStats& st = scan.stats();
  if (st.stream.ubxFrames == 0) {
    if (in != stdin) std::fclose(in);
    throw std::runtime_error("to-rinex: " + name + ": no UBX frame with a good checksum in " +
                             std::to_string(st.stream.bytes) + " bytes; nothing to convert");
  }
  if (st.epochs == 0 && nav.kepler.empty() && nav.glonass.empty()) {
    if (in != stdin) std::fclose(in);
    throw std::runtime_error("to-rinex: " + name + ": " + std::to_string(st.stream.ubxFrames) +
                             " UBX frames but no RXM-RAWX epoch and no ephemeris from RXM-SFRBX; nothing to convert");
  }
  rtcm_app::sortTypes(header);
  header.station.markerName = std::filesystem::path(path == "-" ? "UBX" : path).stem().string();
  header.station.receiverType = "u-blox";
  if (fix) {
    header.station.approxPosition =
        geodeticToEcef({fix->latDeg * constants::kDegToRad, fix->lonDeg * constants::kDegToRad, fix->height});
  }
  header.glonassChannels = scan.glonassChannels();
  header.firstObs = st.firstEpoch;
  header.lastObs = st.lastEpoch;
  if (!spacing.empty()) {
    header.interval = static_cast<double>(std::max_element(spacing.begin(), spacing.end(), [](const auto& a, const auto& b) {
                                            return a.second < b.second;
                                          })->first) * 1e-3;
  }
  if (st.leapSeconds) header.leapSeconds = *st.leapSeconds;
  else if (st.firstEpoch) header.leapSeconds = leapSecondsAtGpst(*st.firstEpoch);
  header.signalStrengthUnit = "DBHZ";
  header.comments.push_back("converted from u-blox UBX RXM-RAWX by gvins-ubx (SRI-GVINS)");
  if (opt.maxPhaseStdDev) {
    char c[80];
    std::snprintf(c, sizeof c, "phases with u-blox cpStdev above %.3f cycles left out", *opt.maxPhaseStdDev);
    header.comments.push_back(c);
  }

  // Pass 2: observations (none when the log has SFRBX but no RAWX: navigation file only).
  const std::string obsPath = prefix + ".obs";
  std::optional<AtomicOutputFile> obsFile;
  std::optional<RinexObsWriter> writer;
  ubx::Decoder dec(opt);
  SummaryExtras ex;
  if (st.epochs > 0) {
    std::rewind(in);
    obsFile.emplace(obsPath);
    writer.emplace(obsFile->stream(), header, "gvins-ubx");
    decodeAll(in, dec, [&](const ubx::Decoded& item) {
      if (const auto* e = std::get_if<ObsEpoch>(&item)) writer->write(*e);
    });
    writer->finish();
  }
  if (in != stdin) std::fclose(in);
  // Navigation file (only when the log carried SFRBX).
  const std::string navPath = prefix + ".nav";
  std::optional<AtomicOutputFile> navFile;
  if (st.sfrbx > 0) {
    std::sort(nav.kepler.begin(), nav.kepler.end(), [](const KeplerEphemeris& a, const KeplerEphemeris& b) {
      return std::make_tuple(a.sat, a.toe) < std::make_tuple(b.sat, b.toe);
    });
    std::sort(nav.glonass.begin(), nav.glonass.end(), [](const GlonassEphemeris& a, const GlonassEphemeris& b) {
      return std::make_tuple(a.sat, a.toe) < std::make_tuple(b.sat, b.toe);
    });
    nav.leapSeconds = header.leapSeconds;
    navFile.emplace(navPath);
    writeRinexNav(navFile->stream(), nav, "gvins-ubx");
  }
  if (obsFile) obsFile->commit();
  if (navFile) navFile->commit();
  if (writer) {
    std::cerr << "wrote " << obsPath << " (" << writer->epochsWritten() << " epochs";
    if (writer->droppedValues() > 0) std::cerr << ", " << writer->droppedValues() << " values not representable";
    std::cerr << ")";
  } else {
    std::cerr << "no RXM-RAWX epoch, no observation file";
  }
  if (navFile) {
    std::cerr << "; wrote " << navPath << " (" << nav.kepler.size() << " Keplerian + " << nav.glonass.size()
              << " GLONASS records from " << st.sfrbx << " SFRBX messages)";
  } else {
    std::cerr << "; no SFRBX, no navigation file";
  }
  std::cerr << "\n";
  printSummary(std::cerr, writer ? dec : scan, ex, name);
  return 0;
}

}  // namespace gvins::ubx_app
