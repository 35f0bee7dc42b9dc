#include "gvins/fusion/replay_pipeline.hpp"

#include <algorithm>
#include <atomic>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cinttypes>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <mutex>
#include <sstream>
#include <thread>

#include <sys/resource.h>

#include "gvins/base/geodetic.hpp"
#include "gvins/base/line_reader.hpp"
#include "gvins/base/local_frame.hpp"
#include "gvins/base/text_fields.hpp"
#include "gvins/base/parse_error.hpp"
#include "gvins/base/rinex_obs_reader.hpp"
#include "gvins/ephemeris/ephemeris_store.hpp"
#include "gvins/ephemeris/precise_product_files.hpp"
#include "gvins/ephemeris/rinex_nav.hpp"
#include "gvins/fusion/replay_feature_tracks.hpp"
#include "gvins/gnss/base_reader.hpp"
#include "gvins/gnss/kml_writer.hpp"
#include "gvins/gnss/nmea_writer.hpp"
#include "gvins/gnss/pos_writer.hpp"
#include "gvins/rtcm/ssr_file.hpp"
#include "gvins/vio/camera_model.hpp"
#include "gvins/vio/euroc_dataset.hpp"
#include "gvins/vio/frontend_thread.hpp"
#include "gvins/vio/trajectory_metrics.hpp"
#include "gvins/vio/tum_trajectory.hpp"

namespace gvins::fusion {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

double msSince(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

GpsTime gpsFromNs(std::int64_t t_ns) {
  return GpsTime::fromSeconds(t_ns / 1'000'000'000, static_cast<double>(t_ns % 1'000'000'000) * 1e-9);
}

class OutFile {
 public:
  explicit OutFile(const fs::path& p) : path_(p.string()), f_(p, std::ios::binary) {
    if (!f_) throw std::runtime_error("cannot create output file " + path_);
  }
  std::ofstream& out() { return f_; }
  void close() {
    f_.close();
    if (!f_) throw std::runtime_error("error writing output file " + path_);
  }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::ofstream f_;
};

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

struct GnssInputs {
  std::unique_ptr<BaseReader> rover;  // RINEX or a u-blox UBX log
  std::unique_ptr<BaseReader> base;   // RINEX, an RTCM 3 log or a UBX log
  bool basePositionSet = false;
  EphemerisStore nav;
  ObsEpoch nextRover, nextBase, currentBase;
  bool haveRover = false, haveBase = false, haveCurrentBase = false;
};

void writeKml(const fs::path& path, const std::vector<Geodetic>& pts, const std::string& name) {
  OutFile f(path);
  writeKmlTrack(f.out(), pts, name);
  f.close();
}

}  // namespace

namespace {
std::vector<EcefTruthSample> parseEcefTruth(LineReader& r) {
  std::vector<EcefTruthSample> out;
  std::string line;
  while (r.next(line)) {
    std::string_view l = line;
    if (!l.empty() && l.back() == '\r') l.remove_suffix(1);
    const std::string_view t = trim(l);
    if (t.empty() || t.front() == '#') continue;
    const TextLocation where = r.location();
    std::vector<std::string_view> f;
    std::size_t start = 0;
    for (;;) {
      const std::size_t c = l.find(',', start);
      f.push_back(trim(l.substr(start, c == std::string_view::npos ? std::string_view::npos : c - start)));
      if (c == std::string_view::npos) break;
      start = c + 1;
    }
    if (f.size() < 14)
      throwParseError(where, f.size() < 12 ? "line" : (f.size() == 12 ? "antenna_E_y" : "antenna_E_z"),
                      "expected at least 14 fields (antenna position in columns 12-14), found " + std::to_string(f.size()));
    EcefTruthSample s;
    {
      const std::string_view st = f[0];
      const auto res = std::from_chars(st.data(), st.data() + st.size(), s.t_ns);
      if (st.empty() || res.ec != std::errc() || res.ptr != st.data() + st.size() || s.t_ns < 0)
        throwParseError(where, "timestamp", "not a non-negative integer nanosecond stamp: '" + std::string(st) + "'");
    }
    s.antenna = {parseDouble(f[11], where, "antenna_E_x"), parseDouble(f[12], where, "antenna_E_y"),
                 parseDouble(f[13], where, "antenna_E_z")};
    if (!s.antenna.allFinite()) throwParseError(where, "antenna_E_x", "antenna position is not finite");
    if (f.size() >= 17) {
      const Eigen::Vector3d v(parseDouble(f[14], where, "antenna_v_E_x"), parseDouble(f[15], where, "antenna_v_E_y"),
                              parseDouble(f[16], where, "antenna_v_E_z"));
      if (!v.allFinite()) throwParseError(where, "antenna_v_E_x", "antenna velocity is not finite");
      s.antennaVelocity = v;
    }
    if (!out.empty() && s.t_ns <= out.back().t_ns)
      throwParseError(where, "timestamp", "time stamps must increase strictly");
    out.push_back(s);
  }
  return out;
}
}  // namespace

std::vector<EcefTruthSample> ecefTruthFromPos(const PosFile& pos, int maxQuality, std::int64_t sensorToGpst_ns) {
  std::vector<EcefTruthSample> out;
  for (const PositionSolution& s : pos.solutions) {
    const int q = static_cast<int>(s.quality);
    if (q < 1 || q > maxQuality) continue;
    EcefTruthSample x;
    x.t_ns = s.time.wholeSeconds() * 1'000'000'000 + static_cast<std::int64_t>(std::llround(s.time.fraction() * 1e9)) -
             sensorToGpst_ns;
    x.antenna = s.position;
    x.antennaVelocity = s.velocity;
    if (!out.empty() && x.t_ns <= out.back().t_ns) continue;
    out.push_back(x);
  }
  return out;
}

std::vector<EcefTruthSample> readEcefTruthCsv(const std::string& path) {
  LineReader r(path, 16384);
  return parseEcefTruth(r);
}

std::vector<EcefTruthSample> parseEcefTruthCsv(std::string_view text, const std::string& name) {
  LineReader r(text, name, 16384);
  return parseEcefTruth(r);
}

