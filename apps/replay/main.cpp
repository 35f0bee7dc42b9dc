// gvins-replay: runs the SRI-GVINS pipeline (front end thread, SRI-SWF estimator, optional GNSS
// fusion) over a dataset folder and writes trajectories, covariances, timing and GNSS outputs.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <vector>
#include <string>

#include "gvins/base/command_line.hpp"
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

/// Largest lever-arm component accepted from --lever-arm, m.
constexpr double kMaxLeverArm = 10.0;

/// The command line: only what was given (the configuration file and the dataset fill the rest).
struct Args {
  std::string dataset, outDir, nmeaPath, configPath, mode = "vio";
  std::optional<bool> leverCalib, timeCalib;
  std::optional<double> timeOffset, carrierSmoothing;
  std::string saveTracks;
  bool useFloat = false, quiet = false, images = false, noEval = false, skipBad = false, skipMissing = false;
  std::optional<double> start, duration, maxGap;
  std::optional<ImuGapPolicy> gapPolicy;
  std::optional<std::string> rover, base, nav;
  std::vector<std::string> sp3Files, clockFiles, antennaFiles, biasFiles;
  bool broadcastOnly = false;
  std::vector<std::string> ssrFiles;
  std::optional<Eigen::Vector3d> basePos, leverArm;
  std::int64_t sensorToGpst = 0;
  std::string truthPos;
  int truthQuality = 1;
  std::optional<double> cameraLessRate;
  std::vector<std::pair<double, double>> outages;  // --gnss-outage, s after the first frame
};

Args parseArgs(int argc, char** argv) {
  Args a;
  CommandLine cl("gvins-replay", kUsage, argc, argv);
  while (cl.next()) {
    if (cl.is("-o")) a.outDir = cl.value();
    else if (cl.is("--nmea")) a.nmeaPath = cl.value();
    else if (cl.is("--config")) a.configPath = cl.value();
    else if (cl.is("--mode")) a.mode = cl.value();
    else if (cl.is("--float")) a.useFloat = true;
    else if (cl.is("--lever-arm-calib")) a.leverCalib = cl.onOff();
    else if (cl.is("--time-offset-calib")) a.timeCalib = cl.onOff();
    else if (cl.is("--time-offset")) a.timeOffset = cl.number(-1.0, 1.0, "s");
    else if (cl.is("--rover")) a.rover = cl.value();
    else if (cl.is("--base")) a.base = cl.value();
    else if (cl.is("--nav")) a.nav = cl.value();
    else if (cl.is("--sp3")) a.sp3Files.push_back(cl.value());
    else if (cl.is("--clk")) a.clockFiles.push_back(cl.value());
    else if (cl.is("--atx")) a.antennaFiles.push_back(cl.value());
    else if (cl.is("--bia")) a.biasFiles.push_back(cl.value());
    else if (cl.is("--broadcast")) a.broadcastOnly = true;
    else if (cl.is("--ssr")) a.ssrFiles.push_back(cl.value());
    else if (cl.is("--carrier-smoothing")) a.carrierSmoothing = cl.number(0.0, 3600.0, "s");
    else if (cl.is("--base-position")) a.basePos = cl.stationEcef();
    // A GNSS antenna a few metres from the IMU at most on the vehicles this estimator is for;
    // a larger value is a unit or sign mistake that would only show as a km-level error.
    else if (cl.is("--lever-arm")) a.leverArm = cl.vector3(-kMaxLeverArm, kMaxLeverArm, "m");
    else if (cl.is("--sensor-to-gpst")) a.sensorToGpst = cl.integer(std::numeric_limits<std::int64_t>::min(), std::numeric_limits<std::int64_t>::max());
    else if (cl.is("--start")) a.start = cl.number(0.0, 1e7, "s");
    else if (cl.is("--duration")) a.duration = cl.number(0.0, 1e7, "s (0: to the end)");
    else if (cl.is("--max-imu-gap")) a.maxGap = cl.number(1e-4, 3600.0, "s");
    else if (cl.is("--imu-gaps")) a.gapPolicy = cl.choice(kImuGapPolicyNames);
    else if (cl.is("--skip-bad-images")) a.skipBad = true;
    else if (cl.is("--skip-missing-images")) a.skipMissing = true;
    else if (cl.is("--images")) a.images = true;
    else if (cl.is("--save-tracks")) a.saveTracks = cl.value();
    else if (cl.is("--no-eval")) a.noEval = true;
    else if (cl.is("--truth-pos")) a.truthPos = cl.value();
    else if (cl.is("--truth-quality")) a.truthQuality = static_cast<int>(cl.integer(1, 6));
    else if (cl.is("--camera-less-rate")) a.cameraLessRate = cl.number(0.5, 100.0, "Hz");
    else if (cl.is("--gnss-outage")) {
      const std::vector<double> w = cl.numberList(0.0, 1e7, "s");
      if (w.size() != 2) cl.error("--gnss-outage takes START,LENGTH (s)");
      a.outages.emplace_back(w[0], w[0] + w[1]);
    }
    else if (cl.is("-q", "--quiet")) a.quiet = true;
    else if (a.dataset.empty()) a.dataset = cl.operand();
    else cl.error(cl.isOption() ? "unknown option '" + cl.arg() + "'" : "more than one dataset given");
  }
  if (a.dataset.empty()) cl.error("no dataset folder given");
  return a;
}

