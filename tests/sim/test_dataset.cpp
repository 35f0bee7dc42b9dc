// gvins-sim dataset folders, checked from the files alone against independent truth:
// - feature-only mode: the pixels of features.csv are OpenCV's projection (cv::projectPoints,
//   not the simulator's vio::CameraModel) of truth/landmarks.csv through truth/camN_poses.csv
//   and sensor.yaml; the pixel noise and outlier rate have the configured statistics; tracks
//   keep their landmark ids across images;
// - the IMU log and ground truth read back with vio's EuRoC readers, and the noise-free IMU log
//   integrated by vio's ImuPropagator (gravity from dataset.yaml) reproduces the written truth;
// - dataset.yaml states the time convention, the frame origin and the calibration that the
//   sensor.yaml files hold;
// - the same scenario and seed give byte-identical files for any number of threads;
// - gnss/ssr.rtcm3 (precise_products.ssr_interval_s, default 5 s) decodes to combined orbit/clock
//   corrections every 5 s over the GNSS span which, applied to nav.rnx, give the states of
//   precise.sp3/.clk with satellites.atx; ssr_interval_s: 0 writes no such file.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <unistd.h>
#include <vector>

#include <opencv2/calib3d.hpp>
#include <yaml-cpp/yaml.h>

#include "gvins/base/constants.hpp"
#include "gvins/base/rinex_obs_reader.hpp"
#include "gvins/base/yaml_reader.hpp"
#include "gvins/ephemeris/ephemeris_store.hpp"
#include "gvins/ephemeris/precise_product_files.hpp"
#include "gvins/ephemeris/rinex_nav.hpp"
#include "gvins/rtcm/ssr_file.hpp"
#include "gvins/sim/dataset_generator.hpp"
#include "gvins/sim/scenario.hpp"
#include "gvins/vio/euroc_csv.hpp"
#include "gvins/vio/imu_propagation.hpp"
#include "gvins/vio/sensor_yaml.hpp"
#include "gvins/vio/so3.hpp"

