// Replay pipeline (fusion/replay_*.hpp) with test doubles for the estimator and the GNSS fusion:
// order of IMU/frame/GNSS hand-over, output files against independently read inputs, the accuracy
// table through the pipeline, bad datasets (missing files, unsorted/duplicate stamps, unreadable
// images, IMU gaps), feature-track datasets, and the replay's parsers.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include <zlib.h>

#include "gvins/base/parse_error.hpp"
#include "gvins/base/rinex_obs_reader.hpp"
#include "gvins/ephemeris/antex.hpp"
#include "gvins/ephemeris/bias_sinex.hpp"
#include "gvins/ephemeris/broadcast_sp3.hpp"
#include "gvins/ephemeris/ephemeris_store.hpp"
#include "gvins/ephemeris/rinex_nav.hpp"
#include "gvins/ephemeris/sp3.hpp"
#include "gvins/fusion/replay_config.hpp"
#include "gvins/fusion/replay_feature_tracks.hpp"
#include "gvins/fusion/replay_pipeline.hpp"
#include "gvins/fusion/sim_dataset_info.hpp"
#include "gvins/rtcm/encoder.hpp"
#include "gvins/gnss/pos_reader.hpp"
#include "gvins/vio/camera_model.hpp"
#include "gvins/vio/euroc_csv.hpp"
#include "gvins/vio/pose_covariance_csv.hpp"
#include "gvins/vio/so3.hpp"
#include "gvins/vio/tum_trajectory.hpp"

namespace fs = std::filesystem;
using namespace gvins;
using namespace gvins::fusion;

namespace {

const fs::path kData = GVINS_TEST_DATA;
const fs::path kV101 = kData / "euroc" / "v101_static_stereo";

fs::path scratch(const std::string& name) {
  const fs::path p = fs::temp_directory_path() / ("gvins_test_replay_" + name);
  fs::remove_all(p);
  fs::create_directories(p);
  return p;
}

/// A writable copy of the V1_01 stereo clip (24 frames, 2.7 s of IMU).
fs::path copyV101(const std::string& name) {
  const fs::path d = scratch(name) / "dataset";
  fs::copy(kV101, d, fs::copy_options::recursive);
  return d;
}

std::vector<std::string> lines(const fs::path& p, bool skipComments = true) {
  std::ifstream f(p);
  std::vector<std::string> out;
  std::string l;
  while (std::getline(f, l))
    if (!(skipComments && (l.empty() || l[0] == '#'))) out.push_back(l);
  return out;
}

void writeText(const fs::path& p, const std::string& s) {
  std::ofstream f(p, std::ios::binary);
  f << s;
}

std::vector<std::int64_t> cameraStamps(const fs::path& dataCsv) {
  std::vector<std::int64_t> t;
  for (const auto& l : lines(dataCsv)) t.push_back(std::stoll(l.substr(0, l.find(','))));
  return t;
}

/// Test double of the estimator: checks the hand-over order, reports the pose of a known
/// trajectory (optionally perturbed) at each frame, initialised from the third frame on.
class StubEstimator : public ReplayEstimator {
 public:
  std::vector<std::int64_t> imuTimes, frameTimes;
  std::vector<std::size_t> featureCounts;
  std::vector<vio::FeatureFrame> frames;
  bool orderOk = true;
  double zNoise = 0.0;         ///< ±zNoise alternating on z
  std::int64_t stateStride = 0;  ///< reported state time = frame time + (frames − 1)·stride
  vio::Matrix6d P = (Eigen::Matrix<double, 6, 1>() << 1e-4, 2e-4, 3e-4, 0.01, 0.02, 0.03).finished().asDiagonal();

  static Eigen::Vector3d truthP(std::int64_t t) {
    const double s = static_cast<double>(t % 1'000'000'000'000LL) * 1e-9;
    return {0.5 * s, 0.2 * s * s, 0.1 * std::sin(s)};
  }
  static Eigen::Matrix3d truthR(std::int64_t t) {
    const double s = static_cast<double>(t % 1'000'000'000'000LL) * 1e-9;
    return vio::so3::exp(Eigen::Vector3d(0.01 * s, -0.02 * s, 0.1 * s));
  }

  void addImu(const vio::ImuSample& s) override {
    if (!imuTimes.empty() && s.t_ns <= imuTimes.back()) orderOk = false;
    imuTimes.push_back(s.t_ns);
  }
  FrameOutcome processFrame(const vio::FeatureFrame& f) override {
    // The pipeline must have handed over IMU up to (at least) the frame time.
    if (imuTimes.empty() || imuTimes.back() < f.t_ns) orderOk = false;
    if (!frameTimes.empty() && f.t_ns <= frameTimes.back()) orderOk = false;
    frameTimes.push_back(f.t_ns);
    featureCounts.push_back(f.features.size());
    frames.push_back(f);
    FrameOutcome o;
    o.initialized = initialized();
    o.updated = o.initialized;
    o.estimator_ms = 0.5;
    o.msckf_features = 3;
    o.slam_features = 4;
    return o;
  }
  bool initialized() const override { return frameTimes.size() >= 3; }
  vio::ImuState newestImuState() const override {
    vio::ImuState s;
    s.t_ns = frameTimes.back() + static_cast<std::int64_t>(frameTimes.size() - 1) * stateStride;
    s.p_WI = truthP(frameTimes.back());
    s.p_WI.z() += (frameTimes.size() % 2 == 0 ? zNoise : -zNoise);
    s.R_WI = truthR(frameTimes.back());
    return s;
  }
  vio::Matrix6d poseCovariance() const override { return P; }
};

class StubGnss : public ReplayGnss {
 public:
  std::vector<GpsTime> rover, base;
  Eigen::Vector3d basePos = Eigen::Vector3d::Zero();
  Eigen::Vector3d antenna = Eigen::Vector3d(-3'961'904.0, 3'348'993.0, 3'698'211.0);
  void setBasePosition(const Eigen::Vector3d& e) override { basePos = e; }
  ReplayGnssOutcome processEpoch(const ObsEpoch& r, const ObsEpoch* b, const EphemerisStore&) override {
    rover.push_back(r.time);
    if (b) base.push_back(b->time);
    ReplayGnssOutcome o;
    o.report.stage = GnssFusionStage::kTight;
    o.report.psr.used = static_cast<int>(r.sats.size());
    o.report.updated = true;
    o.report.antennaEcef = antenna;
    o.report.antennaVelocityEcef = Eigen::Vector3d(0.1, 0.2, 0.3);
    return o;
  }
};

ReplayOptions quietOptions(const fs::path& out) {
  ReplayOptions o;
  o.outDir = out.string();
  o.progress = false;
  return o;
}

template <typename F>
ParseError expectParseError(F&& f) {
  try {
    f();
  } catch (const ParseError& e) {
    return e;
  }
  ADD_FAILURE() << "no ParseError";
  return ParseError("", 0, "", "");
}

}  // namespace

