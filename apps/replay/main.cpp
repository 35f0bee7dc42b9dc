// gvins-replay: runs the SRI-GVINS pipeline (front end thread, SRI-SWF estimator, optional GNSS
// fusion) over a dataset folder and writes trajectories, covariances, timing and GNSS outputs.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <vector>
#include <string>

#include "gvins/base/option_values.hpp"
#include "gvins/base/parse_error.hpp"
#include "gvins/fusion/gnss_fusion_config.hpp"
#include "gvins/fusion/replay_config.hpp"
#include "gvins/fusion/replay_pipeline.hpp"
#include "gvins/fusion/replay_sri_swf.hpp"
#include "gvins/fusion/sim_dataset_info.hpp"
#include "gvins/vio/sensor_yaml.hpp"
#include "gvins/vio/sri_swf_estimator.hpp"

namespace fs = std::filesystem;
using namespace gvins;
using namespace gvins::fusion;

namespace {

const char* kUsage =
    "usage: gvins-replay DATASET [options] -o OUTDIR\n"
    "\n"
    "Replays a dataset folder in the EuRoC/ASL layout (EuRoC MAV or gvins-sim output) through the\n"
    "visual front end (own thread; or the simulated feature tracks of a feature-only dataset), the\n"
    "SRI-SWF estimator and, in GNSS modes, the tightly-coupled GNSS fusion. Prints a progress line\n"
    "and a summary (timing, real-time factor, accuracy table when the dataset has ground truth).\n"
    "\n"
    "  -o OUTDIR              output folder (created): trajectory.tum, trajectory.cov.csv,\n"
    "                         timing.csv, metrics.csv (key figures for scripts); GNSS modes add\n"
    "                         global.pos, global_ecef.csv, track.kml, gnss_epochs.csv; with ground\n"
    "                         truth eval_*.svg\n"
    "  --nmea FILE            also NMEA 0183 GGA+RMC sentences of the global (GNSS) solutions\n"
    "  --config F.yaml        replay:, estimator: and gnss_fusion: sections (docs/replay.md)\n"
    "  --mode M               vio | vio+gpsvel | vio+dopp | vio+dopp+psr | vio+dopp+dpsr |\n"
    "                         vio+dopp+ddcp | vio+dopp+psr-nointegration | vio+dopp+ppp (float PPP:\n"
    "                         carrier phases with float ambiguities; default vio)\n"
    "  --float                run the estimator in single precision\n"
    "  --lever-arm-calib on|off  estimate the GNSS antenna lever arm online (default off)\n"
    "  --lever-arm X,Y,Z      initial GNSS lever arm ^I p_r, m (default: the config, else\n"
    "                         lever_arm_m of a gvins-sim dataset.yaml, which is also the truth\n"
    "                         for the lever-arm error in the summary)\n"
    "  --time-offset-calib on|off  estimate the camera-IMU time offset online (default: the\n"
    "                         estimator config, else off)\n"
    "  --time-offset S        camera-IMU time offset t_d (s, t_imu = t_cam + t_d): the value used,\n"
    "                         or the start value when calibrating (default: the estimator config,\n"
    "                         else 0; a gvins-sim dataset's cameras.time_offset_s is the truth for\n"
    "                         the time-offset error in the summary)\n"
    "  --rover F --base F --nav F   GNSS files (default DATASET/gnss/rover.obs, base.obs, nav file);\n"
    "                         rover RINEX or u-blox UBX, base RINEX, RTCM 3 or UBX (by content);\n"
    "                         no --nav needed with UBX (its RXM-SFRBX ephemerides are used)\n"
    "  --sp3 F --clk F        precise orbit / clock products, repeatable (default: the *.sp3 and\n"
    "                         *.clk files in DATASET/gnss, except in vio+dopp+dpsr and vio+dopp+ddcp,\n"
    "                         whose differences cancel the orbit/clock errors); they replace the\n"
    "                         broadcast orbits and clocks where they cover a satellite\n"
    "  --atx F                ANTEX satellite antenna offsets for the products (IGS SP3 orbits are\n"
    "                         centres of mass; default: *.atx in DATASET/gnss)\n"
    "  --bia F                Bias-SINEX code biases (OSB) for the products' clocks, repeatable\n"
    "                         (default: *.bia / *.bsx in DATASET/gnss)\n"
    "  --broadcast            broadcast orbits and clocks only (ignore precise products)\n"
    "  --ssr F                SSR corrections from a recorded RTCM 3 stream (e.g. DATASET/gnss/\n"
    "                         ssr.rtcm3 of gvins-sim, a caster's SSR mountpoint saved to a file),\n"
    "                         repeatable; used where no precise products cover a satellite (with\n"
    "                         --broadcast: for all)\n"
    "  --carrier-smoothing S  psr modes: Hatch window of the carrier-smoothed pseudoranges, s\n"
    "                         (default: gnss_fusion.carrier_smoothing, 100; 0 = raw codes)\n"
    "  --base-position X,Y,Z  base antenna ECEF (default: base.obs header)\n"
    "  --sensor-to-gpst NS    GPST ns = sensor stamp + NS (default 0: gvins-sim datasets are GPST)\n"
    "  --start S --duration S replay a part (seconds after the first frame)\n"
    "  --imu-gaps error|warn  IMU gaps longer than --max-imu-gap (s, default 0.05) stop the run\n"
    "                         (default) or are counted\n"
    "  --skip-bad-images      skip frames whose images cannot be decoded (counted)\n"
    "  --skip-missing-images  drop listed images that do not exist (counted)\n"
    "  --images               use images even if the dataset has feature tracks\n"
    "  --save-tracks DIR      images: also write the front end's tracks to DIR as a feature-only\n"
    "                         dataset (links to the rest of DATASET); replaying DIR runs the\n"
    "                         estimator on the same tracks without the front end\n"
    "  --no-eval              no accuracy table/plots\n"
    "  --truth-pos F.pos      antenna reference for the GNSS accuracy table: a .pos file (RTKLIB layout,\n"
    "                         e.g. an RTK solution of the same receiver), its epochs of quality <= Q\n"
    "  --truth-quality Q      1 (fixed only, default), 2 (and float), 5 (and single)\n"
    "  --camera-less-rate HZ  a dataset without cam0 runs camera-less (IMU and GNSS): frames without\n"
    "                         features at this rate (default 10 Hz)\n"
    "  --gnss-outage S,LEN    simulated GNSS outage from S s after the first frame for LEN s (repeatable):\n"
    "                         those rover epochs reach the fusion without satellites, the track goes on\n"
    "                         from the IMU alone\n"
    "  -q, --quiet            no progress line\n"
    "  -h, --help             this text\n"
    "\n"
    "Exit status: 0 success, 1 dataset/processing error, 2 usage error.\n";

[[noreturn]] void usageError(const std::string& msg) {
  std::fprintf(stderr, "gvins-replay: %s (see --help)\n", msg.c_str());
  std::exit(2);
}

/// Largest lever-arm component accepted from --lever-arm, m.
constexpr double kMaxLeverArm = 10.0;

/// The value of a checked option (base/option_values.hpp), or a usage error naming it.
template <class F>
auto optionValue(F&& parse) {
  try {
    return parse();
  } catch (const OptionError& e) {
    usageError(e.what());
  }
}

double toNumber(const std::string& s, const std::string& opt) {
  try {
    std::size_t p = 0;
    const double v = std::stod(s, &p);
    if (p == s.size()) return v;
  } catch (const std::exception&) {
  }
  usageError("bad number '" + s + "' for " + opt);
}

template <typename Scalar>
ReplaySummary run(const std::string& dataset, const vio::SriSwfConfig& ec, const std::optional<GnssFusionConfig>& gc,
                  const ReplayOptions& opt) {
  SriSwfReplayEstimator<Scalar> est(ec);
  std::unique_ptr<GnssFusionReplayClient<Scalar>> gnss;
  if (gc) gnss = std::make_unique<GnssFusionReplayClient<Scalar>>(*gc, est.estimator());
  return runReplay(dataset, est, gnss.get(), opt);
}

}  // namespace