namespace gvins::sim {
namespace {

namespace fs = std::filesystem;

/// A fresh folder under the temporary directory, removed at the end of the test.
class TempDir {
 public:
  explicit TempDir(const std::string& name)
      : path_(fs::temp_directory_path() / ("gvins_sim_" + name + "_" + std::to_string(::getpid()))) {
    fs::remove_all(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

/// Rows of a CSV file without its '#' header lines, as numbers (the test's own reader).
std::vector<std::vector<double>> readNumbers(const fs::path& p) {
  std::ifstream in(p);
  EXPECT_TRUE(in.good()) << p;
  std::vector<std::vector<double>> rows;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::vector<double> r;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) r.push_back(std::strtod(cell.c_str(), nullptr));
    rows.push_back(std::move(r));
  }
  return rows;
}

/// Integer columns (stamps and landmark ids do not fit a double exactly in general).
std::vector<std::vector<std::int64_t>> readIntegers(const fs::path& p, std::size_t columns) {
  std::ifstream in(p);
  std::vector<std::vector<std::int64_t>> rows;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::int64_t> r;
    std::stringstream ss(line);
    std::string cell;
    for (std::size_t i = 0; i < columns && std::getline(ss, cell, ','); ++i) r.push_back(std::strtoll(cell.c_str(), nullptr, 10));
    rows.push_back(std::move(r));
  }
  return rows;
}

/// A short hovering-start circle (about 25 s) without GNSS.
std::string shortFlight(const std::string& cameras) {
  return "name: short_test\n"
         "trajectory: {pattern: circle, height_m: 30, length_m: 120, speed_mps: 6, laps: 1,\n"
         "             takeoff_landing: false, hover_start_s: 2, hover_end_s: 2, wobble_deg: 0.5}\n"
         "imu: {white_noise: false, bias_random_walk: false, gyro_bias_sigma_radps: 0, accel_bias_sigma_mps2: 0}\n"
         "gnss: none\n" +
         cameras;
}

GenerationSummary generate(const std::string& yaml, const fs::path& dir, std::uint64_t seed, int threads = 2) {
  const Scenario sc = parseScenario(yaml, "test.yaml");
  GenerationOptions o;
  o.seed = seed;
  o.threads = threads;
  return generateDataset(sc, dir, o);
}

struct Pose {
  Eigen::Matrix3d R_WC;
  Eigen::Vector3d p_WC;
};

std::map<std::int64_t, Pose> readPoses(const fs::path& p) {
  std::map<std::int64_t, Pose> out;
  const auto stamps = readIntegers(p, 1);
  const auto rows = readNumbers(p);
  EXPECT_EQ(stamps.size(), rows.size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const auto& r = rows[i];
    EXPECT_EQ(r.size(), 8u);
    Pose q;
    q.p_WC = Eigen::Vector3d(r[1], r[2], r[3]);
    q.R_WC = Eigen::Quaterniond(r[4], r[5], r[6], r[7]).normalized().toRotationMatrix();
    out[stamps[i][0]] = q;
  }
  return out;
}

/// OpenCV's projection of world points through a camera pose and sensor.yaml calibration.
std::vector<cv::Point2d> opencvProject(const vio::CameraCalibration& cal, const Pose& pose,
                                       const std::vector<Eigen::Vector3d>& p_W) {
  const Eigen::Matrix3d R_CW = pose.R_WC.transpose();
  const Eigen::Vector3d t_CW = -R_CW * pose.p_WC;
  cv::Mat R(3, 3, CV_64F), rvec, tvec(3, 1, CV_64F);
  for (int i = 0; i < 3; ++i) {
    tvec.at<double>(i) = t_CW[i];
    for (int j = 0; j < 3; ++j) R.at<double>(i, j) = R_CW(i, j);
  }
  cv::Rodrigues(R, rvec);
  const auto& k = cal.intrinsics;
  const cv::Matx33d K(k.fx, 0, k.cx, 0, k.fy, k.cy, 0, 0, 1);
  std::vector<cv::Point3d> obj;
  for (const auto& p : p_W) obj.emplace_back(p.x(), p.y(), p.z());
  std::vector<cv::Point2d> px;
  if (obj.empty()) return px;
  const cv::Vec4d d(k.distortion[0], k.distortion[1], k.distortion[2], k.distortion[3]);
  cv::projectPoints(obj, rvec, tvec, K, d, px);
  return px;
}

TEST(SimDataset, FeaturePixelsAreOpenCvProjectionsOfTheTruthLandmarks) {
  TempDir dir("features_exact");
  const auto sum = generate(shortFlight("cameras: {output: features, features: {pixel_noise_px: 0, max_per_image: 150}}\n"),
                            dir.path(), 5);
  ASSERT_EQ(sum.cameras, 2);
  ASSERT_GT(sum.framesPerCamera, 400u);
  // Landmarks.
  std::map<std::uint64_t, Eigen::Vector3d> landmarks;
  {
    const auto ids = readIntegers(dir.path() / "truth" / "landmarks.csv", 1);
    const auto rows = readNumbers(dir.path() / "truth" / "landmarks.csv");
    ASSERT_EQ(ids.size(), rows.size());
    for (std::size_t i = 0; i < rows.size(); ++i) landmarks[static_cast<std::uint64_t>(ids[i][0])] = {rows[i][1], rows[i][2], rows[i][3]};
  }
  EXPECT_EQ(landmarks.size(), sum.landmarks);
  for (int c = 0; c < 2; ++c) {
    const std::string cam = "cam" + std::to_string(c);
    const vio::CameraCalibration cal = vio::readCameraSensorYaml((dir.path() / "mav0" / cam / "sensor.yaml").string());
    const auto poses = readPoses(dir.path() / "truth" / (cam + "_poses.csv"));
    ASSERT_EQ(poses.size(), sum.framesPerCamera);
    const auto ids = readIntegers(dir.path() / "mav0" / cam / "features.csv", 2);
    const auto px = readNumbers(dir.path() / "mav0" / cam / "features.csv");
    ASSERT_EQ(ids.size(), px.size());
    ASSERT_GT(ids.size(), 100u * sum.framesPerCamera);
    // Group by image.
    std::map<std::int64_t, std::vector<std::size_t>> byImage;
    for (std::size_t i = 0; i < ids.size(); ++i) byImage[ids[i][0]].push_back(i);
    EXPECT_EQ(byImage.size(), sum.framesPerCamera);
    double worst = 0.0;
    std::size_t checked = 0, minPerImage = 1 << 30;
    for (const auto& [stamp, rows] : byImage) {
      const auto pose = poses.find(stamp);
      ASSERT_NE(pose, poses.end()) << stamp;
      std::vector<Eigen::Vector3d> pts;
      for (std::size_t i : rows) {
        const auto l = landmarks.find(static_cast<std::uint64_t>(ids[i][1]));
        ASSERT_NE(l, landmarks.end());
        pts.push_back(l->second);
      }
      const auto proj = opencvProject(cal, pose->second, pts);
      for (std::size_t j = 0; j < rows.size(); ++j) {
        const double du = proj[j].x - px[rows[j]][2], dv = proj[j].y - px[rows[j]][3];
        worst = std::max(worst, std::hypot(du, dv));
        EXPECT_GE(px[rows[j]][2], 0.0);
        EXPECT_LE(px[rows[j]][2], cal.intrinsics.width - 1.0);
        EXPECT_GE(px[rows[j]][3], 0.0);
        EXPECT_LE(px[rows[j]][3], cal.intrinsics.height - 1.0);
        ++checked;
      }
      minPerImage = std::min(minPerImage, rows.size());
    }
    std::printf("%s: %zu noise-free observations, largest difference to cv::projectPoints %.2e px, at least %zu per image\n",
                cam.c_str(), checked, worst, minPerImage);
    // Pixels are written with 4 decimals (rounding <= 7.1e-5 px).
    EXPECT_LT(worst, 1e-4);
    EXPECT_GE(minPerImage, 100u);
    // Tracks: most landmarks of an image are seen again in the next one.
    std::size_t kept = 0, total = 0;
    std::set<std::int64_t> previous;
    for (const auto& [stamp, rows] : byImage) {
      std::set<std::int64_t> now;
      for (std::size_t i : rows) now.insert(ids[i][1]);
      if (!previous.empty()) {
        for (auto id : previous) kept += now.count(id);
        total += previous.size();
      }
      previous = std::move(now);
    }
    EXPECT_GT(static_cast<double>(kept) / static_cast<double>(total), 0.9) << cam;
  }
}

TEST(SimDataset, FeatureNoiseAndOutliersHaveTheConfiguredStatistics) {
  TempDir dir("features_noise");
  generate(shortFlight("cameras:\n  output: features\n  list: [{}]\n"
                       "  features: {pixel_noise_px: 0.7, outlier_rate: 0.04, outlier_offset_px: 30}\n"),
           dir.path(), 9);
  const auto obs = readNumbers(dir.path() / "mav0" / "cam0" / "features.csv");
  const auto tru = readNumbers(dir.path() / "truth" / "cam0_features.csv");
  ASSERT_EQ(obs.size(), tru.size());
  ASSERT_GT(obs.size(), 50000u);
  double s = 0.0, s2 = 0.0;
  std::size_t n = 0, outliers = 0;
  for (std::size_t i = 0; i < obs.size(); ++i) {
    ASSERT_EQ(obs[i][1], tru[i][1]);
    if (tru[i][4] != 0.0) {
      ++outliers;
      continue;
    }
    for (int k : {2, 3}) {
      const double d = obs[i][static_cast<std::size_t>(k)] - tru[i][static_cast<std::size_t>(k)];
      s += d;
      s2 += d * d;
      ++n;
    }
  }
  const double mean = s / n, sigma = std::sqrt(s2 / n - mean * mean);
  const double rate = static_cast<double>(outliers) / static_cast<double>(obs.size());
  std::printf("pixel noise: mean %.4f px, sigma %.4f px over %zu values; outliers %.4f\n", mean, sigma, n, rate);
  EXPECT_NEAR(sigma, 0.7, 0.02);
  EXPECT_NEAR(mean, 0.0, 0.01);
  EXPECT_NEAR(rate, 0.04, 0.005);
}

TEST(SimDataset, NoiseFreeImuLogIntegratesToTheWrittenTruth) {
  TempDir dir("imu_files");
  const auto sum = generate(shortFlight("cameras: {list: []}\n"), dir.path(), 3);
  const auto imu = vio::readImuCsv((dir.path() / "mav0" / "imu0" / "data.csv").string());
  const auto gt = vio::readGroundTruthCsv((dir.path() / "mav0" / "state_groundtruth_estimate0" / "data.csv").string());
  ASSERT_EQ(imu.size(), sum.imuSamples);
  ASSERT_EQ(gt.size(), imu.size());
  EXPECT_NEAR(static_cast<double>(imu.size()), sum.duration * 200.0 + 1.0, 1.0);
  const YAML::Node ds = YamlReader::loadFile((dir.path() / "dataset.yaml").string());
  const double g = ds["gravity"]["magnitude_mps2"].as<double>();
  const vio::ImuCalibration ic = vio::readImuSensorYaml((dir.path() / "mav0" / "imu0" / "sensor.yaml").string());
  EXPECT_EQ(ic.noise.rate_hz, 200.0);
  const vio::ImuPropagator prop(ic.noise, g);
  vio::ImuState x = gt.front().state;
  const vio::ImuState& truth = gt.back().state;
  prop.propagate(x, imu, truth.t_ns);
  const double dp = (x.p_WI - truth.p_WI).norm();
  const double dth = vio::so3::log(truth.R_WI.transpose() * x.R_WI).norm();
  std::printf("IMU file over %.1f s: |dp| %.2e m, |dv| %.2e m/s, |dtheta| %.2e rad\n", sum.duration, dp,
              (x.v_WI - truth.v_WI).norm(), dth);
  EXPECT_GT(sum.pathLength, 100.0);
  EXPECT_LT(dp, 1e-3);
  EXPECT_LT((x.v_WI - truth.v_WI).norm(), 1e-4);
  EXPECT_LT(dth, 1e-6);
}

TEST(SimDataset, DatasetYamlStatesConventionsAndCalibration) {
  TempDir dir("yaml");
  const auto sum = generate(shortFlight("cameras: {output: features}\nlever_arm_m: [0.1, -0.02, 0.2]\n"), dir.path(), 4);
  const YAML::Node ds = YamlReader::loadFile((dir.path() / "dataset.yaml").string());
  EXPECT_EQ(ds["format"].as<std::string>(), "gvins-sim-dataset");
  EXPECT_NE(ds["time"]["convention"].as<std::string>().find("GPST"), std::string::npos);
  // 2024-06-24 08:20:00 GPST = GPS week 2320, TOW 116400 s (Monday 08:20;
  // 1403252400 s after 1980-01-06).
  EXPECT_EQ(ds["time"]["gps_week"].as<int>(), 2320);
  EXPECT_DOUBLE_EQ(ds["time"]["gps_tow_s"].as<double>(), 116400.0);
  EXPECT_EQ(ds["time"]["start_ns"].as<std::int64_t>(), 1403252400LL * 1000000000LL);
  EXPECT_DOUBLE_EQ(ds["local_frame"]["origin_latitude_deg"].as<double>(), 35.134707705);
  const auto lever = ds["lever_arm_m"].as<std::vector<double>>();
  ASSERT_EQ(lever.size(), 3u);
  EXPECT_DOUBLE_EQ(lever[2], 0.2);
  ASSERT_EQ(ds["cameras"]["list"].size(), 2u);
  for (int c = 0; c < 2; ++c) {
    const YAML::Node n = ds["cameras"]["list"][c];
    const vio::CameraCalibration cal = vio::readCameraSensorYaml((dir.path() / n["sensor_yaml"].as<std::string>()).string());
    const auto k = n["intrinsics"].as<std::vector<double>>();
    ASSERT_EQ(k.size(), 4u);
    EXPECT_EQ(k[0], cal.intrinsics.fx);
    EXPECT_EQ(k[3], cal.intrinsics.cy);
    const auto T = n["T_BS"].as<std::vector<double>>();
    ASSERT_EQ(T.size(), 16u);
    // (vio's reader re-orthonormalises the rotation: equal to rounding.)
    for (int i = 0; i < 16; ++i) EXPECT_NEAR(T[static_cast<std::size_t>(i)], cal.T_BS(i / 4, i % 4), 1e-12);
  }
  EXPECT_EQ(ds["cameras"]["frames"].as<std::size_t>(), sum.framesPerCamera);
  EXPECT_TRUE(ds["gnss"].IsNull());
}

/// Every file under a folder, relative path -> bytes, without the RINEX "PGM / RUN BY / DATE"
/// header lines (they hold the wall-clock time of writing).
std::map<std::string, std::string> readTree(const fs::path& root) {
  std::map<std::string, std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(root)) {
    if (!e.is_regular_file()) continue;
    std::ifstream in(e.path(), std::ios::binary);
    std::stringstream ss;
    std::string text, line;
    while (std::getline(in, line))
      if (line.find("PGM / RUN BY / DATE") == std::string::npos) text += line + '\n';
    out[fs::relative(e.path(), root).generic_string()] = text;
  }
  return out;
}

TEST(SimDataset, SameSeedSameBytesForAnyThreadCount) {
  // Small images keep the three renderings quick; threads only share out the images.
  TempDir a("repro_a"), b("repro_b"), c("repro_c");
  const std::string yaml =
      "name: repro\n"
      "trajectory: {pattern: circle, height_m: 20, length_m: 40, speed_mps: 4, laps: 1, takeoff_landing: false,\n"
      "             hover_start_s: 2, hover_end_s: 2, wobble_deg: 0.5}\n"
      "cameras: {list: [{resolution: [160, 120], intrinsics: [100, 100, 79.5, 59.5]}], png_compression: 1}\n"
      "gnss: {rover: {rate_hz: 5}, base: {enabled: false}}\n";
  generate(yaml, a.path(), 77, 1);
  generate(yaml, b.path(), 77, 2);
  generate(yaml, c.path(), 78, 2);
  const auto ta = readTree(a.path()), tb = readTree(b.path()), tc = readTree(c.path());
  ASSERT_GT(ta.size(), 100u);  // images, IMU, truth, GNSS
  EXPECT_TRUE(ta.count("gnss/rover.obs"));
  ASSERT_EQ(ta.size(), tb.size());
  for (const auto& [name, bytes] : ta) {
    ASSERT_TRUE(tb.count(name)) << name;
    EXPECT_TRUE(bytes == tb.at(name)) << name << " differs between 1 and 2 threads";
  }
  // Another seed changes the noise (IMU, images, GNSS) but not the file set.
  EXPECT_EQ(ta.size(), tc.size());
  EXPECT_NE(ta.at("mav0/imu0/data.csv"), tc.at("mav0/imu0/data.csv"));
  EXPECT_NE(ta.at("gnss/rover.obs"), tc.at("gnss/rover.obs"));
}

/// A short GNSS flight (about 25 s, rover 1 Hz, no base, feature tracks only); `precise` is the
/// body of gnss.precise_products.
std::string shortGnssFlight(const std::string& precise) {
  return "name: ssr_test\n"
         "trajectory: {pattern: circle, height_m: 30, length_m: 120, speed_mps: 6, laps: 1,\n"
         "             takeoff_landing: false, hover_start_s: 2, hover_end_s: 2, wobble_deg: 0.5}\n"
         "cameras: {output: features}\n"
         "gnss: {rover: {rate_hz: 1}, base: {enabled: false}" +
         (precise.empty() ? std::string() : ", precise_products: {" + precise + "}") + "}\n";
}

TEST(SimDataset, SsrStreamGivesThePreciseProductStates) {
  TempDir dir("ssr");
  generate(shortGnssFlight(""), dir.path(), 11);
  const fs::path g = dir.path() / "gnss";
  ASSERT_TRUE(fs::exists(g / "ssr.rtcm3"));
  for (const char* f : {"nav.rnx", "precise.sp3", "precise.clk", "satellites.atx"}) ASSERT_TRUE(fs::exists(g / f)) << f;

  // The rover's span.
  GpsTime first, last;
  {
    RinexObsReader rover((g / "rover.obs").string());
    ObsEpoch e;
    ASSERT_TRUE(rover.next(e));
    first = last = e.time;
    while (rover.next(e)) last = e.time;
  }
  ASSERT_GT(last - first, 20.0);

  const rtcm::SsrFile ssr = rtcm::readSsrFile((g / "ssr.rtcm3").string(), first);
  EXPECT_EQ(ssr.stats.malformed, 0);
  EXPECT_EQ(ssr.stats.framing.crcFailures, 0);
  EXPECT_EQ(ssr.stats.framing.skippedBytes, 0);
  ASSERT_FALSE(ssr.messages.empty());
  // Combined orbit/clock messages every 5 s (udi 5 s), one per system (split into parts with
  // DF388 where it has more than a frame holds) at every epoch, from the rover's first epoch (a
  // multiple of 5 s) to within 5 s of its last.
  std::map<double, std::set<int>> typesAt;  // s after the first epoch -> message numbers
  for (const SsrMessage& m : ssr.messages) {
    EXPECT_EQ(m.header.kind, SsrKind::kCombined);
    EXPECT_EQ(m.header.updateInterval, 5.0);
    EXPECT_FALSE(m.satellites.empty());
    typesAt[m.header.epoch - first].insert(m.header.messageType);
  }
  const std::set<int> allSystems = {1060, 1066, 1243, 1249, 1261};  // G R E J C
  double expected = 0.0;
  for (const auto& [dt, types] : typesAt) {
    EXPECT_NEAR(dt, expected, 1e-9);
    EXPECT_EQ(types, allSystems) << "at +" << dt << " s";
    expected += 5.0;
  }
  EXPECT_NEAR(typesAt.begin()->first, 0.0, 1e-9);
  EXPECT_GE(typesAt.rbegin()->first, (last - first) - 5.0);
  EXPECT_LE(typesAt.rbegin()->first, last - first);

  // The receiver's view: broadcast records of nav.rnx + the SSR stream, against the dataset's
  // products as gvins-replay loads them (SP3 + clock, ANTEX phase-centre offsets).
  EphemerisStore rx;
  rx.add(readRinexNav((g / "nav.rnx").string()));
  for (const SsrMessage& m : ssr.messages) rx.addSsr(m);
  EphemerisStore products;
  products.setPrecise(readPreciseProducts({(g / "precise.sp3").string()}, {(g / "precise.clk").string()}));
  products.setSatelliteAntennas(readAntennaFiles({(g / "satellites.atx").string()}));
  const std::vector<SatId> sats = products.precise()->satellites();
  double worstPos = 0.0, worstClock = 0.0;
  int compared = 0, times = 0, productOnly = 0;
  for (double dt = 0.2; dt < last - first; dt += 2.9) {
    const GpsTime t = first + dt;
    ++times;
    int here = 0;
    for (SatId sat : sats) {
      const auto p = products.preciseState(sat, t);
      const auto s = rx.ssrState(sat, t);
      if (p && !s) {
        // Only satellites without a broadcast record that a real-time receiver holds at the SSR
        // epoch and still at t (the bundled file's BeiDou records transmitted after the run, a
        // Galileo record whose validity ends at the start) lack corrections.
        EphemerisSelection realTime;
        realTime.futureTolerance = -1.0;
        auto heldAt = [&](const GpsTime& x) {
          return sat.system == System::Glonass ? rx.selectGlonass(sat, x, realTime) != nullptr
                                               : rx.selectKepler(sat, x, realTime) != nullptr;
        };
        const bool held = heldAt(first + 5.0 * std::floor(dt / 5.0)) && heldAt(t);
        EXPECT_FALSE(held) << sat.str() << " at +" << dt << " s: products and a broadcast record, but no SSR state";
        ++productOnly;
      }
      if (!p || !s) continue;
      EXPECT_TRUE(s->ssr);
      const double dp = (s->position - p->position).norm();
      const double dc = std::abs(s->clockBias - p->clockBias) * constants::kSpeedOfLight;
      EXPECT_LT(dp, 0.01) << sat.str() << " at +" << dt << " s";
      EXPECT_LT(dc, 0.01) << sat.str() << " at +" << dt << " s";
      worstPos = std::max(worstPos, dp);
      worstClock = std::max(worstClock, dc);
      ++here;
    }
    EXPECT_GE(here, 30) << "at +" << dt << " s";
    compared += here;
  }
  std::printf("ssr.rtcm3: %zu messages, %zu epochs; SSR vs products: %d states at %d times (%d with products only), "
              "worst position %.4f m, clock %.4f m\n",
              ssr.messages.size(), typesAt.size(), compared, times, productOnly, worstPos, worstClock);
  EXPECT_GE(times, 8);

  // ssr_interval_s: 0: the products, but no SSR stream.
  TempDir none("ssr_none");
  generate(shortGnssFlight("ssr_interval_s: 0"), none.path(), 11);
  EXPECT_TRUE(fs::exists(none.path() / "gnss" / "precise.sp3"));
  EXPECT_FALSE(fs::exists(none.path() / "gnss" / "ssr.rtcm3"));
}

}  // namespace
}  // namespace gvins::sim