TEST(Replay, V101ImagesThroughFrontendThreadAndOutputs) {
  const fs::path out = scratch("v101") / "out";
  StubEstimator est;
  const ReplaySummary s = runReplay(kV101.string(), est, nullptr, quietOptions(out));
  const auto stamps = cameraStamps(kV101 / "mav0" / "cam0" / "data.csv");
  ASSERT_EQ(stamps.size(), 24u);
  EXPECT_EQ(est.frameTimes, stamps);
  EXPECT_TRUE(est.orderOk);
  EXPECT_EQ(s.framesProcessed, 24u);
  EXPECT_EQ(s.framesInitialized, 22u);
  EXPECT_FALSE(s.featureTracks);
  // The real front end found features on these 752x480 images (V1_01 start: > 100 corners).
  EXPECT_GT(*std::min_element(est.featureCounts.begin(), est.featureCounts.end()), 50u);
  // IMU: every sample from the start of the log up to the first one at/after the last frame.
  const auto imu = vio::readImuCsv((kV101 / "mav0" / "imu0" / "data.csv.gz").string());
  const auto firstAfter = std::find_if(imu.begin(), imu.end(), [&](const vio::ImuSample& x) { return x.t_ns >= stamps.back(); });
  EXPECT_EQ(s.imuSamples, static_cast<std::size_t>(firstAfter - imu.begin()) + 1);
  EXPECT_EQ(est.imuTimes.front(), imu.front().t_ns);
  // trajectory.tum: the 22 initialised frames, poses as reported.
  const auto tum = vio::readTumTrajectory((out / "trajectory.tum").string());
  ASSERT_EQ(tum.size(), 22u);
  for (std::size_t i = 0; i < tum.size(); ++i) {
    EXPECT_EQ(tum[i].t_ns, stamps[i + 2]);
    EXPECT_LT((tum[i].p - StubEstimator::truthP(stamps[i + 2])).norm(), 1e-8);
  }
  const auto cov = vio::readPoseCovarianceCsv((out / "trajectory.cov.csv").string());
  ASSERT_EQ(cov.size(), 22u);
  EXPECT_LT((cov[5].P - est.P).norm(), 1e-12);
  // timing.csv: one row per frame, the estimator's 0.5 ms, the feature counts.
  const auto t = lines(out / "timing.csv");
  ASSERT_EQ(t.size(), 24u);
  EXPECT_EQ(t[0].substr(0, t[0].find(',')), std::to_string(stamps[0]));
  EXPECT_NE(t[3].find(",0.500,"), std::string::npos) << t[3];
  EXPECT_DOUBLE_EQ(s.estimatorMsMean, 0.5);
  EXPECT_GT(s.frontendMsMean, 0.0);
  EXPECT_NEAR(s.datasetSeconds, static_cast<double>(stamps.back() - stamps.front()) * 1e-9, 1e-9);
  EXPECT_GT(s.realTimeFactor(), 0.0);
  EXPECT_TRUE(s.evaluationTable.empty());  // no ground truth in this clip
  std::ostringstream os;
  s.print(os);
  EXPECT_NE(os.str().find("real-time factor"), std::string::npos);
}

/// metrics.csv of an output folder as key -> value.
std::map<std::string, double> readMetrics(const fs::path& file) {
  std::map<std::string, double> m;
  for (const std::string& l : lines(file)) {
    if (l.empty() || l[0] == '#') continue;
    const auto c = l.find(',');
    if (c != std::string::npos) m[l.substr(0, c)] = std::strtod(l.c_str() + c + 1, nullptr);
  }
  return m;
}

TEST(Replay, AccuracyTableWithGroundTruth) {
  // Ground truth = the stub's known trajectory at 200 Hz; the stub reports it with ±2 cm on z:
  // the accuracy table through the pipeline must show 0.0200 m position RMSE.
  const fs::path d = copyV101("gt");
  const auto imu = vio::readImuCsv((d / "mav0" / "imu0" / "data.csv.gz").string());
  fs::create_directories(d / "mav0" / "state_groundtruth_estimate0");
  std::ostringstream gt;
  gt << "#timestamp,p_x,p_y,p_z,q_w,q_x,q_y,q_z\n";
  gt.precision(12);
  for (const auto& s : imu) {
    const Eigen::Vector3d p = StubEstimator::truthP(s.t_ns);
    const Eigen::Quaterniond q(StubEstimator::truthR(s.t_ns));
    gt << s.t_ns << "," << p.x() << "," << p.y() << "," << p.z() << "," << q.w() << "," << q.x() << "," << q.y() << ","
       << q.z() << "\n";
  }
  writeText(d / "mav0" / "state_groundtruth_estimate0" / "data.csv", gt.str());
  const fs::path out = d.parent_path() / "out";
  StubEstimator est;
  est.zNoise = 0.02;
  const ReplaySummary s = runReplay(d.string(), est, nullptr, quietOptions(out));
  ASSERT_FALSE(s.evaluationTable.empty());
  EXPECT_NE(s.evaluationTable.find("position [m]         0.0200"), std::string::npos) << s.evaluationTable;
  EXPECT_TRUE(fs::exists(out / "eval_trajectory_top.svg"));
  // metrics.csv carries the same figures for scripts; no GNSS: global ones are NaN.
  const auto m = readMetrics(out / "metrics.csv");
  EXPECT_NEAR(m.at("local_position_rmse_m"), 0.02, 1e-4);
  EXPECT_NEAR(m.at("local_vertical_rmse_m"), 0.02, 1e-4);
  EXPECT_EQ(m.at("frames"), static_cast<double>(s.framesProcessed));
  EXPECT_NEAR(m.at("estimator_ms_median"), s.estimatorMsMedian, 1e-5 * (1.0 + s.estimatorMsMedian));
  EXPECT_TRUE(std::isnan(m.at("global_position_rmse_m")));
  EXPECT_TRUE(std::isnan(m.at("lever_arm_error_m")));
  EXPECT_TRUE(fs::exists(out / "eval_position_error.svg"));
}

// local_start_aligned_position_rmse_m: the 4-DoF alignment on the first 10 % of the horizontal
// path. The trajectory climbs vertically first (as the simulated flights take off), then flies
// level; the estimate is the truth turned by 0.3 rad of yaw, shifted, with ±1 cm on z. On the
// first 10 % of the 3-D path (all climb) the yaw would be undetermined; on the horizontal path it
// is recovered and the RMSE is the 1 cm noise.
class ClimbStub : public StubEstimator {
 public:
  static Eigen::Vector3d truth(std::int64_t t, std::int64_t t0) {
    const double s = static_cast<double>(t - t0) * 1e-9;
    if (s < 0.4) return {0.0, 0.0, 2.0 * s};  // the clip is 1.15 s long
    const double h = s - 0.4;
    return {3.0 * h, 1.5 * h * h, 0.8};
  }
  std::int64_t t0 = 0;
  vio::ImuState newestImuState() const override {
    vio::ImuState st;
    st.t_ns = frameTimes.back();
    const Eigen::Matrix3d Rz = vio::so3::exp(Eigen::Vector3d(0, 0, 0.3));
    st.p_WI = Rz * truth(st.t_ns, t0) + Eigen::Vector3d(5.0, -2.0, 0.0);
    st.p_WI.z() += (frameTimes.size() % 2 == 0 ? 0.01 : -0.01);
    st.R_WI = Rz;
    return st;
  }
};