int main(int argc, char** argv) {
  std::string nmeaPath;
  std::string dataset, outDir, configPath, mode = "vio", leverCalib, timeCalib;
  std::optional<double> timeOffset, carrierSmoothing;
  std::string saveTracks;
  bool useFloat = false, quiet = false, images = false, noEval = false, skipBad = false, skipMissing = false;
  std::optional<double> start, duration, maxGap;
  std::optional<std::string> gapPolicy, rover, base, nav;
  std::vector<std::string> sp3Files, clockFiles, antennaFiles, biasFiles;
  bool broadcastOnly = false;
  std::vector<std::string> ssrFiles;
  std::optional<Eigen::Vector3d> basePos, leverArm;
  std::int64_t sensorToGpst = 0;
  std::string truthPos;
  int truthQuality = 1;
  std::optional<double> cameraLessRate;
  std::vector<std::pair<double, double>> outages;  // --gnss-outage, s after the first frame
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) usageError("option " + a + " needs a value");
      return argv[++i];
    };
    if (a == "-h" || a == "--help") {
      std::fputs(kUsage, stdout);
      return 0;
    } else if (a == "-o") outDir = value();
    else if (a == "--nmea") nmeaPath = value();
    else if (a == "--config") configPath = value();
    else if (a == "--mode") mode = value();
    else if (a == "--float") useFloat = true;
    else if (a == "--lever-arm-calib") {
      leverCalib = value();
      if (leverCalib != "on" && leverCalib != "off") usageError("--lever-arm-calib takes on or off");
    } else if (a == "--time-offset-calib") {
      timeCalib = value();
      if (timeCalib != "on" && timeCalib != "off") usageError("--time-offset-calib takes on or off");
    } else if (a == "--time-offset") {
      timeOffset = toNumber(value(), a);
      if (!(std::abs(*timeOffset) <= 1.0)) usageError("--time-offset must be within [-1, 1] s");
    } else if (a == "--rover") rover = value();
    else if (a == "--base") base = value();
    else if (a == "--nav") nav = value();
    else if (a == "--sp3") sp3Files.push_back(value());
    else if (a == "--clk") clockFiles.push_back(value());
    else if (a == "--atx") antennaFiles.push_back(value());
    else if (a == "--bia") biasFiles.push_back(value());
    else if (a == "--broadcast") broadcastOnly = true;
    else if (a == "--ssr") ssrFiles.push_back(value());
    else if (a == "--carrier-smoothing") {
      carrierSmoothing = toNumber(value(), a);
      if (!(*carrierSmoothing >= 0.0 && *carrierSmoothing <= 3600.0)) usageError("--carrier-smoothing must be within 0..3600 s");
    }
    else if (a == "--base-position") basePos = optionValue([&] { return optionStationEcef(a, value()); });
    else if (a == "--lever-arm") {
      // A GNSS antenna a few metres from the IMU at most on the vehicles this estimator is for;
      // a larger value is a unit or sign mistake that would only show as a km-level error.
      leverArm = optionValue([&] { return optionVector3(a, value(), -kMaxLeverArm, kMaxLeverArm, "m"); });
    } else if (a == "--sensor-to-gpst") {
      const std::string v = value();
      try {
        std::size_t p = 0;
        sensorToGpst = std::stoll(v, &p);
        if (p != v.size()) throw std::invalid_argument("trailing");
      } catch (const std::exception&) {
        usageError("bad integer '" + v + "' for --sensor-to-gpst");
      }
    } else if (a == "--start") start = optionValue([&] { return optionNumber(a, value(), 0.0, 1e7, "s"); });
    else if (a == "--duration") duration = optionValue([&] { return optionNumber(a, value(), 0.0, 1e7, "s (0: to the end)"); });
    else if (a == "--max-imu-gap") maxGap = optionValue([&] { return optionNumber(a, value(), 1e-4, 3600.0, "s"); });
    else if (a == "--imu-gaps") {
      gapPolicy = value();
      if (*gapPolicy != "error" && *gapPolicy != "warn") usageError("--imu-gaps takes error or warn");
    } else if (a == "--skip-bad-images") skipBad = true;
    else if (a == "--skip-missing-images") skipMissing = true;
    else if (a == "--images") images = true;
    else if (a == "--save-tracks") saveTracks = value();
    else if (a == "--no-eval") noEval = true;
    else if (a == "--truth-pos") truthPos = value();
    else if (a == "--truth-quality") truthQuality = static_cast<int>(optionValue([&] { return optionNumber(a, value(), 1, 6); }));
    else if (a == "--camera-less-rate") cameraLessRate = optionValue([&] { return optionNumber(a, value(), 0.5, 100.0, "Hz"); });
    else if (a == "--gnss-outage") {
      const std::string v = value();
      const auto comma = v.find(',');
      if (comma == std::string::npos) usageError("--gnss-outage takes START,LENGTH (s), not '" + v + "'");
      const double s0 = optionValue([&] { return optionNumber(a, v.substr(0, comma), 0.0, 1e7, "s"); });
      const double len = optionValue([&] { return optionNumber(a, v.substr(comma + 1), 0.0, 1e7, "s"); });
      outages.emplace_back(s0, s0 + len);
    } else if (a == "-q" || a == "--quiet") quiet = true;
    else if (!a.empty() && a[0] == '-') usageError("unknown option " + a);
    else if (dataset.empty()) dataset = a;
    else usageError("more than one dataset given");
  }
  if (dataset.empty()) usageError("no dataset folder given");
  {
    std::error_code ec;
    if (!fs::is_directory(dataset, ec)) {
      std::fprintf(stderr, "gvins-replay: dataset %s: %s\n", dataset.c_str(),
                   fs::exists(dataset, ec) ? "not a folder (give the dataset folder, e.g. as gvins-sim writes it)"
                                           : "no such folder");
      return 1;
    }
  }
  if (outDir.empty()) usageError("no output folder given (-o)");
  const auto gnssMode = gnssFusionModeFromString(mode);
  if (!gnssMode) usageError("unknown mode '" + mode + "'");
  try {
    ReplayConfig rc;
    if (!configPath.empty()) rc = loadReplayConfig(configPath);
    ReplayOptions opt = rc.options;
    opt.outDir = outDir;
    opt.nmeaPath = nmeaPath;
    opt.modeName = mode;
    opt.progress = !quiet;
    if (start) opt.start_s = *start;
    if (duration) opt.duration_s = *duration;
    if (maxGap) opt.maxImuGap_s = *maxGap;
    if (gapPolicy) opt.imuGapPolicy = *gapPolicy == "warn" ? ImuGapPolicy::Warn : ImuGapPolicy::Error;
    if (skipBad) opt.skipBadImages = true;
    if (skipMissing) opt.skipMissingImages = true;
    if (images) opt.useFeatureTracks = false;
    if (!saveTracks.empty()) opt.saveTracksDir = saveTracks;
    if (noEval) opt.evaluate = false;
    opt.truthPos = truthPos;
    opt.truthPosMaxQuality = truthQuality;
    if (cameraLessRate) opt.cameraLessRate_hz = *cameraLessRate;
    opt.gnssOutages = outages;
    if (rover) opt.roverObs = *rover;
    if (base) opt.baseObs = *base;
    if (nav) opt.navFile = *nav;
    opt.sp3Files = sp3Files;
    opt.clockFiles = clockFiles;
    opt.antennaFiles = antennaFiles;
    opt.biasFiles = biasFiles;
    opt.broadcastOnly = broadcastOnly;
    opt.ssrFiles = ssrFiles;
    opt.basePosition = basePos;
    opt.sensorToGpst_ns = sensorToGpst;

    // A gvins-sim dataset: its lever arm and the gravity its IMU was simulated with.
    const std::optional<SimDatasetInfo> info = readSimDatasetInfo(dataset);
    // Estimator configuration: the dataset's calibration (IMU noise, cameras, a simulation's
    // gravity), changed by the estimator file of the config if there is one (a file without
    // cameras, e.g. config/estimator_euroc.yaml, tunes the filter for any dataset).
    fs::path mav0 = fs::path(dataset) / "mav0";
    if (!fs::is_directory(mav0)) mav0 = dataset;
    // A rig without a camera (no cam0 folder) runs camera-less: IMU and GNSS only.
    const bool cameraLess = fs::exists(mav0 / "imu0") && !fs::exists(mav0 / "cam0");
    const bool datasetCalibration =
        fs::exists(mav0 / "imu0" / "sensor.yaml") && (cameraLess || fs::exists(mav0 / "cam0" / "sensor.yaml"));
    vio::SriSwfConfig ec;
    if (datasetCalibration || rc.estimatorConfig.empty()) {
      ec.imu = vio::readImuSensorYaml((mav0 / "imu0" / "sensor.yaml").string()).noise;
      if (!cameraLess) ec.cameras.push_back(vio::readCameraSensorYaml((mav0 / "cam0" / "sensor.yaml").string()));
      if (opt.frontend.useStereo && fs::exists(mav0 / "cam1" / "sensor.yaml"))
        ec.cameras.push_back(vio::readCameraSensorYaml((mav0 / "cam1" / "sensor.yaml").string()));
      if (info && info->gravity) ec.gravity = *info->gravity;
      if (info && info->gravityModel == "rotating")
        std::fprintf(stderr, "gvins-replay: note: the dataset's IMU includes the Earth rotation, which the estimator does not model\n");
    }
    if (!rc.estimatorConfig.empty()) ec = vio::loadSriSwfConfig(rc.estimatorConfig, datasetCalibration ? &ec : nullptr);
    if (useFloat) ec.use_float = true;
    if (!timeCalib.empty()) ec.calibrate_time_offset = timeCalib == "on";
    if (timeOffset) ec.time_offset = *timeOffset;
    if (info) opt.timeOffsetTruth = info->cameraTimeOffset;

    std::optional<GnssFusionConfig> gc;
    const std::optional<Eigen::Vector3d> trueLever = info ? info->leverArm : std::nullopt;
    if (*gnssMode != GnssFusionMode::kVio) {
      gc = rc.hasGnssFusion ? parseGnssFusionConfig(rc.text, rc.file) : GnssFusionConfig{};
      gc->mode = *gnssMode;
      if (!leverCalib.empty()) gc->calibrateLeverArm = leverCalib == "on";
      if (!gc->leverArmGiven && trueLever) gc->leverArm = *trueLever;
      if (leverArm) gc->leverArm = *leverArm;
      if (carrierSmoothing) gc->carrierSmoothing = *carrierSmoothing;
      opt.leverArmTruth = trueLever;
      // The differential modes keep the broadcast orbits unless products are named (ReplayOptions::folderProducts).
      opt.folderProducts = !gc->usesDifferences();
    }
    ec = estimatorConfigFor(ec, *gnssMode);
    const ReplaySummary s = ec.use_float ? run<float>(dataset, ec, gc, opt) : run<double>(dataset, ec, gc, opt);
    if (s.framesProcessed == 0) {
      // Output files of a run without a single frame would look like a result: removed.
      for (const auto& f : s.files) std::filesystem::remove(f);
      std::fprintf(stderr,
                   "gvins-replay: %s: no frame was processed (%zu frames in the dataset): empty or unreadable "
                   "cam0 data (features.csv / data.csv), or a --start/--duration window without frames; "
                   "no output written\n",
                   dataset.c_str(), s.frames);
      return 1;
    }
    s.print(std::cout);
    for (const auto& f : s.files) std::cout << "wrote " << f << "\n";
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "gvins-replay: %s\n", e.what());
  }
  return 1;
}