namespace {
ReplaySummary::Accuracy accuracyOf(const vio::EvaluationResult& r) {
  ReplaySummary::Accuracy a;
  a.poses = r.matched;
  a.positionRmse = r.translation.rmse;
  a.rotationRmseDeg = r.rotation.rmse;
  if (r.velocity.count > 0) a.velocityRmse = r.velocity.rmse;
  if (r.bodyVelocity.count > 0) a.bodyVelocityRmse = r.bodyVelocity.rmse;
  a.pathLength = r.pathLength;
  for (const auto& seg : r.segments)
    if (seg.count > 0) a.driftPercent = seg.driftPercent;
  if (r.neesCount > 0) {
    a.positionNees = r.positionNees;
    a.orientationNees = r.orientationNees;
  }
  double h = 0.0, v = 0.0;
  for (std::size_t i = 0; i < r.reference.size(); ++i) {
    const Eigen::Vector3d e = r.estimateAligned[i] - r.reference[i];
    h += e.head<2>().squaredNorm();
    v += e.z() * e.z();
  }
  const double m = static_cast<double>(std::max<std::size_t>(r.reference.size(), 1));
  a.horizontalRmse = std::sqrt(h / m);
  a.verticalRmse = std::sqrt(v / m);
  return a;
}
}  // namespace

void ReplaySummary::writeMetrics(std::ostream& os) const {
  auto kv = [&](const char* k, double v) {
    char b[96];
    std::snprintf(b, sizeof b, "%s,%.6g\n", k, v);
    os << b;
  };
  os << "# gvins-replay figures: key,value (NaN: not evaluated); docs/replay.md\n";
  kv("frames", static_cast<double>(framesProcessed));
  kv("frames_initialized", static_cast<double>(framesInitialized));
  kv("vio_resets", static_cast<double>(estimatorResets));
  kv("dataset_s", datasetSeconds);
  kv("wall_s", wallSeconds);
  kv("cpu_s", cpuSeconds);
  kv("real_time_factor", realTimeFactor());
  kv("frontend_ms_mean", frontendMsMean);
  kv("estimator_ms_mean", estimatorMsMean);
  kv("init_s", initSeconds);
  kv("estimator_ms_mean_before_init", estimatorMsBeforeInit);
  kv("estimator_ms_mean_after_init", estimatorMsAfterInit);
  kv("estimator_ms_median", estimatorMsMedian);
  kv("gnss_ms_per_epoch", gnssMsMean);
  kv("gnss_ms_per_frame", gnssMsPerFrame);
  kv("gnss_epochs", static_cast<double>(gnssEpochs));
  kv("gnss_epochs_updated", static_cast<double>(gnssEpochsUpdated));
  kv("gnss_epochs_fixed", static_cast<double>(gnssEpochsFixed));
  kv("precise_satellites", static_cast<double>(preciseSatellites));
  kv("antex_satellite_antennas", static_cast<double>(antexAntennas));
  kv("code_biases", static_cast<double>(codeBiases));
  kv("ssr_messages", static_cast<double>(ssrMessages));
  kv("phase_rows_used", static_cast<double>(phaseRowsUsed));
  kv("phase_rows_rejected", static_cast<double>(phaseRowsRejected));
  kv("ambiguity_states_max", static_cast<double>(ambiguityStatesMax));
  kv("broadcast_record_changes", static_cast<double>(recordChanges));
  kv("frame_init_s", frameInitSeconds);
  kv("enu_move_s", enuMoveSeconds);
  auto acc = [&](const std::string& p, const Accuracy& a) {
    kv((p + "position_rmse_m").c_str(), a.positionRmse);
    kv((p + "horizontal_rmse_m").c_str(), a.horizontalRmse);
    kv((p + "vertical_rmse_m").c_str(), a.verticalRmse);
    kv((p + "rotation_rmse_deg").c_str(), a.rotationRmseDeg);
    kv((p + "velocity_rmse_mps").c_str(), a.velocityRmse);
    kv((p + "body_velocity_rmse_mps").c_str(), a.bodyVelocityRmse);
    kv((p + "start_aligned_position_rmse_m").c_str(), a.startAlignedPositionRmse);
    kv((p + "path_m").c_str(), a.pathLength);
    kv((p + "drift_percent").c_str(), a.driftPercent);
    kv((p + "position_nees").c_str(), a.positionNees);
    kv((p + "orientation_nees").c_str(), a.orientationNees);
    kv((p + "position_nees_first_pose").c_str(), a.positionNeesFirstPose);
    kv((p + "orientation_nees_first_pose").c_str(), a.orientationNeesFirstPose);
    kv((p + "poses").c_str(), static_cast<double>(a.poses));
  };
  acc("local_", local);
  acc("global_", global);
  const Eigen::Vector3d nan = Eigen::Vector3d::Constant(kNaN);
  const Eigen::Vector3d l = leverArm.value_or(nan);
  kv("lever_arm_x_m", l.x());
  kv("lever_arm_y_m", l.y());
  kv("lever_arm_z_m", l.z());
  kv("lever_arm_error_m", leverArm && leverArmTruth ? (*leverArm - *leverArmTruth).norm() : kNaN);
  kv("time_offset_ms", timeOffset ? *timeOffset * 1e3 : kNaN);
  kv("time_offset_sigma_ms", timeOffsetSigma ? *timeOffsetSigma * 1e3 : kNaN);
  kv("time_offset_error_ms", timeOffset && timeOffsetTruth ? (*timeOffset - *timeOffsetTruth) * 1e3 : kNaN);
}

