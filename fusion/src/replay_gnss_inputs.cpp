// GNSS inputs of the replay (replay_stages.hpp): rover, base, navigation data, precise products
// and SSR corrections.
#include <algorithm>
#include <cctype>
#include <cstdio>

#include "gvins/base/parse_error.hpp"
#include "gvins/base/rinex_obs_reader.hpp"
#include "gvins/ephemeris/precise_product_files.hpp"
#include "gvins/ephemeris/rinex_nav.hpp"
#include "gvins/rtcm/ssr_file.hpp"
#include "replay_stages.hpp"

namespace gvins::fusion::detail {

namespace fs = std::filesystem;

namespace {

// Precise products in a dataset's gnss folder (preciseFileKind: *.sp3, *.clk, *.atx, *.bia, also
// gzipped or upper case), each list sorted by name (consecutive days).
PreciseProductFiles findPreciseProducts(const fs::path& dir) {
  PreciseProductFiles p;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    if (e.is_regular_file()) p.add(e.path().string());
  }
  for (auto* list : {&p.orbits, &p.clocks, &p.antennas, &p.biases}) std::sort(list->begin(), list->end());
  return p;
}

/// The navigation file of a gvins-sim gnss/ folder: the first regular file that is neither an
/// observation file nor the RTCM stream.
std::string findNavFile(const fs::path& dir) {
  std::vector<fs::path> c;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    if (!e.is_regular_file()) continue;
    const std::string n = e.path().filename().string();
    if (n == "rover.obs" || n == "base.obs" || n.find(".rtcm") != std::string::npos) continue;
    std::string lower = n;
    for (char& ch : lower) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    const bool navLike = lower.find("nav") != std::string::npos || lower.ends_with(".rnx") ||
                         (lower.size() > 3 && lower[lower.size() - 4] == '.' && (lower.back() == 'n' || lower.back() == 'p' || lower.back() == 'g'));
    if (navLike) c.push_back(e.path());
  }
  std::sort(c.begin(), c.end());
  return c.empty() ? std::string() : c.front().string();
}

}  // namespace

void GnssInputs::open(const std::string& dataset, const ReplayOptions& opt, ReplayGnss& gnss, ReplaySummary& sum) {
  const fs::path gdir = fs::path(dataset) / "gnss";
  const std::string roverPath = !opt.roverObs.empty() ? opt.roverObs : (gdir / "rover.obs").string();
  const std::string basePath = !opt.baseObs.empty() ? opt.baseObs : (gdir / "base.obs").string();
  loadNavigation(gdir, roverPath, basePath, opt);
  if (!opt.broadcastOnly) loadPreciseProducts(gdir, opt, sum);
  rover = BaseReader::open(roverPath, GpsTime{}, &nav, true);
  haveRover = rover->next(nextRover);
  loadSsr(opt, sum);
  // Float PPP on broadcast orbits and clocks: their errors drift and jump with the records, which
  // the millimetre phase rows cannot absorb (docs/gnss_fusion.md, "Float PPP").
  if (opt.modeName == "vio+dopp+ppp" && !nav.precise() && opt.ssrFiles.empty()) {
    std::fprintf(stderr, "[gvins-replay] warning: vio+dopp+ppp without precise products or an SSR stream: the "
                         "broadcast orbit/clock errors limit it (simulated flights: 0.70 m against 0.58 m with "
                         "vio+dopp+psr)\n");
  }
  // Products of another day than the observations: every state would silently be broadcast.
  if (const PreciseEphemeris* p = nav.precise(); p && haveRover) {
    const auto [first, last] = p->span();
    if (nextRover.time < first || last < nextRover.time) {
      std::fprintf(stderr, "[gvins-replay] warning: the precise products cover %s to %s GPST, the rover starts at %s: "
                           "broadcast orbits and clocks are used where they do not reach\n",
                   first.toString(0).c_str(), last.toString(0).c_str(), nextRover.time.toString(0).c_str());
    }
  }
  if (fs::exists(basePath)) openBase(basePath, opt, gnss);
}

void GnssInputs::loadNavigation(const fs::path& gdir, const std::string& roverPath, const std::string& basePath,
                                const ReplayOptions& opt) {
  const std::string navPath = !opt.navFile.empty() ? opt.navFile : findNavFile(gdir);
  if (!fs::exists(roverPath)) throw ParseError(roverPath, 0, "rover", "GNSS mode needs the rover observation file");
  // A UBX rover or base brings its own ephemerides (RXM-SFRBX, added as they are read).
  const auto roverFormat = BaseReader::detect(roverPath);
  if (roverFormat == BaseFormat::Rtcm) {
    throw ParseError(roverPath, 0, "rover", "an RTCM 3 rover log needs a date: convert it with gvins-rtcm to-rinex first");
  }
  const bool ubxNav = roverFormat == BaseFormat::Ubx || (fs::exists(basePath) && BaseReader::detect(basePath) == BaseFormat::Ubx);
  if (navPath.empty() && !ubxNav) {
    throw ParseError(gdir.string(), 0, "navigation", "no navigation file in the gnss folder (use --nav)");
  }
  if (!navPath.empty()) nav.add(readRinexNav(navPath));
}