TEST(Replay, StartAlignedRmseUsesTheHorizontalPath) {
  const fs::path d = copyV101("climb");
  const auto imu = vio::readImuCsv((d / "mav0" / "imu0" / "data.csv.gz").string());
  const auto stamps = cameraStamps(kV101 / "mav0" / "cam0" / "data.csv");
  const std::int64_t t0 = stamps.front();
  fs::create_directories(d / "mav0" / "state_groundtruth_estimate0");
  std::ostringstream gt;
  gt << "#timestamp,p_x,p_y,p_z,q_w,q_x,q_y,q_z\n";
  gt.precision(12);
  for (const auto& smp : imu) {
    const Eigen::Vector3d p = ClimbStub::truth(smp.t_ns, t0);
    gt << smp.t_ns << "," << p.x() << "," << p.y() << "," << p.z() << ",1,0,0,0\n";
  }
  writeText(d / "mav0" / "state_groundtruth_estimate0" / "data.csv", gt.str());
  const fs::path out = d.parent_path() / "out";
  ClimbStub est;
  est.t0 = t0;
  runReplay(d.string(), est, nullptr, quietOptions(out));
  const auto m = readMetrics(out / "metrics.csv");
  EXPECT_NEAR(m.at("local_start_aligned_position_rmse_m"), 0.01, 2e-3);
  EXPECT_NEAR(m.at("local_position_rmse_m"), 0.01, 2e-3);
}

TEST(Replay, GnssEpochsHandedOverUpToTheNewestState) {
  // GEONET 0759 rover (30 s epochs) and 3040 base, with the sensor clock mapped onto the GNSS day:
  // epochs <= each state time must be handed over exactly once, in order, with the latest base
  // epoch at or before them; epochs before the VIO initialisation are skipped and counted.
  const fs::path g = kData / "gnss" / "geonet_0759_3040_2005";
  RinexObsHeader rh;
  const auto rover = readRinexObs((g / "07590920.05o.gz").string(), &rh);
  ASSERT_GT(rover.size(), 3u);
  const auto stamps = cameraStamps(kV101 / "mav0" / "cam0" / "data.csv");
  const auto ns = [](const GpsTime& t) {
    return t.wholeSeconds() * 1'000'000'000LL + static_cast<std::int64_t>(std::llround(t.fraction() * 1e9));
  };
  StubEstimator est;
  // The third frame is the first initialised one; its state time is put 10 ms after rover[1].
  // Frame 0 (not initialised, 100 ms earlier) passes rover[0]: skipped. Frame 2 hands over
  // rover[1]; the frames span 1.15 s and rover[2] is 30 s later.
  StubGnss gnss;
  // A true antenna track 0.5 m from the stub's constant solution (ECEF offset (0.3, 0, -0.4)):
  // the global accuracy table must show exactly 0.5 m.
  const fs::path d = copyV101("gnss");
  fs::create_directories(d / "truth");
  std::ostringstream tr;
  tr.precision(15);
  tr << "#timestamp [ns],p_E_x,p_E_y,p_E_z,v_E_x,v_E_y,v_E_z,q_w,q_x,q_y,q_z,antenna_E_x,antenna_E_y,antenna_E_z\n";
  const Eigen::Vector3d trueAntenna = gnss.antenna + Eigen::Vector3d(0.3, 0.0, -0.4);
  for (std::int64_t t = stamps.front() - 100'000'000; t <= stamps.back(); t += 5'000'000)
    tr << t << ",0,0,0,0,0,0,1,0,0,0," << trueAntenna.x() << "," << trueAntenna.y() << "," << trueAntenna.z() << "\n";
  writeText(d / "truth" / "groundtruth_ecef.csv", tr.str());
  ReplayOptions o = quietOptions(d.parent_path() / "out");
  o.sensorToGpst_ns = ns(rover[1].time) + 10'000'000 - stamps[2];
  o.roverObs = (g / "07590920.05o.gz").string();
  o.baseObs = (g / "30400920.05o.gz").string();
  o.navFile = (g / "07590920.05n.gz").string();
  o.modeName = "vio+dopp+psr";
  const ReplaySummary s = runReplay(d.string(), est, &gnss, o);
  ASSERT_EQ(gnss.rover.size(), 1u);
  EXPECT_EQ(gnss.rover[0], rover[1].time);
  EXPECT_EQ(s.gnssEpochs, 1u);
  EXPECT_EQ(s.gnssEpochsSkipped, 1u);
  RinexObsHeader bh;
  readRinexObs((g / "30400920.05o.gz").string(), &bh);
  ASSERT_TRUE(bh.station.approxPosition);
  EXPECT_EQ(gnss.basePos, *bh.station.approxPosition);
  for (std::size_t i = 0; i < gnss.base.size(); ++i) EXPECT_LE(gnss.base[i], gnss.rover[i]);
  // Outputs: global.pos read back by the .pos reader, the epoch at the stub's antenna position.
  const PosFile pos = readPosFile((fs::path(o.outDir) / "global.pos").string());
  ASSERT_EQ(pos.solutions.size(), 1u);
  EXPECT_LT((pos.solutions[0].position - gnss.antenna).norm(), 1e-3);
  EXPECT_EQ(pos.solutions[0].time, rover[1].time);
  ASSERT_TRUE(pos.solutions[0].velocity);
  EXPECT_LT((*pos.solutions[0].velocity - Eigen::Vector3d(0.1, 0.2, 0.3)).norm(), 1e-3);
  const auto ep = lines(fs::path(o.outDir) / "gnss_epochs.csv");
  ASSERT_EQ(ep.size(), 1u);
  EXPECT_NE(ep[0].find(",tight," + std::to_string(rover[1].sats.size()) + ",0,"), std::string::npos) << ep[0];
  EXPECT_EQ(lines(fs::path(o.outDir) / "global_ecef.csv").size(), 1u);
  const auto kml = lines(fs::path(o.outDir) / "track.kml");
  EXPECT_EQ(std::count_if(kml.begin(), kml.end(), [](const std::string& l) { return std::count(l.begin(), l.end(), ',') == 2; }), 1);
  // One epoch only: the evaluation needs two, so it says why it could not evaluate.
  EXPECT_TRUE(s.globalEvaluationTable.empty()) << s.globalEvaluationTable;
}