/// The replay options: the configuration file's, changed by the command line.
ReplayOptions replayOptions(const ReplayConfig& rc, const Args& a) {
  ReplayOptions opt = rc.options;
  opt.outDir = a.outDir;
  opt.nmeaPath = a.nmeaPath;
  opt.modeName = a.mode;
  opt.progress = !a.quiet;
  if (a.start) opt.start_s = *a.start;
  if (a.duration) opt.duration_s = *a.duration;
  if (a.maxGap) opt.maxImuGap_s = *a.maxGap;
  if (a.gapPolicy) opt.imuGapPolicy = *a.gapPolicy;
  if (a.skipBad) opt.skipBadImages = true;
  if (a.skipMissing) opt.skipMissingImages = true;
  if (a.images) opt.useFeatureTracks = false;
  if (!a.saveTracks.empty()) opt.saveTracksDir = a.saveTracks;
  if (a.noEval) opt.evaluate = false;
  opt.truthPos = a.truthPos;
  opt.truthPosMaxQuality = a.truthQuality;
  if (a.cameraLessRate) opt.cameraLessRate_hz = *a.cameraLessRate;
  opt.gnssOutages = a.outages;
  if (a.rover) opt.roverObs = *a.rover;
  if (a.base) opt.baseObs = *a.base;
  if (a.nav) opt.navFile = *a.nav;
  opt.sp3Files = a.sp3Files;
  opt.clockFiles = a.clockFiles;
  opt.antennaFiles = a.antennaFiles;
  opt.biasFiles = a.biasFiles;
  opt.broadcastOnly = a.broadcastOnly;
  opt.ssrFiles = a.ssrFiles;
  opt.basePosition = a.basePos;
  opt.sensorToGpst_ns = a.sensorToGpst;
  return opt;
}

/// Estimator configuration: the dataset's calibration (IMU noise, cameras, a simulation's
/// gravity), changed by the estimator file of the config if there is one (a file without
/// cameras, e.g. config/estimator_euroc.yaml, tunes the filter for any dataset), then by the
/// command line.
vio::SriSwfConfig estimatorConfig(const ReplayConfig& rc, const ReplayOptions& opt, const std::optional<SimDatasetInfo>& info,
                                  const Args& a) {
  fs::path mav0 = fs::path(a.dataset) / "mav0";
  if (!fs::is_directory(mav0)) mav0 = a.dataset;
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
  if (a.useFloat) ec.use_float = true;
  if (a.timeCalib) ec.calibrate_time_offset = *a.timeCalib;
  if (a.timeOffset) ec.time_offset = *a.timeOffset;
  return ec;
}

/// The GNSS fusion configuration of a GNSS mode: the config's gnss_fusion: section, the
/// dataset's true lever arm as the start value, the command line.
GnssFusionConfig gnssConfig(const ReplayConfig& rc, GnssFusionMode mode, const std::optional<Eigen::Vector3d>& trueLever,
                            const Args& a) {
  GnssFusionConfig gc = rc.hasGnssFusion ? parseGnssFusionConfig(rc.text, rc.file) : GnssFusionConfig{};
  gc.mode = mode;
  if (a.leverCalib) gc.calibrateLeverArm = *a.leverCalib;
  if (!gc.leverArmGiven && trueLever) gc.leverArm = *trueLever;
  if (a.leverArm) gc.leverArm = *a.leverArm;
  if (a.carrierSmoothing) gc.carrierSmoothing = *a.carrierSmoothing;
  return gc;
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
  const Args a = parseArgs(argc, argv);
  {
    std::error_code ec;
    if (!fs::is_directory(a.dataset, ec)) {
      std::fprintf(stderr, "gvins-replay: dataset %s: %s\n", a.dataset.c_str(),
                   fs::exists(a.dataset, ec) ? "not a folder (give the dataset folder, e.g. as gvins-sim writes it)"
                                             : "no such folder");
      return 1;
    }
  }
  if (a.outDir.empty()) usageError("gvins-replay", "no output folder given (-o)");
  const auto gnssMode = gnssFusionModeFromString(a.mode);
  if (!gnssMode) usageError("gvins-replay", "unknown mode '" + a.mode + "'");
  try {
    ReplayConfig rc;
    if (!a.configPath.empty()) rc = loadReplayConfig(a.configPath);
    ReplayOptions opt = replayOptions(rc, a);
    // A gvins-sim dataset: its lever arm and the gravity its IMU was simulated with.
    const std::optional<SimDatasetInfo> info = readSimDatasetInfo(a.dataset);
    vio::SriSwfConfig ec = estimatorConfig(rc, opt, info, a);
    if (info) opt.timeOffsetTruth = info->cameraTimeOffset;
    std::optional<GnssFusionConfig> gc;
    if (*gnssMode != GnssFusionMode::kVio) {
      const std::optional<Eigen::Vector3d> trueLever = info ? info->leverArm : std::nullopt;
      gc = gnssConfig(rc, *gnssMode, trueLever, a);
      opt.leverArmTruth = trueLever;
      // The differential modes keep the broadcast orbits unless products are named (ReplayOptions::folderProducts).
      opt.folderProducts = !gc->usesDifferences();
    }
    ec = estimatorConfigFor(ec, *gnssMode);
    const ReplaySummary s = ec.use_float ? run<float>(a.dataset, ec, gc, opt) : run<double>(a.dataset, ec, gc, opt);
    if (s.framesProcessed == 0) {
      // Output files of a run without a single frame would look like a result: removed.
      for (const auto& f : s.files) std::filesystem::remove(f);
      std::fprintf(stderr,
                   "gvins-replay: %s: no frame was processed (%zu frames in the dataset): empty or unreadable "
                   "cam0 data (features.csv / data.csv), or a --start/--duration window without frames; "
                   "no output written\n",
                   a.dataset.c_str(), s.frames);
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
