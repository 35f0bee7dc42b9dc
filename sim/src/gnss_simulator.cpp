#include "gvins/sim/gnss_simulator.hpp"

#include <cmath>
#include <cstdio>
#include <memory>
#include <fstream>
#include <iomanip>
#include <ostream>
#include <set>
#include <stdexcept>

#include "gvins/base/constants.hpp"
#include "gvins/base/rinex_obs_writer.hpp"
#include "gvins/ephemeris/precise_ephemeris.hpp"
#include "gvins/ephemeris/ssr_from_products.hpp"
#include "gvins/rtcm/ssr_file.hpp"
#include "gvins/sim/gnss_epoch_generator.hpp"
#include "gvins/sim/gnss_precise_products.hpp"
#include "gvins/sim/gnss_rtcm_stream.hpp"
#include "gvins/sim/gnss_truth_writer.hpp"

namespace gvins::sim {

namespace {

RinexObsHeader makeHeader(const GnssSimConfig& cfg, const GnssReceiverConfig& rc, const GlonassChannels& channels,
                          const NavData& nav, const Eigen::Vector3d& approx, std::uint64_t seed, bool base) {
  RinexObsHeader h;
  h.version = 3.04;
  h.fileSystem = 'M';
  h.station.markerName = rc.markerName;
  h.station.markerNumber = base ? "SIMBASE" : "SIMROVER";
  h.station.receiverNumber = base ? "2" : "1";
  h.station.receiverType = rc.receiverType;
  h.station.receiverVersion = "1.0";
  h.station.antennaNumber = base ? "2" : "1";
  h.station.antennaType = rc.antennaType;
  h.station.approxPosition = approx;
  h.observer = "GVINS-SIM";
  h.agency = "SRI-GVINS";
  for (int s = 0; s < kNumSystems; ++s) {
    if (!cfg.systems[s]) continue;
    for (const ObsCode& c : cfg.signals[s]) {
      for (ObsType t : {ObsType::Code, ObsType::Phase, ObsType::Doppler, ObsType::Snr}) h.obsTypes[s].push_back({t, c});
      PhaseShiftRecord ps;
      ps.system = static_cast<System>(s);
      ps.obs = ObsDescriptor{ObsType::Phase, c};
      ps.cycles = 0.0;
      h.phaseShifts.push_back(ps);
    }
  }
  h.glonassChannels = channels;
  if (cfg.useSystem(System::Glonass)) {
    for (const char* d : {"C1C", "C1P", "C2C", "C2P"}) h.glonassBiases.push_back({*ObsDescriptor::parse(d), 0.0});
  }
  h.interval = 1.0 / rc.rate;
  h.leapSeconds = nav.leapSeconds;
  h.signalStrengthUnit = "DBHZ";
  h.comments = {"SIMULATED BY SRI-GVINS GVINS-SIM, SEED " + std::to_string(seed),
                "EPOCHS IN RECEIVER TIME: TRUE GPST = TAG - CLOCK BIAS",
                "PHASES ALIGNED WITH THE PSEUDORANGE WHEN LOCK STARTS",
                base ? "APPROX POSITION = TRUE ANTENNA PHASE CENTRE" : "APPROX POSITION = START, ROUNDED TO 1 M"};
  return h;
}

std::string fmtVec(const Eigen::Vector3d& v, int decimals) {
  char b[160];
  std::snprintf(b, sizeof b, "[%.*f, %.*f, %.*f]", decimals, v.x(), decimals, v.y(), decimals, v.z());
  return b;
}

/// Throws std::invalid_argument when no satellite has a usable ephemeris at the scenario start:
/// the observation files would not have a single epoch.
void requireEphemerisAtStart(const GnssSimWorld& world, const LocalFrame& frame,
                             const std::filesystem::path& navigationFile) {
  for (const SatId sat : world.store().satellites()) {
    if (world.store().satelliteState(sat, frame.startTime)) return;
  }
  throw std::invalid_argument("gnss.navigation " + navigationFile.string() +
                              ": no satellite has a usable ephemeris at the scenario start " +
                              frame.startTime.toString(0) + " GPST (start_gpst outside the navigation file)");
}

/// Creates dir/name and lists it in the summary's files.
std::ofstream openOutput(const std::filesystem::path& dir, const std::string& name, GnssSimSummary& sum) {
  std::ofstream f(dir / name, std::ios::binary);
  if (!f) throw std::runtime_error("cannot create " + (dir / name).string());
  sum.files.push_back(dir / name);
  return f;
}

/// The observation outputs: rover RINEX and, with a base, its RINEX and RTCM stream.
struct ObservationFiles {
  std::ofstream roverFile, baseFile, rtcmFile;
  std::unique_ptr<RinexObsWriter> roverWriter, baseWriter;
  std::unique_ptr<GnssRtcmStream> rtcm;
};

/// Writes every epoch of the generator (observations, RTCM, truth) and counts epochs, signals,
/// satellites and RTCM bytes into the summary; progress lines by tenths of the flight.
void recordEpochs(GnssEpochGenerator& gen, ObservationFiles& out, GnssTruthWriter& truth, std::ostream* progress,
                  GnssSimSummary& sum) {
  const GnssSimWorld& world = gen.world();
  std::array<std::set<int>, kNumSystems> roverSats, baseSats;
  std::array<std::int64_t, kNumSystems> roverSatEpochs{};
  std::vector<std::uint8_t> bytes;
  bool first = true;
  int lastPercent = -1;
  while (auto e = gen.next()) {
    truth.add(*e);
    if (e->role == GnssReceiverRole::Rover) {
      if (first) {
        sum.firstTag = e->obs.time;
        sum.baselineStart = (e->truth.antennaPosition - sum.basePosition).norm();
        first = false;
      }
      sum.lastTag = e->obs.time;
      if (e->obs.sats.empty()) {
        ++sum.roverEmptyEpochs;
      } else {
        out.roverWriter->write(e->obs);
        ++sum.roverEpochs;
      }
      for (const SatObs& so : e->obs.sats) {
        roverSats[systemIndex(so.sat.system)].insert(so.sat.prn);
        ++roverSatEpochs[systemIndex(so.sat.system)];
        sum.roverSignals += static_cast<std::int64_t>(so.signals.size());
      }
      if (progress) {
        const int pct = static_cast<int>(100.0 * (e->truth.time - world.start()) / std::max(world.duration(), 1e-9));
        if (pct / 10 != lastPercent / 10) {
          *progress << "gnss: " << pct << " % (" << sum.roverEpochs << " rover epochs)\n";
          lastPercent = pct;
        }
      }
    } else {
      if (!e->obs.sats.empty()) {
        out.baseWriter->write(e->obs);
        ++sum.baseEpochs;
      }
      for (const SatObs& so : e->obs.sats) baseSats[systemIndex(so.sat.system)].insert(so.sat.prn);
      bytes.clear();
      out.rtcm->addEpoch(e->obs, bytes);
      out.rtcmFile.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
      sum.rtcmBytes += static_cast<std::int64_t>(bytes.size());
    }
  }
  for (int s = 0; s < kNumSystems; ++s) {
    sum.roverSatellites[s] = static_cast<int>(roverSats[s].size());
    sum.baseSatellites[s] = static_cast<int>(baseSats[s].size());
    const std::int64_t n = sum.roverEpochs + sum.roverEmptyEpochs;
    sum.roverMeanSatellites[s] = n > 0 ? static_cast<double>(roverSatEpochs[s]) / static_cast<double>(n) : 0.0;
  }
}

/// Writes the ambiguity arcs, slips and event intervals of both receivers to the truth and
/// counts them into the summary.
void recordEvents(const GnssEpochGenerator& gen, GnssTruthWriter& truth, GnssSimSummary& sum) {
  std::vector<GnssAmbiguityArc> arcs = gen.rover().arcs();
  std::vector<GnssSlipEvent> slips = gen.rover().slips();
  std::vector<GnssEventInterval> events = gen.rover().events();
  if (gen.base()) {
    arcs.insert(arcs.end(), gen.base()->arcs().begin(), gen.base()->arcs().end());
    slips.insert(slips.end(), gen.base()->slips().begin(), gen.base()->slips().end());
    events.insert(events.end(), gen.base()->events().begin(), gen.base()->events().end());
  }
  truth.finish(arcs, slips, events);
  for (const GnssSlipEvent& s : slips) {
    if (s.role == GnssReceiverRole::Rover) {
      if (s.cause == "slip") {
        ++sum.roverSlips;
        if (!s.flagged) ++sum.roverUnflaggedSlips;
      } else {
        ++sum.roverRestarts;
      }
    } else {
      ++sum.baseSlips;
    }
  }
  for (const GnssEventInterval& ev : events) {
    if (ev.role != GnssReceiverRole::Rover) continue;
    if (ev.kind == "nlos") ++sum.nlosEvents;
    else if (ev.kind == "blockage") ++sum.blockages;
    else if (ev.kind == "outage") sum.outageSeconds += ev.end - ev.start;
  }
}

/// Precise orbit and clock products over the flight and, with an SSR interval, their real-time
/// counterpart: SSR corrections for the broadcast records (ssr.rtcm3).
void writeProducts(const GnssPreciseProductsConfig& cfg, const GnssSimWorld& world, std::uint64_t seed,
                   const std::filesystem::path& dir, GnssSimSummary& sum) {
  const GnssPreciseProducts products =
      makePreciseProducts(world.constellation(), cfg, world.start(), world.start() + world.duration(), seed);
  for (const auto& p : writePreciseProducts(products, dir)) sum.files.push_back(p);
  sum.preciseSatellites = products.orbits.satellites.size();
  if (!(cfg.ssrInterval > 0.0)) return;
  EphemerisStore productStore;
  auto precise = std::make_shared<PreciseEphemeris>();
  precise->add(products.orbits);
  precise->add(products.clocks);
  productStore.setPrecise(std::move(precise));
  if (products.antennas) productStore.setSatelliteAntennas(std::make_shared<AntexData>(*products.antennas));
  SsrServiceConfig service;
  service.interval = cfg.ssrInterval;
  const std::vector<SsrMessage> ssr =
      ssrFromProducts(world.store(), productStore, world.start(), world.start() + world.duration(), service);
  const std::vector<std::uint8_t> ssrBytes = rtcm::encodeSsrFrames(ssr);
  std::ofstream f = openOutput(dir, "ssr.rtcm3", sum);
  f.write(reinterpret_cast<const char*>(ssrBytes.data()), static_cast<std::streamsize>(ssrBytes.size()));
  if (!f) throw std::runtime_error("writing ssr.rtcm3 failed");
  sum.ssrMessages = static_cast<std::int64_t>(ssr.size());
}

void writeIsb(std::ostream& f, const GnssReceiverClock& clock) {
  const char* sep = "";
  for (System s : {System::Gps, System::Glonass, System::Galileo, System::BeiDou, System::Qzss}) {
    f << sep << systemLetter(s) << ": " << clock.isb(s);
    sep = ", ";
  }
}

/// truth/gnss_truth.yaml: the constants of the run (seed, times, origin, lever arm, receiver
/// clocks' inter-system biases, base position, atmosphere scales, RTCM settings).
void writeTruthConstants(const GnssSimConfig& config, const GnssEpochGenerator& gen, const LocalFrame& frame,
                         const Eigen::Vector3d& leverArmBody, std::uint64_t seed, const std::filesystem::path& path,
                         GnssSimSummary& sum) {
  const GnssSimWorld& world = gen.world();
  const bool withBase = gen.base() != nullptr;
  std::ofstream f(path, std::ios::binary);
  if (!f) throw std::runtime_error("cannot create " + path.string());
  sum.files.push_back(path);
  const Geodetic bl = ecefToGeodetic(sum.basePosition);
  f << std::setprecision(12);
  f << "# GNSS truth of a gvins-sim run (docs/dataset_format.md, gnss/)\n";
  f << "seed: " << seed << "\n";
  f << "time_tags: receiver  # RINEX epochs are receiver time; true GPST = tag - clock bias (truth/*_clock.csv)\n";
  f << "start_gpst: \"" << world.start().toString(3) << "\"\n";
  f << "duration_s: " << world.duration() << "\n";
  f << "origin_llh_deg: [" << frame.origin.lat * constants::kRadToDeg << ", " << frame.origin.lon * constants::kRadToDeg
    << ", " << frame.origin.height << "]\n";
  f << "lever_arm_body_m: " << fmtVec(leverArmBody, 4) << "  # antenna phase centre in the IMU (body) frame\n";
  f << "rover:\n  rate_hz: " << config.rover.rate << "\n  isb_s: {";
  writeIsb(f, gen.rover().clock());
  f << "}  # clock of system = bias + isb\n";
  f << "base:\n  enabled: " << (withBase ? "true" : "false") << "\n";
  f << "  ecef_m: " << fmtVec(sum.basePosition, 4) << "  # antenna phase centre (= RINEX APPROX POSITION)\n";
  f << "  llh_deg: [" << std::setprecision(12) << bl.lat * constants::kRadToDeg << ", " << bl.lon * constants::kRadToDeg
    << ", " << bl.height << "]\n";
  if (withBase) {
    f << "  rate_hz: " << config.base.receiver.rate << "\n  isb_s: {";
    writeIsb(f, gen.base()->clock());
    f << "}\n";
  }
  const GnssAtmosphere& atm = world.atmosphere();
  f << "troposphere: {hydrostatic_scale: " << atm.hydrostaticScale() << ", wet_scale: " << atm.wetScale()
    << "}  # true zenith delays / Saastamoinen model\n";
  f << "ionosphere: {klobuchar_scale: " << atm.ionosphereScale() << "}  # before the residual fields\n";
  f << "rtcm: {msm: " << config.rtcm.msm << ", station_id: " << config.rtcm.stationId << "}\n";
  if (!f) throw std::runtime_error("writing " + path.string() + " failed");
}

}  // namespace

GnssSimulator::GnssSimulator(GnssSimConfig config) : config_(std::move(config)) {}

GnssSimSummary GnssSimulator::run(const Trajectory& trajectory, const LocalFrame& frame,
                                  const Eigen::Vector3d& leverArmBody, std::uint64_t seed,
                                  const std::filesystem::path& datasetDir) const {
  if (config_.navigationFile.empty()) throw std::invalid_argument("gnss.navigation: no navigation file configured");
  const NavData nav = readRinexNav(config_.navigationFile.string());
  return run(nav, trajectory, frame, leverArmBody, seed, datasetDir);
}

GnssSimSummary GnssSimulator::run(const NavData& nav, const Trajectory& trajectory, const LocalFrame& frame,
                                  const Eigen::Vector3d& leverArmBody, std::uint64_t seed,
                                  const std::filesystem::path& datasetDir) const {
  const std::filesystem::path dir = datasetDir / "gnss";
  std::filesystem::create_directories(dir);
  GnssEpochGenerator gen(config_, nav, trajectory, frame, leverArmBody, seed);
  if (pathModel_) gen.setRoverPathModel(pathModel_);
  const GnssSimWorld& world = gen.world();
  requireEphemerisAtStart(world, frame, config_.navigationFile);
  const bool withBase = gen.base() != nullptr;

  GnssSimSummary sum;
  sum.roverRate = config_.rover.rate;
  sum.baseRate = withBase ? config_.base.receiver.rate : 0.0;
  sum.basePosition = gen.basePosition();

  // Rover approximate position: the start, rounded to 1 m (a receiver's header value is rough).
  const GnssAntennaMotion motion = trajectoryAntennaMotion(trajectory, frame, leverArmBody);
  Eigen::Vector3d approx = motion(frame.startTime).position;
  for (int i = 0; i < 3; ++i) approx[i] = std::round(approx[i]);
  const GlonassChannels& channels = world.constellation().glonassChannels();

  ObservationFiles out;
  out.roverFile = openOutput(dir, "rover.obs", sum);
  out.roverWriter = std::make_unique<RinexObsWriter>(
      out.roverFile, makeHeader(config_, config_.rover, channels, nav, approx, seed, false));
  if (withBase) {
    out.baseFile = openOutput(dir, "base.obs", sum);
    out.baseWriter = std::make_unique<RinexObsWriter>(
        out.baseFile, makeHeader(config_, config_.base.receiver, channels, nav, sum.basePosition, seed, true));
    out.rtcmFile = openOutput(dir, "base.rtcm3", sum);
    out.rtcm = std::make_unique<GnssRtcmStream>(config_.rtcm, world.store(), sum.basePosition, channels);
  }
  GnssTruthWriter truth(dir / "truth", withBase, config_.writeErrorTerms);

  recordEpochs(gen, out, truth, progress_, sum);
  gen.finish();
  out.roverWriter->finish();
  if (out.baseWriter) out.baseWriter->finish();
  if (!out.roverFile || (withBase && (!out.baseFile || !out.rtcmFile)))
    throw std::runtime_error("writing " + dir.string() + " failed");
  recordEvents(gen, truth, sum);
  if (out.rtcm) sum.rtcmMessages = out.rtcm->messageCounts();

  {
    std::ofstream f = openOutput(dir, "nav.rnx", sum);
    writeRinexNav(f, nav, "SRI-GVINS gvins-sim");
    if (!f) throw std::runtime_error("writing nav.rnx failed");
  }
  if (config_.preciseProducts.write) writeProducts(config_.preciseProducts, world, seed, dir, sum);
  writeTruthConstants(config_, gen, frame, leverArmBody, seed, dir / "truth" / "gnss_truth.yaml", sum);
  return sum;
}

void GnssSimSummary::print(std::ostream& os) const {
  char line[256];
  os << "GNSS: rover " << roverRate << " Hz";
  if (baseRate > 0.0) {
    std::snprintf(line, sizeof line, ", base %.3g Hz at %.0f m", baseRate, baselineStart);
    os << line;
  }
  os << ", " << firstTag.toString(1) << " - " << lastTag.toString(1) << " (receiver time)\n";
  os << "  system   rover sats  mean/epoch  base sats\n";
  for (System s : {System::Gps, System::Glonass, System::Galileo, System::BeiDou, System::Qzss}) {
    const int i = systemIndex(s);
    if (roverSatellites[i] == 0 && baseSatellites[i] == 0) continue;
    std::snprintf(line, sizeof line, "  %-8s %10d  %10.1f  %9d\n", std::string(systemName(s)).c_str(),
                  roverSatellites[i], roverMeanSatellites[i], baseSatellites[i]);
    os << line;
  }
  std::snprintf(line, sizeof line,
                "  rover: %lld epochs (%lld without signals), %lld signals, %d slips (%d unflagged), %d restarts, "
                "%d NLOS, %d blockages, outages %.1f s\n",
                static_cast<long long>(roverEpochs), static_cast<long long>(roverEmptyEpochs),
                static_cast<long long>(roverSignals), roverSlips, roverUnflaggedSlips, roverRestarts, nlosEvents,
                blockages, outageSeconds);
  os << line;
  if (baseRate > 0.0) {
    std::snprintf(line, sizeof line, "  base: %lld epochs, %d slips/restarts; RTCM %lld bytes:", static_cast<long long>(baseEpochs),
                  baseSlips, static_cast<long long>(rtcmBytes));
    os << line;
    for (const auto& [type, n] : rtcmMessages) os << " " << type << "x" << n;
    os << "\n";
  }
  if (preciseSatellites > 0)
    os << "  precise products: precise.sp3, precise.clk (" << preciseSatellites << " satellites)\n";
  if (ssrMessages > 0) os << "  SSR corrections:  ssr.rtcm3 (" << ssrMessages << " combined orbit/clock messages)\n";
}

}  // namespace gvins::sim