// Precise products in the dataset's gnss folder are loaded (precise_satellites); products of
// another day than the rover observations are loaded too but the replay warns that they do not
// reach the rover epochs. With folderProducts off (the differential modes) they are not read.
TEST(Replay, PreciseProductsInTheGnssFolder) {
  const fs::path g = kData / "gnss" / "geonet_0759_3040_2005";
  const auto stamps = cameraStamps(kV101 / "mav0" / "cam0" / "data.csv");
  RinexObsHeader rh;
  const auto rover = readRinexObs((g / "07590920.05o.gz").string(), &rh);
  EphemerisStore nav;
  nav.add(readRinexNav((g / "07590920.05n.gz").string()));
  // SP3 of the broadcast orbits over [start, start + 1 h].
  auto products = [&](const GpsTime& start) {
    std::ostringstream os;
    writeSp3(os, broadcastSp3(nav, start, start + 3600.0, 900.0));
    return os.str();
  };
  const auto ns = [](const GpsTime& t) {
    return t.wholeSeconds() * 1'000'000'000LL + static_cast<std::int64_t>(std::llround(t.fraction() * 1e9));
  };
  for (const bool sameDay : {true, false}) {
    const fs::path d = copyV101(sameDay ? "sp3_same" : "sp3_other");
    fs::create_directories(d / "gnss");
    writeText(d / "gnss" / "products.sp3", products(rover[0].time - 1800.0 + (sameDay ? 0.0 : 86400.0)));
    // The ANTEX and Bias-SINEX files beside them are picked up too (fuzz seeds: valid files).
    fs::copy_file(kData / "fuzz" / "antex" / "valid_satellites.atx", d / "gnss" / "igs.atx",
                  fs::copy_options::overwrite_existing);
    fs::copy_file(kData / "fuzz" / "bias_sinex" / "valid_gps_galileo.bia", d / "gnss" / "products.bia",
                  fs::copy_options::overwrite_existing);
    StubEstimator est;
    StubGnss gnss;
    ReplayOptions o = quietOptions(d.parent_path() / ("out_" + d.filename().string()));
    o.sensorToGpst_ns = ns(rover[1].time) + 10'000'000 - stamps[2];
    o.roverObs = (g / "07590920.05o.gz").string();
    o.baseObs = (g / "30400920.05o.gz").string();
    o.navFile = (g / "07590920.05n.gz").string();
    ::testing::internal::CaptureStderr();
    const ReplaySummary s = runReplay(d.string(), est, &gnss, o);
    const std::string err = ::testing::internal::GetCapturedStderr();
    EXPECT_EQ(s.preciseSatellites, nav.satellites().size());
    EXPECT_EQ(s.antexAntennas, readAntex((kData / "fuzz" / "antex" / "valid_satellites.atx").string()).antennas.size());
    EXPECT_EQ(s.codeBiases, readBiasSinex((kData / "fuzz" / "bias_sinex" / "valid_gps_galileo.bia").string()).entries.size());
    EXPECT_GT(s.codeBiases, 0u);
    EXPECT_EQ(err.find("precise products cover") != std::string::npos, !sameDay) << err;
    EXPECT_FALSE(s.folderProductsSkipped);
    // The differential modes' setting: the folder's products are not read, and the summary says so;
    // products named explicitly still are.
    ReplayOptions f = o;
    f.folderProducts = false;
    const ReplaySummary skipped = runReplay(d.string(), est, &gnss, f);
    EXPECT_EQ(skipped.preciseSatellites, 0u);
    EXPECT_EQ(skipped.antexAntennas, 0u);
    EXPECT_EQ(skipped.codeBiases, 0u);
    EXPECT_TRUE(skipped.folderProductsSkipped);
    f.sp3Files = {(d / "gnss" / "products.sp3").string()};
    const ReplaySummary named = runReplay(d.string(), est, &gnss, f);
    EXPECT_EQ(named.preciseSatellites, nav.satellites().size());
    EXPECT_FALSE(named.folderProductsSkipped);
    o.broadcastOnly = true;
    EXPECT_EQ(runReplay(d.string(), est, &gnss, o).preciseSatellites, 0u);
  }
  // A folder with a clock file and no orbits: an error where the folder's products are read
  // (clocks need an SP3 file), skipped like any other folder product where they are not.
  const fs::path d = copyV101("clk_only");
  fs::create_directories(d / "gnss");
  fs::copy_file(kData / "fuzz" / "rinex_clock" / "valid_v300", d / "gnss" / "products.clk",
                fs::copy_options::overwrite_existing);
  StubEstimator est;
  StubGnss gnss;
  ReplayOptions o = quietOptions(d.parent_path() / "out_clk_only");
  o.sensorToGpst_ns = ns(rover[1].time) + 10'000'000 - stamps[2];
  o.roverObs = (g / "07590920.05o.gz").string();
  o.navFile = (g / "07590920.05n.gz").string();
  const ParseError e = expectParseError([&] { runReplay(d.string(), est, &gnss, o); });
  EXPECT_EQ(e.file(), (d / "gnss" / "products.clk").string());
  EXPECT_EQ(e.field(), "precise clock");
  o.folderProducts = false;
  const ReplaySummary skipped = runReplay(d.string(), est, &gnss, o);
  EXPECT_TRUE(skipped.folderProductsSkipped);
  EXPECT_EQ(skipped.preciseSatellites, 0u);
}

TEST(Replay, GlobalAccuracyAgainstEcefTruth) {
  // The stub's state time advances 30 s per frame (GEONET epochs are 30 s apart), so frames 2..23
  // hand over one rover epoch each. The true antenna track (at the epochs' sensor stamps) is 0.5 m
  // from the stub's constant solution: the global accuracy table must show exactly 0.5 m.
  const fs::path g = kData / "gnss" / "geonet_0759_3040_2005";
  const auto rover = readRinexObs((g / "07590920.05o.gz").string());
  const auto stamps = cameraStamps(kV101 / "mav0" / "cam0" / "data.csv");
  const auto ns = [](const GpsTime& t) {
    return t.wholeSeconds() * 1'000'000'000LL + static_cast<std::int64_t>(std::llround(t.fraction() * 1e9));
  };
  StubEstimator est;
  est.stateStride = 30'000'000'000LL;
  StubGnss gnss;
  ReplayOptions o = quietOptions(scratch("global") / "out");
  o.sensorToGpst_ns = ns(rover[0].time) + 10'000'000 - stamps[2] - 2 * est.stateStride;
  o.roverObs = (g / "07590920.05o.gz").string();
  o.navFile = (g / "07590920.05n.gz").string();
  const fs::path d = copyV101("global_ds");
  fs::create_directories(d / "truth");
  std::ostringstream tr;
  tr.precision(15);
  tr << "#timestamp [ns],p_E_x,p_E_y,p_E_z,v_E_x,v_E_y,v_E_z,q_w,q_x,q_y,q_z,antenna_E_x,antenna_E_y,antenna_E_z,"
        "antenna_v_E_x,antenna_v_E_y,antenna_v_E_z\n";
  const Eigen::Vector3d trueAntenna = gnss.antenna + Eigen::Vector3d(0.3, 0.0, -0.4);
  // True antenna velocity 0.3 m/s (ECEF z) from the stub's (0.1, 0.2, 0.3).
  for (const auto& e : rover)
    tr << ns(e.time) - o.sensorToGpst_ns << ",0,0,0,0,0,0,1,0,0,0," << trueAntenna.x() << "," << trueAntenna.y() << ","
       << trueAntenna.z() << ",0.1,0.2,0\n";
  writeText(d / "truth" / "groundtruth_ecef.csv", tr.str());
  const ReplaySummary s = runReplay(d.string(), est, &gnss, o);
  // Epochs handed over: those up to the last state time, counted from the file independently.
  const std::int64_t lastState = stamps.back() + 23 * est.stateStride + o.sensorToGpst_ns;
  const auto expected = std::count_if(rover.begin(), rover.end(), [&](const ObsEpoch& e) { return ns(e.time) <= lastState; });
  EXPECT_EQ(static_cast<std::ptrdiff_t>(s.gnssEpochs), expected);
  EXPECT_GE(s.gnssEpochs, 20u);
  EXPECT_NE(s.globalEvaluationTable.find("position [m]         0.5000     0.5000"), std::string::npos)
      << s.globalEvaluationTable;
  EXPECT_NE(s.globalEvaluationTable.find("velocity [m/s]       0.3000     0.3000"), std::string::npos)
      << s.globalEvaluationTable;
  EXPECT_TRUE(fs::exists(fs::path(o.outDir) / "eval_global_trajectory_top.svg"));
  const auto m = readMetrics(fs::path(o.outDir) / "metrics.csv");
  EXPECT_NEAR(m.at("global_position_rmse_m"), 0.5, 1e-5);
  EXPECT_NEAR(m.at("global_velocity_rmse_mps"), 0.3, 1e-5);
  EXPECT_NEAR(std::hypot(m.at("global_horizontal_rmse_m"), m.at("global_vertical_rmse_m")), 0.5, 1e-5);
  EXPECT_EQ(m.at("global_poses"), static_cast<double>(s.gnssEpochs));
  // Every epoch of the stub is in the tight stage: the frame counts as initialised at the first.
  EXPECT_GE(m.at("frame_init_s"), 0.0);
  // No base file given and none in the dataset: no base epochs.
  EXPECT_TRUE(gnss.base.empty());
}