void ReplaySummary::print(std::ostream& os) const {
  char b[200];
  os << "------------------------------------------------------------\n";
  auto row = [&](const char* k, const std::string& v) {
    std::snprintf(b, sizeof b, "%-30s %s\n", k, v.c_str());
    os << b;
  };
  auto f = [&](const char* fmt, double v) {
    std::snprintf(b, sizeof b, fmt, v);
    return std::string(b);
  };
  row("camera input", cameraLess ? "none (camera-less: IMU and GNSS)" : featureTracks ? "simulated feature tracks" : "images (front end thread)");
  row("frames", std::to_string(framesProcessed) + " processed of " + std::to_string(frames) + ", " +
                    std::to_string(framesInitialized) + " initialised, " + std::to_string(framesUpdated) + " with visual update" +
                    (estimatorResets ? ", " + std::to_string(estimatorResets) + " VIO resets (lock-out)" : std::string()));
  row("IMU samples", std::to_string(imuSamples));
  row("skipped frames", std::to_string(skippedBadImages) + " unreadable images, " + std::to_string(skippedMissingImages) +
                            " missing images");
  row("IMU gaps", std::to_string(imuGaps) + " (largest " + f("%.3f", largestImuGap_s) + " s)");
  row("front end [ms/frame]", f("mean %.2f", frontendMsMean) + f(", max %.2f", frontendMsMax));
  row("estimator [ms/frame]", f("mean %.2f", estimatorMsMean) + f(", median %.2f", estimatorMsMedian) +
                                   f(", max %.2f", estimatorMsMax));
  if (!framesWaitingBy.empty()) {
    std::string w = f("%.2f s to initialise", initSeconds) + f(" (%.2f ms/frame before, ", estimatorMsBeforeInit) +
                    f("%.2f after); waiting: ", estimatorMsAfterInit);
    for (const auto& [why, count] : framesWaitingBy)
      w += std::string(vio::initStatusText(why)) + " " + std::to_string(count) + ", ";
    char k[32];
    std::snprintf(k, sizeof k, "%-30s ", "initialisation");
    os << k << w.substr(0, w.size() - 2) << '\n';
  }
  if (!gnssEpochsWaitingBy.empty()) {
    std::string w;
    for (const auto& [why, count] : gnssEpochsWaitingBy) w += why + " " + std::to_string(count) + ", ";
    row("GNSS/INS start waiting", w.substr(0, w.size() - 2) + " (epochs)");
  }
  if (gnssEpochs + gnssEpochsSkipped > 0) {
    row("GNSS epochs", std::to_string(gnssEpochs) + " processed (" + std::to_string(gnssEpochsUpdated) + " updated, " +
                           std::to_string(gnssEpochsFixed) + " RTK fixed), " + std::to_string(gnssEpochsSkipped) +
                           " before VIO initialisation" +
                           (gnssEpochsInOutage ? ", " + std::to_string(gnssEpochsInOutage) + " in simulated outages" : ""));
    row("GNSS [ms/epoch]", f("mean %.3f", gnssMsMean) + f(" (%.3f ms per frame)", gnssMsPerFrame));
    std::string products = "broadcast";
    if (folderProductsSkipped)
      products += " (differential rows cancel the orbit/clock errors; the folder's precise products were not read, "
                  "--sp3/--clk to use them)";
    if (preciseSatellites > 0) {
      products = "precise products, " + std::to_string(preciseSatellites) + " satellites";
      if (antexAntennas > 0) products += ", ANTEX " + std::to_string(antexAntennas) + " satellite antennas";
      if (codeBiases > 0) products += ", " + std::to_string(codeBiases) + " code biases";
    }
    if (ssrMessages > 0) products += std::string(preciseSatellites > 0 ? "; where they do not cover: " : " + ") +
                                     "SSR corrections (" + std::to_string(ssrMessages) + " messages)";
    row("orbits/clocks", products);
    if (phaseRowsUsed + phaseRowsRejected > 0)
      row("carrier phase (PPP)", std::to_string(phaseRowsUsed) + " rows used, " + std::to_string(phaseRowsRejected) +
                                     " gated out; up to " + std::to_string(ambiguityStatesMax) + " ambiguity states" +
                                     (recordChanges > 0 ? "; " + std::to_string(recordChanges) + " broadcast record changes carried over" : ""));
    if (std::isfinite(frameInitSeconds)) row("frame initialised", f("%.1f s after the first frame", frameInitSeconds));
    if (std::isfinite(enuMoveSeconds)) row("estimator in ENU", f("%.1f s after the first frame", enuMoveSeconds));
  }
  if (leverArm) {
    std::string t = f("%.3f", leverArm->x()) + f(" %.3f", leverArm->y()) + f(" %.3f m", leverArm->z());
    if (leverArmTruth) t += f(" (error %.3f m)", (*leverArm - *leverArmTruth).norm());
    row("lever arm", t);
  }
  if (timeOffset) {
    std::string t = f("%.3f ms", *timeOffset * 1e3) + f(" (sigma %.3f ms", timeOffsetSigma.value_or(0.0) * 1e3);
    if (timeOffsetTruth) t += f(", error %.3f ms", (*timeOffset - *timeOffsetTruth) * 1e3);
    row("camera-IMU time offset", t + ")");
  }
  row("dataset / wall / CPU time [s]", f("%.2f", datasetSeconds) + f(" / %.2f", wallSeconds) + f(" / %.2f", cpuSeconds));
  row("real-time factor", f("%.2fx", realTimeFactor()));
  os << "------------------------------------------------------------\n";
  if (!evaluationTable.empty()) os << "accuracy against the dataset ground truth (4-DoF aligned):\n" << evaluationTable;
  if (!globalEvaluationTable.empty())
    os << "GNSS antenna (global.pos) against the true antenna track, ENU, no alignment:\n" << globalEvaluationTable;
}