void GnssInputs::loadPreciseProducts(const fs::path& gdir, const ReplayOptions& opt, ReplaySummary& sum) {
  // The folder's files where none were given (an --atx / --bia file replaces the folder's).
  PreciseProductFiles found;
  if (opt.sp3Files.empty() && opt.clockFiles.empty()) {
    found = findPreciseProducts(gdir);
    if (!opt.folderProducts) {
      sum.folderProductsSkipped = !found.orbits.empty() || !found.clocks.empty();
      found = PreciseProductFiles{};
    }
  }
  const std::vector<std::string>& sp3 = opt.sp3Files.empty() ? found.orbits : opt.sp3Files;
  const std::vector<std::string>& clk = opt.clockFiles.empty() ? found.clocks : opt.clockFiles;
  const std::vector<std::string>& atx = opt.antennaFiles.empty() ? found.antennas : opt.antennaFiles;
  const std::vector<std::string>& bia = opt.biasFiles.empty() ? found.biases : opt.biasFiles;
  if (!sp3.empty()) {
    auto precise = gvins::readPreciseProducts(sp3, clk);
    sum.preciseSatellites = precise->satellites().size();
    nav.setPrecise(std::move(precise));
    if (!atx.empty()) {
      auto antex = readAntennaFiles(atx);
      for (const AntexAntenna& a : antex->antennas) sum.antexAntennas += a.isSatellite();
      nav.setSatelliteAntennas(std::move(antex));
    }
    if (!bia.empty()) {
      auto biases = readCodeBiasFiles(bia);
      sum.codeBiases = biases->entries.size();
      nav.setCodeBiases(std::move(biases));
    }
  } else if (!clk.empty()) {
    throw ParseError(clk.front(), 0, "precise clock", "clock files need an SP3 orbit file (use --sp3)");
  }
}

void GnssInputs::loadSsr(const ReplayOptions& opt, ReplaySummary& sum) {
  // SSR corrections of recorded correction streams; their times of week resolve against the rover.
  for (const std::string& f : opt.ssrFiles) {
    const rtcm::SsrFile ssr = rtcm::readSsrFile(f, haveRover ? nextRover.time : GpsTime{});
    for (const SsrMessage& m : ssr.messages) nav.addSsr(m);
    sum.ssrMessages += ssr.messages.size();
    if (ssr.messages.empty())
      std::fprintf(stderr, "[gvins-replay] warning: %s holds no SSR message\n", f.c_str());
    if (ssr.stats.malformed > 0)
      std::fprintf(stderr, "[gvins-replay] warning: %s: %lld malformed RTCM frames skipped\n", f.c_str(),
                   static_cast<long long>(ssr.stats.malformed));
  }
}

void GnssInputs::openBase(const std::string& basePath, const ReplayOptions& opt, ReplayGnss& gnss) {
  // RINEX (header position + antenna delta) or RTCM 3 (1005/1006, possibly only after some
  // epochs; its ephemerides join the store); RTCM times of week resolve against the rover.
  const GpsTime ref = haveRover ? nextRover.time : GpsTime{};
  base = BaseReader::open(basePath, ref, &nav, true);
  if (opt.basePosition) {
    gnss.setBasePosition(*opt.basePosition);
    basePositionSet = true;
  }
  haveBase = base->next(nextBase);
  if (!basePositionSet) {
    const auto p = base->antennaPosition();
    if (p && p->norm() > 1e6) {
      gnss.setBasePosition(*p);
      basePositionSet = true;
    } else if (base->format() == BaseFormat::Rinex) {
      throw ParseError(basePath, 0, "APPROX POSITION XYZ", "base position missing in the header (use --base-position)");
    }
  }
}

void GnssInputs::advanceBase() {
  while (haveBase && nextBase.time <= nextRover.time) {
    std::swap(currentBase, nextBase);
    haveCurrentBase = true;
    haveBase = base->next(nextBase);
  }
}

void GnssInputs::updateBasePosition(ReplayGnss& gnss) {
  if (basePositionSet || !base) return;
  const auto p = base->antennaPosition();
  if (p && p->norm() > 1e6) {
    gnss.setBasePosition(*p);
    basePositionSet = true;
  }
}

void GnssInputs::reportSkipped() const {
  if (rover && rover->rinexStats() && rover->rinexStats()->skippedEpochs > 0) {
    // Malformed or out-of-order rover epochs were skipped: say which (file:line: reason).
    const RinexObsReaderStats& rs = *rover->rinexStats();
    std::fprintf(stderr, "[gvins-replay] warning: %lld rover epochs skipped (%lld out of order or repeated):\n",
                 static_cast<long long>(rs.skippedEpochs), static_cast<long long>(rs.outOfOrderEpochs));
    for (const std::string& m : rs.messages) std::fprintf(stderr, "  %s\n", m.c_str());
  }
  if (rover && !rover->rinexStats() && rover->skipped() > 0) {
    std::fprintf(stderr, "[gvins-replay] warning: rover %s: %lld malformed messages skipped\n", rover->describe().c_str(),
                 static_cast<long long>(rover->skipped()));
  }
}

}  // namespace gvins::fusion::detail