TEST(Replay, RtcmBaseStreamHandsOverTheSameBaseEpochs) {
  // The GEONET 3040 base as an RTCM 3 log (MSM7 by the project's encoder, 1005 with a position
  // 1 m away from the RINEX header's, so that its use shows): the pipeline detects the format,
  // takes the station position from 1005 and hands over the same base epochs as from RINEX.
  const fs::path g = kData / "gnss" / "geonet_0759_3040_2005";
  const auto rover = readRinexObs((g / "07590920.05o.gz").string());
  RinexObsHeader bh;
  const auto base = readRinexObs((g / "30400920.05o.gz").string(), &bh);
  ASSERT_TRUE(bh.station.approxPosition);
  const Eigen::Vector3d arp = *bh.station.approxPosition + Eigen::Vector3d(1.0, 0.0, 0.0);
  const fs::path rtcmFile = scratch("rtcm_base") / "base.rtcm3";
  {
    std::ofstream out(rtcmFile, std::ios::binary);
    rtcm::Encoder enc(3040);
    rtcm::StationPosition sp;
    sp.stationId = 3040;
    sp.gps = true;
    sp.arp = arp;
    const auto f = enc.stationPosition(sp);
    out.write(reinterpret_cast<const char*>(f.data()), static_cast<std::streamsize>(f.size()));
    for (const ObsEpoch& e : base) {
      const auto m = enc.msm(e, 7);
      out.write(reinterpret_cast<const char*>(m.data()), static_cast<std::streamsize>(m.size()));
    }
  }
  const auto stamps = cameraStamps(kV101 / "mav0" / "cam0" / "data.csv");
  const auto ns = [](const GpsTime& t) {
    return t.wholeSeconds() * 1'000'000'000LL + static_cast<std::int64_t>(std::llround(t.fraction() * 1e9));
  };
  auto run = [&](const fs::path& baseFile, const std::string& name) {
    StubEstimator est;
    est.stateStride = 30'000'000'000LL;
    StubGnss gnss;
    ReplayOptions o = quietOptions(scratch(name) / "out");
    o.sensorToGpst_ns = ns(rover[0].time) + 10'000'000 - stamps[2] - 2 * est.stateStride;
    o.roverObs = (g / "07590920.05o.gz").string();
    o.baseObs = baseFile.string();
    o.navFile = (g / "07590920.05n.gz").string();
    o.evaluate = false;
    runReplay(copyV101(name + "_ds").string(), est, &gnss, o);
    return gnss;
  };
  const StubGnss fromRinex = run(g / "30400920.05o.gz", "base_rinex");
  const StubGnss fromRtcm = run(rtcmFile, "base_rtcm");
  EXPECT_LT((fromRtcm.basePos - arp).norm(), 1e-3);  // 1005: 0.1 mm resolution
  EXPECT_LT((fromRinex.basePos - *bh.station.approxPosition).norm(), 1e-6);
  ASSERT_GE(fromRinex.base.size(), 20u);
  EXPECT_EQ(fromRtcm.rover, fromRinex.rover);
  // MSM epoch times have a resolution of 1 ms (RTCM 10403.3, DF004).
  ASSERT_EQ(fromRtcm.base.size(), fromRinex.base.size());
  for (std::size_t i = 0; i < fromRtcm.base.size(); ++i) EXPECT_LE(std::abs(fromRtcm.base[i] - fromRinex.base[i]), 0.0005) << i;
}

TEST(ReplayParsers, SimDatasetInfo) {
  const SimDatasetInfo i = parseSimDatasetInfo(
      "format: gvins-sim-dataset\ngravity:\n  model: flat  # c\n  magnitude_mps2: 9.797126914213944\n"
      "lever_arm_m: [0.08, 0, 0.18]  # antenna\nother: {a: 1}\n",
      "dataset.yaml");
  ASSERT_TRUE(i.leverArm);
  EXPECT_EQ(*i.leverArm, Eigen::Vector3d(0.08, 0.0, 0.18));
  ASSERT_TRUE(i.gravity);
  EXPECT_DOUBLE_EQ(*i.gravity, 9.797126914213944);
  EXPECT_EQ(i.gravityModel, "flat");
  EXPECT_FALSE(parseSimDatasetInfo("format: x\n", "d.yaml").leverArm);
  auto err = [](const std::string& text) { return expectParseError([&] { parseSimDatasetInfo(text, "d.yaml"); }); };
  ParseError e = err("a: 1\nlever_arm_m: [0.1, 0.2]\n");
  EXPECT_EQ(e.field(), "lever_arm_m");
  EXPECT_EQ(e.line(), 2);
  e = err("gravity:\n  magnitude_mps2: 98.1\n");
  EXPECT_EQ(e.field(), "gravity.magnitude_mps2");
  e = err("gravity:\n  model: round\n");
  EXPECT_EQ(e.field(), "gravity.model");
  e = err("gravity: 9.8\n");
  EXPECT_EQ(e.field(), "gravity");
  e = err("lever_arm_m: [1, 2\n");
  EXPECT_EQ(e.file(), "d.yaml");
  // From a dataset folder; none there: nullopt (a EuRoC recording).
  const fs::path d = scratch("siminfo");
  writeText(d / "dataset.yaml", "lever_arm_m: [0.1, -0.2, 0.3]\n");
  const auto r = readSimDatasetInfo(d.string());
  ASSERT_TRUE(r && r->leverArm);
  EXPECT_EQ(*r->leverArm, Eigen::Vector3d(0.1, -0.2, 0.3));
  EXPECT_FALSE(readSimDatasetInfo((d / "none").string()));
}