ReplaySummary runReplay(const std::string& dataset, ReplayEstimator& est, ReplayGnss* gnss, const ReplayOptions& opt) {
  const auto wall0 = Clock::now();
  ReplaySummary sum;
  if (opt.outDir.empty()) throw std::invalid_argument("runReplay: no output folder");
  std::error_code ec;
  fs::create_directories(opt.outDir, ec);
  if (!fs::is_directory(opt.outDir)) throw std::runtime_error("cannot create output folder " + opt.outDir);
  const fs::path out(opt.outDir);

  fs::path mav0 = fs::path(dataset) / "mav0";
  if (!fs::is_directory(mav0)) mav0 = fs::path(dataset);
  const bool tracks = opt.useFeatureTracks && fs::exists(mav0 / "cam0" / "features.csv");
  vio::EurocOptions eo;
  eo.checkImageFiles = !tracks;
  eo.skipMissingImages = opt.skipMissingImages;
  eo.requireCamera = false;
  const vio::EurocDataset ds(dataset, eo);
  sum.featureTracks = tracks;
  sum.skippedMissingImages = ds.report().missingImages[0] + ds.report().missingImages[1];
  const auto& imu = ds.imu();
  if (imu.size() < 2) throw ParseError((mav0 / "imu0" / "data.csv").string(), 0, "imu0", "fewer than 2 IMU samples");

  // Frame range. A camera-less rig (no cam0 folder) gets frames without features at
  // cameraLessRate_hz over the IMU log: the estimator's clones, IMU propagation and GNSS rows
  // run as with a camera that sees nothing.
  sum.cameraLess = ds.cameraCount() == 0;
  std::vector<vio::EurocFrame> cameraLessFrames;
  if (sum.cameraLess) {
    if (!(opt.cameraLessRate_hz > 0.0)) throw std::invalid_argument("runReplay: camera-less frame rate must be positive");
    const auto period = static_cast<std::int64_t>(std::llround(1e9 / opt.cameraLessRate_hz));
    for (std::int64_t t = imu.front().t_ns + period; t <= imu.back().t_ns; t += period) cameraLessFrames.push_back({t, 0, {}});
  }
  const auto& frames = sum.cameraLess ? cameraLessFrames : ds.frames();
  sum.frames = frames.size();
  if (frames.empty()) throw ParseError((mav0 / "cam0" / "data.csv").string(), 0, "cam0", "no camera frames");
  const std::int64_t tFirst = frames.front().t_ns + static_cast<std::int64_t>(opt.start_s * 1e9);
  const std::int64_t tLast = opt.duration_s > 0.0 ? tFirst + static_cast<std::int64_t>(opt.duration_s * 1e9)
                                                  : std::numeric_limits<std::int64_t>::max();
  std::vector<std::size_t> sel;
  for (std::size_t i = 0; i < frames.size(); ++i)
    if (frames[i].t_ns >= tFirst && frames[i].t_ns <= tLast) sel.push_back(i);
  if (sel.empty()) throw std::invalid_argument("no frames in the requested time range");

  // GNSS inputs.
  GnssInputs g;
  if (gnss) {
    const fs::path gdir = fs::path(dataset) / "gnss";
    const std::string roverPath = !opt.roverObs.empty() ? opt.roverObs : (gdir / "rover.obs").string();
    std::string basePath = !opt.baseObs.empty() ? opt.baseObs : (gdir / "base.obs").string();
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
    if (!navPath.empty()) g.nav.add(readRinexNav(navPath));
    if (!opt.broadcastOnly) {
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
        auto precise = readPreciseProducts(sp3, clk);
        sum.preciseSatellites = precise->satellites().size();
        g.nav.setPrecise(std::move(precise));
        if (!atx.empty()) {
          auto antex = readAntennaFiles(atx);
          for (const AntexAntenna& a : antex->antennas) sum.antexAntennas += a.isSatellite();
          g.nav.setSatelliteAntennas(std::move(antex));
        }
        if (!bia.empty()) {
          auto biases = readCodeBiasFiles(bia);
          sum.codeBiases = biases->entries.size();
          g.nav.setCodeBiases(std::move(biases));
        }
      } else if (!clk.empty()) {
        throw ParseError(clk.front(), 0, "precise clock", "clock files need an SP3 orbit file (use --sp3)");
      }
    }
    g.rover = BaseReader::open(roverPath, GpsTime{}, &g.nav, true);
    g.haveRover = g.rover->next(g.nextRover);
    // SSR corrections of recorded correction streams; their times of week resolve against the rover.
    for (const std::string& f : opt.ssrFiles) {
      const rtcm::SsrFile ssr = rtcm::readSsrFile(f, g.haveRover ? g.nextRover.time : GpsTime{});
      for (const SsrMessage& m : ssr.messages) g.nav.addSsr(m);
      sum.ssrMessages += ssr.messages.size();
      if (ssr.messages.empty())
        std::fprintf(stderr, "[gvins-replay] warning: %s holds no SSR message\n", f.c_str());
      if (ssr.stats.malformed > 0)
        std::fprintf(stderr, "[gvins-replay] warning: %s: %lld malformed RTCM frames skipped\n", f.c_str(),
                     static_cast<long long>(ssr.stats.malformed));
    }
    // Float PPP on broadcast orbits and clocks: their errors drift and jump with the records, which
    // the millimetre phase rows cannot absorb (docs/gnss_fusion.md, "Float PPP").
    if (opt.modeName == "vio+dopp+ppp" && !g.nav.precise() && opt.ssrFiles.empty()) {
      std::fprintf(stderr, "[gvins-replay] warning: vio+dopp+ppp without precise products or an SSR stream: the "
                           "broadcast orbit/clock errors limit it (simulated flights: 0.70 m against 0.58 m with "
                           "vio+dopp+psr)\n");
    }
    // Products of another day than the observations: every state would silently be broadcast.
    if (const PreciseEphemeris* p = g.nav.precise(); p && g.haveRover) {
      const auto [first, last] = p->span();
      if (g.nextRover.time < first || last < g.nextRover.time) {
        std::fprintf(stderr, "[gvins-replay] warning: the precise products cover %s to %s GPST, the rover starts at %s: "
                             "broadcast orbits and clocks are used where they do not reach\n",
                     first.toString(0).c_str(), last.toString(0).c_str(), g.nextRover.time.toString(0).c_str());
      }
    }
    if (fs::exists(basePath)) {
      // RINEX (header position + antenna delta) or RTCM 3 (1005/1006, possibly only after some
      // epochs; its ephemerides join the store); RTCM times of week resolve against the rover.
      const GpsTime ref = g.haveRover ? g.nextRover.time : GpsTime{};
      g.base = BaseReader::open(basePath, ref, &g.nav, true);
      if (opt.basePosition) {
        gnss->setBasePosition(*opt.basePosition);
        g.basePositionSet = true;
      }
      g.haveBase = g.base->next(g.nextBase);
      if (!g.basePositionSet) {
        const auto p = g.base->antennaPosition();
        if (p && p->norm() > 1e6) {
          gnss->setBasePosition(*p);
          g.basePositionSet = true;
        } else if (g.base->format() == BaseFormat::Rinex) {
          throw ParseError(basePath, 0, "APPROX POSITION XYZ", "base position missing in the header (use --base-position)");
        }
      }
    }
  }

  // Outputs.
  vio::TumTrajectoryWriter tum((out / "trajectory.tum").string(),
                               "t x y z qx qy qz qw  (IMU pose in the VIO world frame; gvins-replay " + opt.modeName + ")");
  vio::PoseCovarianceWriter cov((out / "trajectory.cov.csv").string());
  OutFile timing(out / "timing.csv");
  timing.out() << "# t [ns],frame,features,frontend_ms,estimator_ms,gnss_ms,gnss_epochs,initialized,updated,msckf_features,slam_features,state_dim\n";
  std::unique_ptr<OutFile> posFile, ecefFile, epochFile;
  std::unique_ptr<PosWriter> posWriter;
  std::vector<Geodetic> kml;
  std::unique_ptr<OutFile> nmeaFile;
  std::unique_ptr<NmeaWriter> nmeaWriter;
  if (gnss && !opt.nmeaPath.empty()) {
    nmeaFile = std::make_unique<OutFile>(opt.nmeaPath);
    nmeaWriter = std::make_unique<NmeaWriter>(nmeaFile->out());
  }
  if (gnss) {
    posFile = std::make_unique<OutFile>(out / "global.pos");
    PosWriterOptions po;
    po.headerFields = {{"mode", opt.modeName}, {"dataset", dataset}};
    posWriter = std::make_unique<PosWriter>(posFile->out(), po);
    ecefFile = std::make_unique<OutFile>(out / "global_ecef.csv");
    ecefFile->out() << "# gps_week,tow [s],x [m],y [m],z [m],vx [m/s],vy [m/s],vz [m/s],rtk_fixed  (GNSS antenna, ECEF)\n";
    epochFile = std::make_unique<OutFile>(out / "gnss_epochs.csv");
    epochFile->out() << "# gps_week,tow [s],stage,psr_used,psr_rejected,dopp_used,dopp_rejected,dpsr_used,dpsr_rejected,"
                        "ddcp_used,ddcp_rejected,vel_used,vel_rejected,updated,rtk_fixed,reset,chi2,dof,gnss_ms,"
                        "phase_used,phase_rejected,ambiguities\n";
  }
  std::vector<vio::TumPose> poses;
  std::vector<vio::TrajectorySample> localTrack;  // poses with the estimated velocity
  std::vector<vio::PoseCovariance> covs;
  std::vector<double> estimatorMs, estBefore, estAfter;  // per frame; before and after the initialisation
  // Local outputs (trajectory.tum, covariances, the local evaluation) stay in the VIO world frame
  // of the start: once the GNSS fusion has moved the estimator into ENU (ReplayGnss::worldChange),
  // `localMap` takes ENU back to it, fixed at the move.
  std::optional<vio::WorldFrameChange> localMap;
  // GNSS solutions, stamped on the sensor clock: all, and those after the frame initialisation.
  std::vector<EcefTruthSample> antennaTrack, antennaTight;
  std::int64_t firstTight = -1;
  // Set at the first epoch whose tightly coupled GNSS rows were applied. The epoch at which the
  // frame initialisation converges carries the frame-initialisation estimate (SPP-level, metres)
  // and no GNSS rows yet; the global accuracy is evaluated from the next update on.
  bool tightRowsApplied = false;
  auto gnssStamp = [&](const GpsTime& t) {
    return t.wholeSeconds() * 1'000'000'000 + static_cast<std::int64_t>(std::llround(t.fraction() * 1e9)) - opt.sensorToGpst_ns;
  };

  // Camera input: feature tracks, or images through the loader and front end threads.
  std::unique_ptr<FeatureTrackFrames> trackFrames;
  std::unique_ptr<vio::CameraModel> model0, model1;
  std::unique_ptr<vio::FrontendThread> fe;
  std::thread loader;
  std::exception_ptr loaderError;
  std::mutex loaderMutex;
  std::atomic<std::size_t> badImages{0};
  struct Join {
    std::unique_ptr<vio::FrontendThread>& fe;
    std::thread& t;
    ~Join() {
      if (fe) fe->stop();
      if (t.joinable()) t.join();
    }
  } join{fe, loader};
  std::vector<std::size_t> trackIndex;  // tracks: the selected stamp indices
  std::unique_ptr<FeatureTrackDatasetWriter> trackWriter;
  if (tracks && !opt.saveTracksDir.empty())
    throw std::invalid_argument("--save-tracks needs the image front end; this dataset is replayed from its feature tracks (add --images)");
  if (tracks) {
    model0 = std::make_unique<vio::CameraModel>(ds.cameraCalibration(0).intrinsics);
    std::vector<TrackStamp> c1;
    if (ds.cameraCount() > 1 && fs::exists(mav0 / "cam1" / "features.csv")) {
      model1 = std::make_unique<vio::CameraModel>(ds.cameraCalibration(1).intrinsics);
      c1 = readFeatureTracksCsv((mav0 / "cam1" / "features.csv").string());
    }
    std::vector<std::int64_t> imageStamps;
    for (const vio::EurocFrame& fr : frames) imageStamps.push_back(fr.t_ns);
    trackFrames = std::make_unique<FeatureTrackFrames>(
        withImageStamps(readFeatureTracksCsv((mav0 / "cam0" / "features.csv").string()), imageStamps), *model0,
        std::move(c1), model1.get());
    for (std::size_t i = 0; i < trackFrames->size(); ++i)
      if (trackFrames->stamp(i) >= tFirst && trackFrames->stamp(i) <= tLast) trackIndex.push_back(i);
  } else if (!sum.cameraLess) {
    const bool stereo = ds.cameraCount() > 1 && opt.frontend.useStereo;
    if (!opt.saveTracksDir.empty())
      trackWriter = std::make_unique<FeatureTrackDatasetWriter>(dataset, opt.saveTracksDir, stereo ? 2 : 1);
    fe = std::make_unique<vio::FrontendThread>(
        vio::StereoFrontend(opt.frontend, ds.cameraCalibration(0), stereo ? &ds.cameraCalibration(1) : nullptr));
    loader = std::thread([&, stereo] {
      try {
        for (std::size_t k : sel) {
          const vio::EurocFrame& fr = frames[k];
          vio::StereoImages im;
          im.t_ns = fr.t_ns;
          try {
            im.left = ds.loadImage(0, fr.cam0);
            if (stereo && fr.cam1) im.right = ds.loadImage(1, *fr.cam1);
          } catch (const ParseError&) {
            if (!opt.skipBadImages) throw;
            ++badImages;
            continue;
          }
          if (!fe->push(std::move(im))) return;
        }
        fe->finish();
      } catch (...) {
        std::lock_guard<std::mutex> lock(loaderMutex);
        loaderError = std::current_exception();
        fe->stop();
      }
    });
  }

  // Main loop.
  std::size_t imuNext = 0;
  const std::int64_t imuLead = est.imuLeadNs();
  const std::int64_t imuStart = opt.start_s > 0.0 ? tFirst - 2'000'000'000 : imu.front().t_ns;
  while (imuNext < imu.size() && imu[imuNext].t_ns < imuStart) ++imuNext;
  std::int64_t lastImu = -1;
  double feSum = 0.0, estSum = 0.0, gnssSum = 0.0;
  std::int64_t firstT = -1, lastT = -1;
  auto lastProgress = Clock::now();
  const std::size_t total = tracks ? trackIndex.size() : sel.size();
  std::size_t cursor = 0;
  const std::string imuFile = (mav0 / "imu0" / "data.csv").string();
  for (;;) {
    std::optional<vio::FeatureFrame> frame;
    if (tracks) {
      if (cursor >= trackIndex.size()) break;
      frame = trackFrames->frame(trackIndex[cursor++]);
    } else if (sum.cameraLess) {
      if (cursor >= sel.size()) break;
      frame = vio::FeatureFrame{frames[sel[cursor]].t_ns, cursor, {}, {}};
      ++cursor;
    } else {
      frame = fe->pop();
      if (!frame) break;
      if (trackWriter) trackWriter->write(*frame);
    }
    // IMU up to the first sample at or after the frame time.
    while (imuNext < imu.size()) {
      const vio::ImuSample& s = imu[imuNext];
      if (lastImu >= 0) {
        const double gap = static_cast<double>(s.t_ns - lastImu) * 1e-9;
        if (gap > opt.maxImuGap_s) {
          ++sum.imuGaps;
          sum.largestImuGap_s = std::max(sum.largestImuGap_s, gap);
          if (opt.imuGapPolicy == ImuGapPolicy::Error) {
            char b[160];
            std::snprintf(b, sizeof b, "IMU gap of %.3f s before the sample at %" PRId64 " ns (limit %.3f s; --imu-gaps warn to continue)",
                          gap, s.t_ns, opt.maxImuGap_s);
            throw ParseError(imuFile, 0, "timestamp", b);
          }
        }
      }
      est.addImu(s);
      lastImu = s.t_ns;
      ++sum.imuSamples;
      ++imuNext;
      if (s.t_ns >= frame->t_ns + imuLead) break;
    }
    const ReplayEstimator::FrameOutcome r = est.processFrame(*frame);
    ++sum.framesProcessed;
    if (firstT < 0) firstT = frame->t_ns;
    lastT = frame->t_ns;
    feSum += frame->timing.total;
    sum.frontendMsMax = std::max(sum.frontendMsMax, frame->timing.total);
    estSum += r.estimator_ms;
    estimatorMs.push_back(r.estimator_ms);
    sum.estimatorMsMax = std::max(sum.estimatorMsMax, r.estimator_ms);
    if (r.updated) ++sum.framesUpdated;
    (r.initialized ? estAfter : estBefore).push_back(r.estimator_ms);
    if (!r.initialized) ++sum.framesWaitingBy[r.init_status];
    if (r.initialized && std::isnan(sum.initSeconds)) sum.initSeconds = static_cast<double>(frame->t_ns - firstT) * 1e-9;
    if (r.reset) {
      ++sum.estimatorResets;
      // The next poses are in the new state's VIO frame: the local evaluation covers the last
      // state only, and trajectory.tum marks the jump.
      tum.markReset("after a visual lock-out: the poses below are in a new VIO world frame");
      localTrack.clear();
      covs.clear();
      localMap.reset();
      if (opt.progress) {
        std::fprintf(stderr, "\n[gvins-replay] warning: visual lock-out at frame %zu (t %.2f s): the estimator "
                             "starts again (lockout_reset_s; check the camera-IMU time offset and calibration)\n",
                     sum.framesProcessed, static_cast<double>(frame->t_ns - firstT) * 1e-9);
      }
    }
    const bool init = est.initialized();
    if (init) {
      ++sum.framesInitialized;
      vio::ImuState s = est.newestImuState();
      vio::Matrix6d P = est.poseCovariance();
      if (localMap) {  // the estimator is in ENU: to the local frame (δθ is in the body, δp rotates)
        s.R_WI = localMap->attitude(s.R_WI);
        s.p_WI = localMap->point(s.p_WI);
        s.v_WI = localMap->direction(s.v_WI);
        vio::Matrix6d T = vio::Matrix6d::Identity();
        T.bottomRightCorner<3, 3>() = localMap->rotation();
        P = T * P * T.transpose();
      }
      const vio::TumPose p{s.t_ns, s.p_WI, s.R_WI};
      if (poses.empty() || p.t_ns > poses.back().t_ns) {
        tum.write(p);
        cov.write(s.t_ns, P);
        poses.push_back(p);
        localTrack.push_back({s.t_ns, s.R_WI, s.p_WI, s.v_WI});
        covs.push_back({s.t_ns, 0.5 * (P + P.transpose())});
      }
    }
    // GNSS epochs up to the newest state.
    double gnssMs = 0.0;
    int gnssCount = 0;
    if (gnss) {
      const std::int64_t tState = init ? est.newestImuState().t_ns : frame->t_ns;
      const GpsTime limit = gpsFromNs(tState + opt.sensorToGpst_ns);
      while (g.haveRover && g.nextRover.time <= limit) {
        if (!init && !gnss->startsEstimator()) {
          ++sum.gnssEpochsSkipped;
        } else {
          while (g.haveBase && g.nextBase.time <= g.nextRover.time) {
            std::swap(g.currentBase, g.nextBase);
            g.haveCurrentBase = true;
            g.haveBase = g.base->next(g.nextBase);
          }
          if (!g.basePositionSet && g.base) {  // an RTCM station message arrived
            const auto p = g.base->antennaPosition();
            if (p && p->norm() > 1e6) {
              gnss->setBasePosition(*p);
              g.basePositionSet = true;
            }
          }
          // A simulated outage (opt.gnssOutages): the epoch without satellites and no base.
          const double since = static_cast<double>(gnssStamp(g.nextRover.time) - firstT) * 1e-9;
          const bool outage = std::any_of(opt.gnssOutages.begin(), opt.gnssOutages.end(),
                                          [&](const auto& w) { return since >= w.first && since < w.second; });
          ObsEpoch empty;
          if (outage) {
            empty.time = g.nextRover.time;
            ++sum.gnssEpochsInOutage;
          }
          const auto t0 = Clock::now();
          const ReplayGnssOutcome o = gnss->processEpoch(outage ? empty : g.nextRover,
                                                         g.haveCurrentBase && !outage ? &g.currentBase : nullptr, g.nav);
          const double ms = msSince(t0);
          for (const std::string& w : o.warnings) std::fprintf(stderr, "\n[gvins-replay] warning: %s\n", w.c_str());
          gnssMs += ms;
          ++gnssCount;
          if (!init && o.stage != "tight") {  // the GNSS/INS start has not started it yet
            ++sum.gnssEpochsSkipped;
            if (!o.insStart.empty()) ++sum.gnssEpochsWaitingBy[o.insStart];
          } else {
            ++sum.gnssEpochs;
          }
          if (o.updated) ++sum.gnssEpochsUpdated;
          sum.phaseRowsUsed += static_cast<std::size_t>(o.phaseUsed);
          sum.phaseRowsRejected += static_cast<std::size_t>(o.phaseRejected);
          sum.ambiguityStatesMax = std::max(sum.ambiguityStatesMax, static_cast<std::size_t>(o.ambiguities));
          sum.recordChanges += static_cast<std::size_t>(o.recordChanges);
          if (o.rtkFixed) ++sum.gnssEpochsFixed;
          const GpsTime& t = g.nextRover.time;
          char b[400];
          std::snprintf(b, sizeof b, "%d,%.3f,%s,%d,%d,%d,%d,%d,%d,%d,%d,%d,%d,%d,%d,%d,%.3f,%d,%.3f,%d,%d,%d\n", t.week(), t.tow(),
                        o.stage.c_str(), o.psrUsed, o.psrRejected, o.doppUsed, o.doppRejected, o.dpsrUsed, o.dpsrRejected,
                        o.ddcpUsed, o.ddcpRejected, o.velUsed, o.velRejected, o.updated ? 1 : 0, o.rtkFixed ? 1 : 0,
                        o.reset ? 1 : 0, o.chi2, o.dof, ms, o.phaseUsed, o.phaseRejected, o.ambiguities);
          epochFile->out() << b;
          if (o.antennaEcef) {
            PositionSolution ps;
            ps.time = t;
            ps.position = *o.antennaEcef;
            ps.positionCovariance = o.antennaCovarianceEcef;
            ps.quality = o.rtkFixed ? SolutionQuality::Fix
                                    : ((o.dpsrUsed + o.ddcpUsed) > 0 ? SolutionQuality::Float : SolutionQuality::Single);
            ps.numSatellites = std::max({o.psrUsed, o.doppUsed, o.dpsrUsed, o.ddcpUsed, o.phaseUsed});
            ps.velocity = o.antennaVelocityEcef;
            posWriter->write(ps);
            if (nmeaWriter) nmeaWriter->write(ps);
            const Eigen::Vector3d v = o.antennaVelocityEcef ? *o.antennaVelocityEcef : Eigen::Vector3d::Zero();
            std::snprintf(b, sizeof b, "%d,%.3f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%d\n", t.week(), t.tow(), ps.position.x(),
                          ps.position.y(), ps.position.z(), v.x(), v.y(), v.z(), o.rtkFixed ? 1 : 0);
            ecefFile->out() << b;
            kml.push_back(ecefToGeodetic(ps.position));
            const EcefTruthSample a{gnssStamp(t), ps.position, o.antennaVelocityEcef};
            antennaTrack.push_back(a);
            if (o.stage == "tight") {
              if (firstTight < 0) firstTight = a.t_ns;
              if (o.updated && o.psrUsed + o.doppUsed + o.dpsrUsed + o.ddcpUsed + o.velUsed > 0) tightRowsApplied = true;
              if (tightRowsApplied) antennaTight.push_back(a);
            }
          }
        }
        g.haveRover = g.rover->next(g.nextRover);
      }
      gnssSum += gnssMs;
      if (init && !localMap) {
        if (const auto c = gnss->worldChange()) {
          localMap = c->inverse();
          if (!std::isfinite(sum.enuMoveSeconds)) sum.enuMoveSeconds = static_cast<double>(frame->t_ns - firstT) * 1e-9;
        }
      }
    }
    char b[256];
    std::snprintf(b, sizeof b, "%" PRId64 ",%" PRIu64 ",%zu,%.3f,%.3f,%.3f,%d,%d,%d,%d,%d,%d\n", frame->t_ns, frame->index,
                  frame->features.size(), frame->timing.total, r.estimator_ms, gnssMs, gnssCount, init ? 1 : 0,
                  r.updated ? 1 : 0, r.msckf_features, r.slam_features, r.state_dim);
    timing.out() << b;
    if (opt.progress && (Clock::now() - lastProgress > std::chrono::seconds(1) || sum.framesProcessed == total)) {
      lastProgress = Clock::now();
      const double wall = msSince(wall0) * 1e-3;
      const double data = static_cast<double>(lastT - firstT) * 1e-9;
      std::fprintf(stderr, "\r[gvins-replay] frame %zu/%zu  t %.1f s  %s  %.1fx real time   ", sum.framesProcessed, total,
                   data, init ? "initialised" : ("initialising: " + std::string(vio::initStatusText(r.init_status))).c_str(),
                   wall > 0 ? data / wall : 0.0);
      std::fflush(stderr);
    }
  }
  if (opt.progress) std::fputc('\n', stderr);
  if (loader.joinable()) loader.join();
  {
    std::lock_guard<std::mutex> lock(loaderMutex);
    if (loaderError) std::rethrow_exception(loaderError);
  }
  sum.skippedBadImages = badImages.load();
  if (trackWriter) trackWriter->close();

  tum.close();
  cov.close();
  timing.close();
  sum.files = {(out / "trajectory.tum").string(), (out / "trajectory.cov.csv").string(), timing.path()};
  if (gnss && g.rover && g.rover->rinexStats() && g.rover->rinexStats()->skippedEpochs > 0) {
    // Malformed or out-of-order rover epochs were skipped: say which (file:line: reason).
    const RinexObsReaderStats& rs = *g.rover->rinexStats();
    std::fprintf(stderr, "[gvins-replay] warning: %lld rover epochs skipped (%lld out of order or repeated):\n",
                 static_cast<long long>(rs.skippedEpochs), static_cast<long long>(rs.outOfOrderEpochs));
    for (const std::string& m : rs.messages) std::fprintf(stderr, "  %s\n", m.c_str());
  }
  if (gnss && g.rover && !g.rover->rinexStats() && g.rover->skipped() > 0) {
    std::fprintf(stderr, "[gvins-replay] warning: rover %s: %lld malformed messages skipped\n", g.rover->describe().c_str(),
                 static_cast<long long>(g.rover->skipped()));
  }
  if (gnss) {
    posWriter->finish();
    posFile->close();
    ecefFile->close();
    epochFile->close();
    writeKml(out / "track.kml", kml, "gvins-replay " + opt.modeName);
    sum.files.insert(sum.files.end(), {posFile->path(), ecefFile->path(), (out / "track.kml").string(), epochFile->path()});
    if (nmeaFile) {
      nmeaFile->close();
      sum.files.push_back(nmeaFile->path());
    }
  }
  const double n = static_cast<double>(std::max<std::size_t>(sum.framesProcessed, 1));
  sum.frontendMsMean = feSum / n;
  sum.estimatorMsMean = estSum / n;
  auto mean = [](const std::vector<double>& v) {
    double t = 0.0;
    for (double x : v) t += x;
    return v.empty() ? std::numeric_limits<double>::quiet_NaN() : t / static_cast<double>(v.size());
  };
  sum.estimatorMsBeforeInit = mean(estBefore);
  sum.estimatorMsAfterInit = mean(estAfter);
  sum.gnssMsMean = sum.gnssEpochs ? gnssSum / static_cast<double>(sum.gnssEpochs) : 0.0;
  sum.datasetSeconds = firstT >= 0 ? static_cast<double>(lastT - firstT) * 1e-9 : 0.0;
  sum.wallSeconds = msSince(wall0) * 1e-3;
  if (!estimatorMs.empty()) {
    auto mid = estimatorMs.begin() + static_cast<std::ptrdiff_t>(estimatorMs.size() / 2);
    std::nth_element(estimatorMs.begin(), mid, estimatorMs.end());
    sum.estimatorMsMedian = *mid;
  }
  sum.gnssMsPerFrame = gnssSum / n;
  {
    rusage ru{};
    if (getrusage(RUSAGE_SELF, &ru) == 0)
      sum.cpuSeconds = static_cast<double>(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) +
                       1e-6 * static_cast<double>(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
  }
  if (firstTight >= 0 && firstT >= 0) sum.frameInitSeconds = static_cast<double>(firstTight - firstT) * 1e-9;
  if (gnss) sum.leverArm = gnss->leverArm();
  sum.leverArmTruth = opt.leverArmTruth;
  if (const auto td = est.timeOffset()) {
    sum.timeOffset = td->value;
    sum.timeOffsetSigma = td->sigma;
  }
  sum.timeOffsetTruth = opt.timeOffsetTruth;

  if (opt.evaluate && ds.hasGroundTruth() && localTrack.size() >= 2) {
    vio::EvaluationOptions eo2;
    eo2.alignment = vio::AlignmentKind::Yaw4Dof;
    try {
      const auto r = vio::evaluateTrajectory(localTrack, vio::toTrajectorySamples(ds.groundTruth()), covs, eo2);
      std::ostringstream os;
      if (sum.estimatorResets > 0) {
        os << "(the VIO state after the last of " << sum.estimatorResets
           << " resets only: the poses before it are in other VIO frames)\n";
      }
      vio::printEvaluation(os, r);
      sum.evaluationTable = os.str();
      sum.local = accuracyOf(r);
      // Aligned on the poses of the first 10 % of the horizontal path (estimated): the yaw of a
      // 4-DoF alignment is undetermined on a vertical segment, e.g. a take-off climb, which
      // made the first 10 % of the 3-D path of the 60m-400m-8 flight (52 m, nearly all climb)
      // give 134 m.
      vio::EvaluationOptions eo4 = eo2;
      auto horizontal = [&](std::size_t i) { return (localTrack[i].p - localTrack[i - 1].p).head<2>().norm(); };
      double path = 0.0;
      for (std::size_t i = 1; i < localTrack.size(); ++i) path += horizontal(i);
      double walked = 0.0;
      eo4.alignFirst = localTrack.size();
      for (std::size_t i = 1; i < localTrack.size(); ++i) {
        walked += horizontal(i);
        if (walked >= 0.1 * path) {
          eo4.alignFirst = std::max<std::size_t>(i + 1, 2);
          break;
        }
      }
      sum.local.startAlignedPositionRmse =
          vio::evaluateTrajectory(localTrack, vio::toTrajectorySamples(ds.groundTruth()), covs, eo4).translation.rmse;
      vio::EvaluationOptions eo5 = eo2;
      eo5.alignment = vio::AlignmentKind::FirstPose4Dof;
      const auto rf = vio::evaluateTrajectory(localTrack, vio::toTrajectorySamples(ds.groundTruth()), covs, eo5);
      if (rf.neesCount > 0) {
        sum.local.positionNeesFirstPose = rf.positionNees;
        sum.local.orientationNeesFirstPose = rf.orientationNees;
        char b[160];
        std::snprintf(b, sizeof b, "NEES with the first-pose alignment (the estimator's gauge): position %.3f, orientation %.3f\n",
                      rf.positionNees, rf.orientationNees);
        sum.evaluationTable += b;
      }
      for (const auto& f : vio::writeEvaluationPlots(r, (out / "eval_").string())) sum.files.push_back(f);
    } catch (const std::invalid_argument& e) {
      sum.evaluationTable = std::string("not evaluated: ") + e.what() + "\n";
    }
  }
  const fs::path ecefTruth = fs::path(dataset) / "truth" / "groundtruth_ecef.csv";
  // The solutions from the first tightly coupled update on (all if the frame never converged).
  const std::vector<EcefTruthSample>& evalTrack = antennaTight.size() >= 2 ? antennaTight : antennaTrack;
  if (opt.evaluate && gnss && evalTrack.size() >= 2 && (!opt.truthPos.empty() || fs::exists(ecefTruth))) {
    const auto truth = opt.truthPos.empty()
                           ? readEcefTruthCsv(ecefTruth.string())
                           : ecefTruthFromPos(readPosFile(opt.truthPos), opt.truthPosMaxQuality, opt.sensorToGpst_ns);
    if (!truth.empty()) {
      const Eigen::Vector3d origin = truth.front().antenna;
      const Geodetic og = ecefToGeodetic(origin);
      const Eigen::Matrix3d R_NE = ecefToEnuRotation(og.lat, og.lon);
      auto enu = [&](const EcefTruthSample& x) {
        std::optional<Eigen::Vector3d> v;
        if (x.antennaVelocity) v = R_NE * *x.antennaVelocity;
        return vio::TrajectorySample{x.t_ns, Eigen::Matrix3d::Identity(), ecefToEnu(x.antenna, origin), v};
      };
      std::vector<vio::TrajectorySample> ref, track;
      for (const auto& x : truth) ref.push_back(enu(x));
      for (const auto& x : evalTrack) track.push_back(enu(x));
      vio::EvaluationOptions eo3;
      eo3.alignment = vio::AlignmentKind::None;
      try {
        const auto r = vio::evaluateTrajectory(track, ref, {}, eo3);
        std::ostringstream os;
        vio::printEvaluation(os, r);
        double h = 0.0, v = 0.0;
        for (std::size_t i = 0; i < r.reference.size(); ++i) {
          const Eigen::Vector3d e = r.estimateAligned[i] - r.reference[i];
          h += e.head<2>().squaredNorm();
          v += e.z() * e.z();
        }
        const double m = static_cast<double>(std::max<std::size_t>(r.reference.size(), 1));
        char b[200];
        std::snprintf(b, sizeof b, "horizontal RMS %.4f m, vertical RMS %.4f m over %zu epochs%s\n", std::sqrt(h / m),
                      std::sqrt(v / m), r.reference.size(),
                      &evalTrack == &antennaTight ? " (from the first tightly coupled update)" : "");
        sum.globalEvaluationTable = os.str() + b;
        sum.global = accuracyOf(r);
        sum.global.horizontalRmse = std::sqrt(h / m);
        sum.global.verticalRmse = std::sqrt(v / m);
        for (const auto& f : vio::writeEvaluationPlots(r, (out / "eval_global_").string())) sum.files.push_back(f);
      } catch (const std::invalid_argument& e) {
        sum.globalEvaluationTable = std::string("not evaluated: ") + e.what() + "\n";
      }
    }
  }
  {
    OutFile mf(out / "metrics.csv");
    sum.writeMetrics(mf.out());
    mf.close();
    sum.files.push_back(mf.path());
  }
  return sum;
}

}  // namespace gvins::fusion
