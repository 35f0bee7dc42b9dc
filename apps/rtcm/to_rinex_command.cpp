// gvins-rtcm to-rinex FILE|- --date YYYY-MM-DD -o PREFIX
// Two passes over the stream (stdin is spooled to a temporary file first): the first collects
// the observation types, station description, GLONASS channels and epoch span for the header,
// the second writes PREFIX.obs (RINEX 3.04) epoch by epoch; PREFIX.nav (RINEX 3.04) holds every
// distinct ephemeris record.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <tuple>

#include "commands.hpp"
#include "gvins/base/atomic_output_file.hpp"
#include "gvins/base/command_line.hpp"
#include "gvins/base/rinex_obs_writer.hpp"
#include "gvins/ephemeris/rinex_nav.hpp"
#include "stream_summary.hpp"

namespace gvins::rtcm_app {
namespace {

/// Adds b's satellites/signals into a (same epoch time delivered twice).
void mergeEpoch(ObsEpoch& a, const ObsEpoch& b) {
  for (const SatObs& s : b.sats) {
    SatObs& t = a.add(s.sat);
    for (const SignalObs& g : s.signals) {
      if (!t.find(g.code)) t.signals.push_back(g);
    }
  }
}

}  // namespace

int runToRinex(int argc, char** argv) {
  std::string path, prefix;
  std::optional<GpsTime> date;
  CommandLine cl("gvins-rtcm to-rinex", kUsage, argc, argv, 2);
  while (cl.next()) {
    if (cl.is("--date")) date = dateOption(cl);
    else if (cl.is("-o")) prefix = cl.value();
    else if (path.empty()) path = cl.operand();
    else {
      cl.operand();  // an unknown option is reported as such
      cl.error("more than one input");
    }
  }
  if (path.empty()) cl.error("no input (FILE or -)");
  if (!date) cl.error("--date YYYY-MM-DD is required (RTCM times carry no date)");
  if (prefix.empty()) cl.error("no output prefix (-o PREFIX)");

  std::FILE* in = reopenable(path);
  rtcm::DecoderOptions opt;
  opt.referenceTime = date;
  opt.streamName = path;

  // Pass 1: header contents, ephemerides.
  RinexObsHeader header;
  NavData nav;
  std::map<std::tuple<int, int, std::int64_t, int>, bool> seen;  // sat index, message, toe, iode
  std::map<std::int64_t, int> spacing;  // epoch spacing in ms -> count
  std::optional<GpsTime> first, last, prev;
  std::int64_t epochs = 0;
  rtcm::Decoder scan(opt);
  decodeAll(in, scan, [&](const rtcm::Decoded& item) {
    if (const auto* e = std::get_if<ObsEpoch>(&item)) {
      header.addTypesFrom(*e);
      if (prev && e->time > *prev) ++spacing[std::llround((e->time - *prev) * 1000.0)];
      if (!prev || e->time != *prev) ++epochs;
      if (!first || e->time < *first) first = e->time;
      if (!last || e->time > *last) last = e->time;
      prev = e->time;
    } else if (const auto* k = std::get_if<KeplerEphemeris>(&item)) {
      const auto key = std::make_tuple(satIndex(k->sat), static_cast<int>(k->message), k->toe.wholeSeconds(), k->iode);
      if (!seen[key]) nav.kepler.push_back(*k);
      seen[key] = true;
    } else if (const auto* g = std::get_if<GlonassEphemeris>(&item)) {
      const auto key = std::make_tuple(satIndex(g->sat), -1, g->toe.wholeSeconds(), g->iode);
      if (!seen[key]) nav.glonass.push_back(*g);
      seen[key] = true;
    }
  });
  const std::string name = path == "-" ? "<stdin>" : path;
  if (scan.stats().framing.frames == 0) {
    if (in != stdin) std::fclose(in);
    throw std::runtime_error("to-rinex: " + name + ": no RTCM 3 frame with a good CRC in " +
                             std::to_string(scan.stats().framing.bytes) + " bytes; nothing to convert");
  }
  if (epochs == 0 && nav.kepler.empty() && nav.glonass.empty()) {
    if (in != stdin) std::fclose(in);
    throw std::runtime_error("to-rinex: " + name + ": " + std::to_string(scan.stats().framing.frames) +
                             " RTCM 3 frames but no observation epoch and no ephemeris; nothing to convert");
  }
  sortTypes(header);
  header.station = scan.station();
  if (header.station.markerName.empty()) header.station.markerName = std::filesystem::path(path == "-" ? "RTCM" : path).stem().string();
  header.glonassChannels = scan.glonassChannels();
  header.firstObs = first;
  header.lastObs = last;
  if (!spacing.empty()) {
    header.interval = static_cast<double>(std::max_element(spacing.begin(), spacing.end(), [](const auto& a, const auto& b) {
                                            return a.second < b.second;
                                          })->first) * 1e-3;
  }
  if (first) header.leapSeconds = leapSecondsAtGpst(*first);
  header.signalStrengthUnit = "DBHZ";
  header.comments.push_back("converted from RTCM 3 by gvins-rtcm (SRI-GVINS)");
  if (scan.stats().beidouGpstEpochs > 0) {
    header.comments.push_back("BeiDou MSM epochs stamped in GPST read as GPST: " + std::to_string(scan.stats().beidouGpstEpochs));
  }
  if (const auto& b = scan.glonassBiases()) {
    const std::pair<const char*, std::optional<double>> biases[] = {{"C1C", b->l1ca}, {"C1P", b->l1p}, {"C2C", b->l2ca}, {"C2P", b->l2p}};
    for (const auto& [code, value] : biases) header.glonassBiases.push_back({*ObsDescriptor::parse(code), value});
  }

  // Pass 2: observations.
  std::rewind(in);
  const std::string obsPath = prefix + ".obs";
  AtomicOutputFile obsFile(obsPath);  // renamed into place only when both files are complete
  std::ofstream& obs = obsFile.stream();
  RinexObsWriter writer(obs, header, "gvins-rtcm");
  rtcm::Decoder dec(opt);
  std::optional<ObsEpoch> pending;
  decodeAll(in, dec, [&](const rtcm::Decoded& item) {
    const auto* e = std::get_if<ObsEpoch>(&item);
    if (!e) return;
    if (pending && pending->time == e->time) {
      mergeEpoch(*pending, *e);
      return;
    }
    if (pending) writer.write(*pending);
    pending = *e;
  });
  if (pending) writer.write(*pending);
  writer.finish();
  if (in != stdin) std::fclose(in);

  // Navigation file.
  std::sort(nav.kepler.begin(), nav.kepler.end(), [](const KeplerEphemeris& a, const KeplerEphemeris& b) {
    return std::make_tuple(a.sat, a.toe) < std::make_tuple(b.sat, b.toe);
  });
  std::sort(nav.glonass.begin(), nav.glonass.end(), [](const GlonassEphemeris& a, const GlonassEphemeris& b) {
    return std::make_tuple(a.sat, a.toe) < std::make_tuple(b.sat, b.toe);
  });
  if (first) nav.leapSeconds = leapSecondsAtGpst(*first);
  const std::string navPath = prefix + ".nav";
  AtomicOutputFile navFile(navPath);
  writeRinexNav(navFile.stream(), nav, "gvins-rtcm");
  obsFile.commit();
  navFile.commit();

  std::cerr << "wrote " << obsPath << " (" << writer.epochsWritten() << " epochs";
  if (writer.droppedValues() > 0) std::cerr << ", " << writer.droppedValues() << " values not representable";
  std::cerr << ") and " << navPath << " (" << nav.kepler.size() << " Keplerian + " << nav.glonass.size()
            << " GLONASS records)\n";
  printSummary(std::cerr, dec, path == "-" ? "<stdin>" : path);
  return 0;
}

}  // namespace gvins::rtcm_app