TEST(ReplayParsers, EcefTruth) {
  const auto t = parseEcefTruthCsv("#h\n100,0,0,0,0,0,0,1,0,0,0,1.5,2.5,3.5\n200,0,0,0,0,0,0,1,0,0,0,1,2,3,9,9\r\n", "g.csv");
  ASSERT_EQ(t.size(), 2u);
  EXPECT_EQ(t[0].antenna, Eigen::Vector3d(1.5, 2.5, 3.5));
  EXPECT_EQ(t[1].t_ns, 200);
  EXPECT_FALSE(t[1].antennaVelocity);  // 16 fields: no velocity columns
  const auto tv = parseEcefTruthCsv("100,0,0,0,0,0,0,1,0,0,0,1,2,3,0.5,-0.25,2\n", "g.csv");
  ASSERT_TRUE(tv.at(0).antennaVelocity);
  EXPECT_EQ(*tv[0].antennaVelocity, Eigen::Vector3d(0.5, -0.25, 2.0));
  auto err = [](const std::string& text) { return expectParseError([&] { parseEcefTruthCsv(text, "g.csv"); }); };
  ParseError e = err("100,0,0,0,0,0,0,1,0,0,0,1,2\n");
  EXPECT_EQ(e.field(), "antenna_E_z");
  EXPECT_EQ(e.line(), 1);
  e = err("100,0,0,0,0,0,0,1,0,0,0,1,x,3\n");
  EXPECT_EQ(e.field(), "antenna_E_y");
  e = err("100,0,0,0,0,0,0,1,0,0,0,1,2,3\n100,0,0,0,0,0,0,1,0,0,0,1,2,3\n");
  EXPECT_EQ(e.field(), "timestamp");
  EXPECT_EQ(e.line(), 2);
  e = err("-5,0,0,0,0,0,0,1,0,0,0,1,2,3\n");
  EXPECT_EQ(e.field(), "timestamp");
  e = err("100,0,0,0,0,0,0,1,0,0,0,1,2,3,0,v,0\n");
  EXPECT_EQ(e.field(), "antenna_v_E_y");
  e = err("100,0,0,0,0,0,0,1,0,0,0,1,2,3,0,0,nan\n");
  EXPECT_EQ(e.field(), "antenna_v_E_z");
  EXPECT_THROW(readEcefTruthCsv("/nonexistent/groundtruth_ecef.csv"), ParseError);
}

TEST(Replay, MissingFilesAreParseErrorsNamingThem) {
  {
    const fs::path d = copyV101("noimu");
    fs::remove(d / "mav0" / "imu0" / "data.csv.gz");
    StubEstimator est;
    const ParseError e = expectParseError([&] { runReplay(d.string(), est, nullptr, quietOptions(d.parent_path() / "out")); });
    EXPECT_NE(e.file().find("imu0"), std::string::npos) << e.what();
  }
  {
    const fs::path d = copyV101("noimage");
    const auto stamps = cameraStamps(d / "mav0" / "cam0" / "data.csv");
    fs::remove(d / "mav0" / "cam0" / "data" / (std::to_string(stamps[5]) + ".png"));
    StubEstimator est;
    const ParseError e = expectParseError([&] { runReplay(d.string(), est, nullptr, quietOptions(d.parent_path() / "out")); });
    EXPECT_NE(std::string(e.what()).find(std::to_string(stamps[5])), std::string::npos) << e.what();
    ReplayOptions o = quietOptions(d.parent_path() / "out2");
    o.skipMissingImages = true;
    StubEstimator est2;
    const ReplaySummary s = runReplay(d.string(), est2, nullptr, o);
    EXPECT_EQ(s.skippedMissingImages, 1u);
    EXPECT_EQ(s.framesProcessed, 23u);
  }
  {
    StubEstimator est;
    ReplayOptions o = quietOptions(scratch("norover") / "out");
    o.roverObs = "/nonexistent/rover.obs";
    StubGnss gnss;
    const ParseError e = expectParseError([&] { runReplay(kV101.string(), est, &gnss, o); });
    EXPECT_EQ(e.file(), "/nonexistent/rover.obs");
  }
}

TEST(Replay, UnsortedAndDuplicateStampsAreErrorsWithLine) {
  for (const bool duplicate : {false, true}) {
    const fs::path d = copyV101(duplicate ? "dupstamp" : "unsorted");
    auto l = lines(d / "mav0" / "cam0" / "data.csv", false);
    // l[0] is the header; swap lines 4 and 5 (1-based) or repeat line 4.
    if (duplicate) l[4] = l[3];
    else std::swap(l[3], l[4]);
    std::string s;
    for (const auto& x : l) s += x + "\n";
    writeText(d / "mav0" / "cam0" / "data.csv", s);
    StubEstimator est;
    const ParseError e = expectParseError([&] { runReplay(d.string(), est, nullptr, quietOptions(d.parent_path() / "out")); });
    EXPECT_NE(e.file().find("cam0"), std::string::npos) << e.what();
    EXPECT_EQ(e.line(), 5) << e.what();
    EXPECT_EQ(e.field(), "timestamp") << e.what();
  }
}

TEST(Replay, UnreadableImageIsAnErrorOrACountedSkip) {
  const fs::path d = copyV101("badimage");
  const auto stamps = cameraStamps(d / "mav0" / "cam0" / "data.csv");
  const fs::path bad = d / "mav0" / "cam1" / "data" / (std::to_string(stamps[7]) + ".png");
  writeText(bad, "\x89PNG this is not an image");
  {
    StubEstimator est;
    const ParseError e = expectParseError([&] { runReplay(d.string(), est, nullptr, quietOptions(d.parent_path() / "out")); });
    EXPECT_NE(std::string(e.what()).find(std::to_string(stamps[7])), std::string::npos) << e.what();
  }
  ReplayOptions o = quietOptions(d.parent_path() / "out2");
  o.skipBadImages = true;
  StubEstimator est;
  const ReplaySummary s = runReplay(d.string(), est, nullptr, o);
  EXPECT_EQ(s.skippedBadImages, 1u);
  EXPECT_EQ(s.framesProcessed, 23u);
  EXPECT_EQ(std::count(est.frameTimes.begin(), est.frameTimes.end(), stamps[7]), 0);
}

TEST(Replay, ImuGapIsAnErrorOrCounted) {
  const fs::path d = copyV101("imugap");
  // Remove 40 samples (200 ms at 200 Hz) in the middle of the frames; write a plain data.csv.
  gzFile gz = gzopen((d / "mav0" / "imu0" / "data.csv.gz").c_str(), "rb");
  ASSERT_NE(gz, nullptr);
  std::string text;
  char buf[4096];
  int n;
  while ((n = gzread(gz, buf, sizeof buf)) > 0) text.append(buf, static_cast<std::size_t>(n));
  gzclose(gz);
  std::istringstream is(text);
  std::string l, kept;
  int row = 0;
  std::int64_t before = 0, after = 0;
  while (std::getline(is, l)) {
    if (!l.empty() && l[0] != '#') {
      ++row;
      if (row > 300 && row <= 340) continue;
      if (row == 300) before = std::stoll(l);
      if (row == 341) after = std::stoll(l);
    }
    kept += l + "\n";
  }
  fs::remove(d / "mav0" / "imu0" / "data.csv.gz");
  writeText(d / "mav0" / "imu0" / "data.csv", kept);
  {
    StubEstimator est;
    const ParseError e = expectParseError([&] { runReplay(d.string(), est, nullptr, quietOptions(d.parent_path() / "out")); });
    EXPECT_NE(std::string(e.what()).find("IMU gap"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(std::to_string(after)), std::string::npos) << e.what();
  }
  ReplayOptions o = quietOptions(d.parent_path() / "out2");
  o.imuGapPolicy = ImuGapPolicy::Warn;
  StubEstimator est;
  const ReplaySummary s = runReplay(d.string(), est, nullptr, o);
  EXPECT_EQ(s.imuGaps, 1u);
  EXPECT_NEAR(s.largestImuGap_s, static_cast<double>(after - before) * 1e-9, 1e-12);
  EXPECT_EQ(s.framesProcessed, 24u);
}

TEST(Replay, FeatureTrackDatasetReplacesTheFrontEnd) {
  // cam0 sees landmarks 1-3 in frame 0, 1-4 in frame 1, 2-4 in frame 2; cam1 sees 2 and 4 in
  // frame 1 only. Images are deleted: the replay must not need them.
  const fs::path d = copyV101("tracks");
  fs::remove_all(d / "mav0" / "cam0" / "data");
  fs::remove_all(d / "mav0" / "cam1" / "data");
  const auto stamps = cameraStamps(d / "mav0" / "cam0" / "data.csv");
  const vio::CameraModel m0(vio::readCameraSensorYaml((d / "mav0" / "cam0" / "sensor.yaml").string()).intrinsics);
  const vio::CameraModel m1(vio::readCameraSensorYaml((d / "mav0" / "cam1" / "sensor.yaml").string()).intrinsics);
  auto px = [&](const vio::CameraModel& m, std::uint64_t id) {
    const Eigen::Vector2d xn(0.05 * static_cast<double>(id) - 0.1, 0.02 * static_cast<double>(id));
    return *m.project(Eigen::Vector3d(xn.x(), xn.y(), 1.0));
  };
  std::ostringstream c0, c1;
  c0.precision(10);
  c1.precision(10);
  c0 << "#timestamp [ns],landmark_id,u [px],v [px]\n";
  const std::vector<std::vector<std::uint64_t>> seen = {{1, 2, 3}, {1, 2, 3, 4}, {2, 3, 4}};
  for (std::size_t k = 0; k < seen.size(); ++k)
    for (std::uint64_t id : seen[k]) {
      const Eigen::Vector2d p = px(m0, id);
      c0 << stamps[k] << "," << id << "," << p.x() << "," << p.y() << "\n";
    }
  for (std::uint64_t id : {2u, 4u}) {
    const Eigen::Vector2d p = px(m1, id);
    c1 << stamps[1] << "," << id << "," << p.x() << "," << p.y() << "\n";
  }
  writeText(d / "mav0" / "cam0" / "features.csv", c0.str());
  writeText(d / "mav0" / "cam1" / "features.csv", c1.str());

  const auto t0 = readFeatureTracksCsv((d / "mav0" / "cam0" / "features.csv").string());
  const auto t1 = readFeatureTracksCsv((d / "mav0" / "cam1" / "features.csv").string());
  FeatureTrackFrames frames(t0, m0, t1, &m1);
  ASSERT_EQ(frames.size(), 3u);
  const vio::FeatureFrame f0 = frames.frame(0), f1 = frames.frame(1), f2 = frames.frame(2);
  EXPECT_EQ(f1.features.size(), 4u);
  for (const auto& o : f1.features) {
    const Eigen::Vector2d xn(0.05 * static_cast<double>(o.id) - 0.1, 0.02 * static_cast<double>(o.id));
    EXPECT_LT((o.normalized0 - xn).norm(), 1e-7) << o.id;
    EXPECT_EQ(o.stereo, o.id == 2 || o.id == 4) << o.id;
    if (o.stereo) {
      EXPECT_LT((o.normalized1 - xn).norm(), 1e-7);
    }
    EXPECT_EQ(o.trackLength, o.id == 4 ? 1 : 2) << o.id;
  }
  for (const auto& o : f2.features) EXPECT_EQ(o.trackLength, o.id == 4 ? 2 : 3) << o.id;
  EXPECT_FALSE(f0.features[0].stereo);

  StubEstimator est;
  const ReplaySummary s = runReplay(d.string(), est, nullptr, quietOptions(d.parent_path() / "out"));
  EXPECT_TRUE(s.featureTracks);
  // The image stamps without a track row are empty frames (withImageStamps; issue 43).
  EXPECT_EQ(s.framesProcessed, stamps.size());
  std::vector<std::size_t> counts(stamps.size(), 0);
  counts[0] = 3;
  counts[1] = 4;
  counts[2] = 3;
  EXPECT_EQ(est.featureCounts, counts);
  EXPECT_TRUE(est.orderOk);
}

// --save-tracks: the front end's tracks of the real V1_01 images written as a feature-only
// dataset; replaying that folder hands the estimator the same frames (stamps, ids, pixels to the
// written 1e-6 px, normalised coordinates through the same camera model, stereo matches).
TEST(Replay, SavedFrontEndTracksReplayAsTheSameFrames) {
  const fs::path root = scratch("save_tracks");
  StubEstimator images;
  ReplayOptions o = quietOptions(root / "out_images");
  o.saveTracksDir = (root / "tracks").string();
  runReplay(kV101.string(), images, nullptr, o);
  ASSERT_TRUE(fs::is_regular_file(root / "tracks" / "mav0" / "cam0" / "features.csv"));
  ASSERT_TRUE(fs::is_regular_file(root / "tracks" / "mav0" / "cam1" / "features.csv"));
  EXPECT_TRUE(fs::is_symlink(root / "tracks" / "mav0" / "imu0"));
  EXPECT_FALSE(fs::exists(root / "tracks" / "mav0" / "cam0" / "data"));  // no images

  StubEstimator tracks;
  const ReplaySummary s = runReplay((root / "tracks").string(), tracks, nullptr, quietOptions(root / "out_tracks"));
  EXPECT_TRUE(s.featureTracks);
  ASSERT_EQ(tracks.frames.size(), images.frames.size());
  std::size_t stereo = 0, total = 0;
  for (std::size_t i = 0; i < images.frames.size(); ++i) {
    const vio::FeatureFrame& a = images.frames[i];
    const vio::FeatureFrame& b = tracks.frames[i];
    EXPECT_EQ(a.t_ns, b.t_ns);
    ASSERT_EQ(a.features.size(), b.features.size()) << "frame " << i;
    std::map<std::uint64_t, const vio::FeatureObservation*> byId;
    for (const auto& f : b.features) byId[f.id] = &f;
    for (const auto& f : a.features) {
      ASSERT_EQ(byId.count(f.id), 1u) << "frame " << i << " id " << f.id;
      const vio::FeatureObservation& g = *byId[f.id];
      EXPECT_LT((f.pixel0 - g.pixel0).cwiseAbs().maxCoeff(), 5.1e-7);
      EXPECT_LT((f.normalized0 - g.normalized0).norm(), 1e-8);
      EXPECT_EQ(f.stereo, g.stereo);
      if (f.stereo && g.stereo) {
        EXPECT_LT((f.pixel1 - g.pixel1).cwiseAbs().maxCoeff(), 5.1e-7);
        EXPECT_LT((f.normalized1 - g.normalized1).norm(), 1e-8);
        ++stereo;
      }
      // Track lengths: counted again from consecutive stamps, equal while the first frame's
      // tracks have not been cut by the written range.
      EXPECT_EQ(f.trackLength, g.trackLength) << "frame " << i << " id " << f.id;
      ++total;
    }
  }
  EXPECT_GT(total, 24u * 50u);
  EXPECT_GT(stereo, total / 2);

  // The folder must be new or empty; a dataset of tracks has no front end to record.
  StubEstimator again;
  EXPECT_THROW(runReplay(kV101.string(), again, nullptr, o), std::runtime_error);
  ReplayOptions o2 = quietOptions(root / "out_again");
  o2.saveTracksDir = (root / "tracks2").string();
  EXPECT_THROW(runReplay((root / "tracks").string(), again, nullptr, o2), std::invalid_argument);
}

TEST(ReplayParsers, FeatureTracksMalformed) {
  auto err = [](const std::string& text) {
    return expectParseError([&] { parseFeatureTracksCsv(text, "f.csv"); });
  };
  ParseError e = err("100,5,1\n");
  EXPECT_EQ(e.line(), 1);
  EXPECT_EQ(e.field(), "v");
  e = err("# h\n100,5,1,2\n50,6,1,2\n");
  EXPECT_EQ(e.line(), 3);
  EXPECT_EQ(e.field(), "timestamp");
  e = err("100,5,1,2\n100,5,3,4\n");
  EXPECT_EQ(e.line(), 2);
  EXPECT_EQ(e.field(), "landmark_id");
  e = err("100,x5,1,2\n");
  EXPECT_EQ(e.field(), "landmark_id");
  e = err("100,5,1,nan\n");
  EXPECT_EQ(e.field(), "v");
  e = err("-100,5,1,2\n");
  EXPECT_EQ(e.field(), "timestamp");
  const auto ok = parseFeatureTracksCsv("100,5,1.5,2.5\r\n100,6,3,4\r\n200,5,1,2\n", "f.csv");
  ASSERT_EQ(ok.size(), 2u);
  EXPECT_EQ(ok[0].obs.size(), 2u);
  EXPECT_EQ(ok[0].obs[0].pixel, Eigen::Vector2d(1.5, 2.5));
}

TEST(ReplayParsers, Config) {
  const ReplayConfig c = parseReplayConfig(
      "replay:\n  max_imu_gap_s: 0.1\n  imu_gaps: warn\n  skip_bad_images: true\n  start_s: 1.5\n  duration_s: 10\n"
      "estimator: sri.yaml\ngnss_fusion:\n  mode: vio+dopp\n",
      "r.yaml", "/cfg");
  EXPECT_EQ(c.options.maxImuGap_s, 0.1);
  EXPECT_EQ(c.options.imuGapPolicy, ImuGapPolicy::Warn);
  EXPECT_TRUE(c.options.skipBadImages);
  EXPECT_EQ(c.options.start_s, 1.5);
  EXPECT_EQ(c.options.duration_s, 10.0);
  EXPECT_EQ(c.estimatorConfig, "/cfg/sri.yaml");
  EXPECT_TRUE(c.hasGnssFusion);
  auto err = [](const std::string& text) { return expectParseError([&] { parseReplayConfig(text, "r.yaml"); }); };
  ParseError e = err("replay:\n  imu_gaps: sometimes\n");
  EXPECT_EQ(e.line(), 2);
  EXPECT_EQ(e.field(), "replay.imu_gaps");
  e = err("replay:\n  start_s: 1\n  bogus: 2\n");
  EXPECT_EQ(e.line(), 3);
  EXPECT_EQ(e.field(), "replay.bogus");
  e = err("replay:\n  max_imu_gap_s: -1\n");
  EXPECT_EQ(e.field(), "replay.max_imu_gap_s");
  e = err("replay:\n  evaluate: maybe\n");
  EXPECT_EQ(e.field(), "replay.evaluate");
  const ReplayConfig t = parseReplayConfig("replay:\n  max_track_length: 30\n  max_track_travel_px: 80\n", "r.yaml");
  EXPECT_EQ(t.options.frontend.tracker.maxTrackLength, 30);
  EXPECT_EQ(t.options.frontend.tracker.maxTrackTravel, 80.0);
  e = err("replay:\n  max_track_length: 2.5\n");
  EXPECT_EQ(e.field(), "replay.max_track_length");
  const ReplayConfig u = parseReplayConfig("replay:\n  align_templates: false\n  template_max_track_travel_px: 120\n", "r.yaml");
  EXPECT_FALSE(u.options.frontend.tracker.alignTemplates);
  EXPECT_EQ(u.options.frontend.tracker.templateMaxTrackTravel, 120.0);
  EXPECT_EQ(parseReplayConfig("replay:\n  klt_window_px: 11\n", "r.yaml").options.frontend.tracker.klt.window, 11);
  EXPECT_FALSE(ReplayOptions{}.frontend.tracker.patch.translationFallback);
  EXPECT_TRUE(parseReplayConfig("replay:\n  template_translation_fallback: true\n", "r.yaml")
                  .options.frontend.tracker.patch.translationFallback);
  e = err("replay:\n  template_translation_fallback: 2\n");
  EXPECT_EQ(e.field(), "replay.template_translation_fallback");
  for (const char* bad : {"replay:\n  klt_window_px: 12\n", "replay:\n  klt_window_px: 3\n", "replay:\n  klt_window_px: 9.5\n"}) {
    e = err(bad);
    EXPECT_EQ(e.field(), "replay.klt_window_px") << bad;
  }
  e = err("replay:\n  align_templates: sometimes\n");
  EXPECT_EQ(e.field(), "replay.align_templates");
  e = err("replay:\n  template_max_track_travel_px: -3\n");
  EXPECT_EQ(e.field(), "replay.template_max_track_travel_px");
  EXPECT_EQ(e.line(), 2);
  e = err("replay:\n  start_s: 0\n  max_track_travel_px: -1\n");
  EXPECT_EQ(e.field(), "replay.max_track_travel_px");
  EXPECT_EQ(e.line(), 3);
  e = err("other: 1\n");
  EXPECT_EQ(e.field(), "other");
  e = err("[1, 2\n");
  EXPECT_EQ(e.field(), "YAML");
  EXPECT_THROW(loadReplayConfig("/nonexistent/replay.yaml"), ParseError);
}
