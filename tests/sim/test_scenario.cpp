// Scenario files: config/default.yaml is the built-in default; the ten config/uav_*.yaml flights
// are the paper's ten UAV datasets (height, length and speed from its tables, checked on the
// trajectories they build); malformed scenarios throw gvins::ParseError naming the file, the line
// and the key, and randomly damaged ones throw nothing else.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <tuple>

#include "gvins/base/parse_error.hpp"
#include "gvins/sim/dataset_generator.hpp"
#include "gvins/sim/scenario.hpp"

namespace gvins::sim {
namespace {

namespace fs = std::filesystem;

fs::path configDir() { return fs::path(GVINS_TEST_DATA) / ".." / ".." / "config"; }

std::string readText(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(Scenario, DefaultFileIsTheBuiltInDefault) {
  const Scenario file = loadScenario((configDir() / "default.yaml").string());
  const Scenario built = defaultScenario();
  EXPECT_EQ(file.name, built.name);
  EXPECT_EQ(file.seed, built.seed);
  EXPECT_EQ(file.frame.startTime, built.frame.startTime);
  EXPECT_NEAR((file.frame.originEcef() - built.frame.originEcef()).norm(), 0.0, 1e-6);
  const auto a = buildTrajectory(file, 1), b = buildTrajectory(built, 1);
  ASSERT_EQ(a->duration(), b->duration());
  for (double t = 0.0; t < a->duration(); t += 0.37) {
    EXPECT_EQ(a->evaluate(t).p_WB, b->evaluate(t).p_WB) << t;
    EXPECT_EQ(a->evaluate(t).R_WB, b->evaluate(t).R_WB) << t;
  }
  // Two minutes (the default flight), stereo, IMU 200 Hz, base 3 km away.
  EXPECT_GT(a->duration(), 100.0);
  EXPECT_LT(a->duration(), 140.0);
  ASSERT_EQ(file.cameras.size(), 2u);
  for (std::size_t c = 0; c < 2; ++c) {
    EXPECT_EQ(file.cameras[c].T_BS, built.cameras[c].T_BS);
    EXPECT_EQ(file.cameras[c].intrinsics.fx, built.cameras[c].intrinsics.fx);
  }
  EXPECT_EQ(file.imu.rateHz, 200.0);
  ASSERT_TRUE(file.gnss && built.gnss);
  EXPECT_TRUE(fs::equivalent(file.gnss->navigationFile, built.gnss->navigationFile));
  EXPECT_EQ(file.gnss->base.distance, 3000.0);
  EXPECT_TRUE(file.texture.board.enabled);
}

TEST(Scenario, TheTenPaperFlightsHaveTheirHeightLengthAndSpeed) {
  // SRI-GVINS paper, section V, tables "RMSE with Psr and Dopp measurements" and "... Dpsr and
  // Ddcp ...": height (m) - length (m) - speed (m/s) of the ten UAV datasets.
  const std::set<std::tuple<int, int, int>> paper = {{60, 1000, 6}, {60, 1000, 4}, {60, 1000, 8}, {60, 1000, 10},
                                                     {60, 400, 8},  {50, 3000, 4}, {50, 3000, 8}, {50, 3000, 12},
                                                     {20, 1000, 8}, {40, 1000, 8}};
  std::set<std::tuple<int, int, int>> found;
  for (const auto& e : fs::directory_iterator(configDir())) {
    const std::string name = e.path().filename().string();
    if (name.rfind("uav_", 0) != 0) continue;
    const Scenario sc = loadScenario(e.path().string());
    const auto traj = buildTrajectory(sc, sc.seed);
    double horizontal = 0.0, maxSpeed = 0.0, maxHeight = 0.0;
    Eigen::Vector3d last = traj->evaluate(0.0).p_WB;
    for (double t = 0.02; t <= traj->duration(); t += 0.02) {
      const TrajectoryState s = traj->evaluate(t);
      horizontal += (s.p_WB - last).head<2>().norm();
      last = s.p_WB;
      maxSpeed = std::max(maxSpeed, s.v_WB.head<2>().norm());
      maxHeight = std::max(maxHeight, s.p_WB.z());
    }
    std::printf("%-26s %5.1f m high, %6.1f m long, %5.2f m/s max, %6.1f s\n", name.c_str(), maxHeight, horizontal, maxSpeed,
                traj->duration());
    const int h = static_cast<int>(std::lround(sc.flight.height)), l = static_cast<int>(std::lround(sc.flight.length)),
              v = static_cast<int>(std::lround(sc.flight.speed));
    EXPECT_TRUE(paper.count({h, l, v})) << name;
    found.insert({h, l, v});
    // The flights built from the files: cruise height, horizontal path and top speed.
    EXPECT_NEAR(maxHeight, h, 0.5) << name;
    EXPECT_NEAR(horizontal, l, 0.02 * l) << name;
    EXPECT_NEAR(maxSpeed, v, 0.05 * v) << name;
    // The paper's rig.
    EXPECT_EQ(sc.cameras.size(), 2u) << name;
    EXPECT_EQ(sc.cameraRate, 20.0) << name;
    EXPECT_EQ(sc.imu.rateHz, 250.0) << name;
    ASSERT_TRUE(sc.gnss) << name;
    EXPECT_EQ(sc.gnss->rover.rate, 5.0) << name;
    EXPECT_EQ(sc.gnss->base.distance, 3000.0) << name;
    EXPECT_TRUE(sc.gnss->base.enabled) << name;
    EXPECT_TRUE(fs::exists(sc.gnss->navigationFile)) << name;
  }
  EXPECT_EQ(found, paper);
}

TEST(Scenario, DemoFlightIsShort) {
  const Scenario sc = loadScenario((configDir() / "demo_short.yaml").string());
  const auto traj = buildTrajectory(sc, sc.seed);
  EXPECT_GT(traj->duration(), 35.0);
  EXPECT_LT(traj->duration(), 60.0);
  EXPECT_EQ(sc.cameras.size(), 2u);
  EXPECT_TRUE(sc.gnss && sc.gnss->base.enabled);
}

TEST(Scenario, ReadsKeysOnTopOfTheDefault) {
  const Scenario sc = parseScenario(
      "name: x\nseed: 18446744073709551615\n"
      "origin: {latitude_deg: -33.9, longitude_deg: 18.4, height_m: 20}\n"
      "start_gpst: \"2024-06-24 08:21:30.5\"\n"
      "trajectory: {pattern: circle, laps: 3, height_m: 25, length_m: 600, speed_mps: 5, turn: left, yaw: fixed, yaw_deg: 45}\n"
      "imu: {rate_hz: 250, earth: rotating, gravity_mps2: normal, gyro_bias_radps: [0.001, 0, 0]}\n"
      "cameras:\n"
      "  rate_hz: 10\n"
      "  output: features\n"
      "  features: {pixel_noise_px: 0.3, max_per_image: 80}\n"
      "  list:\n"
      "    - {resolution: [640, 480], intrinsics: [400, 400, 319.5, 239.5], distortion_model: equidistant,\n"
      "       distortion_coefficients: [0.01, 0, 0, 0], look: forward}\n"
      "lever_arm_m: [0, 0, 0.3]\n"
      "gnss: none\n",
      "dir/x.yaml");
  EXPECT_EQ(sc.name, "x");
  EXPECT_EQ(sc.seed, 18446744073709551615ULL);
  EXPECT_NEAR(sc.frame.origin.lat * 180.0 / M_PI, -33.9, 1e-12);
  EXPECT_EQ(sc.frame.startTime - GpsTime::fromCalendar({2024, 6, 24, 8, 21, 30.0}), 0.5);
  EXPECT_EQ(sc.flight.pattern, FlightPattern::Circle);
  EXPECT_EQ(sc.flight.laps, 3);
  EXPECT_FALSE(sc.flight.turnRight);
  EXPECT_EQ(sc.flight.yaw, YawMode::Fixed);
  EXPECT_EQ(sc.imu.earth, EarthModel::Rotating);
  EXPECT_EQ(sc.imu.gravity, 0.0);
  EXPECT_EQ(sc.cameraRate, 10.0);
  EXPECT_EQ(sc.output, CameraOutput::Features);
  EXPECT_EQ(sc.features.maxPerImage, 80);
  ASSERT_EQ(sc.cameras.size(), 1u);
  EXPECT_EQ(sc.cameras[0].intrinsics.model, vio::DistortionModel::Equidistant);
  EXPECT_EQ(sc.cameras[0].intrinsics.width, 640);
  // Looking forward: the optical axis (camera z) is body x.
  EXPECT_NEAR((sc.cameras[0].T_BS.block<3, 1>(0, 2) - Eigen::Vector3d::UnitX()).norm(), 0.0, 1e-12);
  EXPECT_FALSE(sc.gnss.has_value());
  EXPECT_EQ(sc.leverArm.z(), 0.3);
  // An empty file is the default scenario; a gnss section without a navigation file uses the
  // bundled one.
  EXPECT_EQ(parseScenario("", "e.yaml").name, "default");
  const Scenario g = parseScenario("gnss: {rover: {rate_hz: 2}}\n", "g.yaml");
  ASSERT_TRUE(g.gnss);
  EXPECT_EQ(g.gnss->rover.rate, 2.0);
  EXPECT_EQ(g.gnss->navigationFile, bundledNavigationFile());
}

struct BadCase {
  const char* yaml;
  std::int64_t line;
  const char* key;
};

TEST(Scenario, GroundScenariosReadTheirStructureAndGait) {
  const Scenario car = loadScenario((configDir() / "car_city_drive.yaml").string());
  EXPECT_EQ(car.flight.pattern, FlightPattern::Drive);
  EXPECT_EQ(car.flight.cornerStopSeconds, 8.0);
  EXPECT_EQ(car.output, CameraOutput::Features);
  ASSERT_TRUE(car.structure.has_value());
  EXPECT_EQ(car.structure->streetHalfWidth, 10.0);
  EXPECT_EQ(car.structure->buildingHeightMin, 8.0);
  EXPECT_EQ(car.structure->buildingHeightMax, 45.0);
  ASSERT_EQ(car.cameras.size(), 2u);
  // Forward-looking: the optical axis (camera z) along body x.
  EXPECT_GT((car.cameras[0].T_BS.topLeftCorner<3, 3>() * Eigen::Vector3d::UnitZ()).x(), 0.99);
  const auto drive = buildTrajectory(car, car.seed);
  EXPECT_NEAR(drive->evaluate(drive->duration() / 2).p_WB.z(), 1.4, 1e-6);
  const Scenario walk = loadScenario((configDir() / "handheld_walk.yaml").string());
  EXPECT_EQ(walk.flight.pattern, FlightPattern::Walk);
  EXPECT_EQ(walk.flight.gait.stepLength, 0.7);
  EXPECT_EQ(walk.flight.gait.bob, 0.025);
  EXPECT_EQ(walk.flight.gait.sway, 0.02);
  EXPECT_EQ(walk.flight.gait.tiltDeg, 1.5);
  ASSERT_TRUE(walk.structure.has_value());
  EXPECT_EQ(walk.structure->streetHalfWidth, 6.0);
  const Scenario fuzz = loadScenario((fs::path(GVINS_TEST_DATA) / "fuzz" / "scenario" / "structure_walk.yaml").string());
  ASSERT_TRUE(fuzz.structure.has_value());
  EXPECT_EQ(fuzz.structure->tileSize, 40.0);
}

TEST(Scenario, MalformedInputNamesFileLineAndKey) {
  const BadCase cases[] = {
      {"bogus: 1\n", 1, "bogus"},
      {"name: a\nseed: -3\n", 2, "seed"},
      {"seed: 1.5\n", 1, "seed"},
      {"seed: 99999999999999999999\n", 1, "seed"},
      {"name: [a]\n", 1, "name"},
      {"origin: {latitude_deg: 95}\n", 1, "origin.latitude_deg"},
      {"origin: {lat: 35}\n", 1, "origin.lat"},
      {"start_gpst: yesterday\n", 1, "start_gpst"},
      {"start_gpst: \"2024-13-01 00:00:00\"\n", 1, "start_gpst"},
      {"start_gpst: \"2024-06-24 08:20:00 UTC\"\n", 1, "start_gpst"},
      {"trajectory:\n  speed_mps: fast\n", 2, "trajectory.speed_mps"},
      {"trajectory:\n  speed_mps: 0\n", 2, "trajectory.speed_mps"},
      {"trajectory:\n  speed_mps: .nan\n", 2, "trajectory.speed_mps"},
      {"trajectory:\n  speeed_mps: 3\n", 2, "trajectory.speeed_mps"},
      {"trajectory:\n  pattern: spiral\n", 2, "trajectory.pattern"},
      {"trajectory:\n  type: rocket\n", 2, "trajectory.type"},
      {"trajectory:\n  turn: up\n", 2, "trajectory.turn"},
      {"trajectory:\n  rows: 2.5\n", 2, "trajectory.rows"},
      {"trajectory:\n  waypoints_m: [[1, 2]]\n", 2, "trajectory.waypoints_m"},
      {"trajectory: 5\n", 1, "trajectory"},
      {"trajectory:\n  type: recorded\n", 2, "trajectory"},
      {"trajectory:\n  type: recorded\n  imu_csv: a.csv\n  groundtruth_csv: b.csv\n  smoothing: -1\n", 5,
       "trajectory.smoothing"},
      {"trajectory:\n  type: gnss_track\n  pos_file: a.pos\n", 2, "trajectory"},
      {"trajectory:\n  type: gnss_track\n  pos_file: a.pos\n  imu_csv: b.csv\n  max_quality: 0\n", 5,
       "trajectory.max_quality"},
      {"trajectory:\n  type: gnss_track\n  pos_file: a.pos\n  imu_csv: b.csv\n  groundtruth_csv: c.csv\n", 5,
       "trajectory.groundtruth_csv"},
      {"trajectory:\n  type: gnss_track\n  pos_file: a.pos\n  imu_csv: b.csv\n  rover_log: r.ubx\n", 2,
       "trajectory.rover_log"},
      {"imu:\n  rate_hz: 5\n", 2, "imu.rate_hz"},
      {"imu:\n  earth: round\n", 2, "imu.earth"},
      {"imu:\n  white_noise: maybe\n", 2, "imu.white_noise"},
      {"imu:\n  gyro_bias_radps: [0, 0]\n", 2, "imu.gyro_bias_radps"},
      {"cameras:\n  output: video\n", 2, "cameras.output"},
      {"cameras:\n  list: [{}, {}, {}]\n", 2, "cameras.list"},
      {"cameras:\n  list:\n    - {name: cam3}\n", 3, "cameras.list[0].name"},
      {"cameras:\n  list:\n    - {intrinsics: [0, 400, 300, 200]}\n", 3, "cameras.list[0].intrinsics"},
      {"cameras:\n  list:\n    - {resolution: [640.5, 480]}\n", 3, "cameras.list[0].resolution"},
      {"cameras:\n  list:\n    - {distortion_model: kannala}\n", 3, "cameras.list[0].distortion_model"},
      {"cameras:\n  list:\n    - {T_BS: [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 2]}\n", 3, "cameras.list[0].T_BS"},
      {"cameras:\n  list:\n    - {T_BS: [2, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]}\n", 3, "cameras.list[0].T_BS"},
      {"cameras:\n  list:\n    - {look: up}\n", 3, "cameras.list[0].look"},
      {"cameras:\n  imaging: {exposure_s: 2}\n", 2, "cameras.imaging.exposure_s"},
      {"cameras:\n  features: {outlier_rate: 1.5}\n", 2, "cameras.features.outlier_rate"},
      {"cameras:\n  png_compression: 10\n", 2, "cameras.png_compression"},
      {"scene:\n  texture: {levels: 30}\n", 2, "scene.texture.levels"},
      {"scene:\n  checkerboard: {inner_corners: [1, 6]}\n", 2, "scene.checkerboard.inner_corners"},
      {"scene:\n  structure: {street_half_width_m: 1}\n", 2, "scene.structure.street_half_width_m"},
      {"scene:\n  structure: {building_height_m: [30, 10]}\n", 2, "scene.structure.building_height_m"},
      {"scene:\n  structure: {building_length_m: 20}\n", 2, "scene.structure.building_length_m"},
      {"scene:\n  structure: {pole_spacing_m: 1}\n", 2, "scene.structure.pole_spacing_m"},
      {"scene:\n  structure: {roofs: 3}\n", 2, "scene.structure.roofs"},
      {"scene:\n  structure: {facade_density_per_m2: 10, building_height_m: [10, 1000]}\n", 2, "scene.structure"},
      {"cameras:\n  output: images\nscene:\n  structure: {}\n", 4, "scene.structure"},
      {"trajectory:\n  gait_bob_m: 1\n", 2, "trajectory.gait_bob_m"},
      {"trajectory:\n  corner_stop_s: -1\n", 2, "trajectory.corner_stop_s"},
      {"trajectory:\n  pattern: walk\n  speed_mps: 1.4\n  rest_height_m: 1.3\n", 2, "trajectory"},
      {"lever_arm_m: [1, 2]\n", 1, "lever_arm_m"},
      {"lever_arm_m: [1, 2, x]\n", 1, "lever_arm_m"},
      {"gnss:\n  rover: {rate_hz: 0}\n", 2, "gnss.rover.rate_hz"},
      {"gnss:\n  bogus: 1\n", 2, "gnss.bogus"},
      {"- 1\n- 2\n", 1, ""},
      {"trajectory: {speed_mps: 1\n", 2, "YAML"},
      {"imu: *nothing\n", 1, "YAML"},
  };
  for (const BadCase& c : cases) {
    try {
      parseScenario(c.yaml, "bad.yaml");
      ADD_FAILURE() << "accepted:\n" << c.yaml;
    } catch (const ParseError& e) {
      EXPECT_EQ(e.file(), "bad.yaml") << c.yaml;
      EXPECT_EQ(e.line(), c.line) << c.yaml << "\n" << e.what();
      EXPECT_EQ(e.field(), c.key) << c.yaml << "\n" << e.what();
      EXPECT_FALSE(e.reason().empty()) << c.yaml;
      // The message names all three.
      const std::string what = e.what();
      EXPECT_NE(what.find("bad.yaml"), std::string::npos) << what;
    }
  }
  // Files.
  EXPECT_THROW(loadScenario("/nonexistent/scenario.yaml"), ParseError);
  try {
    parseScenario(std::string("name: a\0b\n", 10), "nul.yaml");
    ADD_FAILURE() << "NUL accepted";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.file(), "nul.yaml");
  }
  EXPECT_THROW(parseScenario(std::string(2 << 20, ' '), "big.yaml"), ParseError);
}

TEST(Scenario, RandomlyDamagedScenariosThrowOnlyParseErrors) {
  // Byte flips, insertions of YAML punctuation and truncations of every shipped scenario: the
  // result is a scenario or a ParseError, never another exception or a crash.
  std::mt19937_64 rng(1234);
  const char punct[] = "{}[]:,-?*&!|>'\"#% \n\t0.e";
  int errors = 0, accepted = 0;
  for (const char* f : {"default.yaml", "demo_short.yaml", "uav_50m_3km_8mps.yaml"}) {
    const std::string text = readText(configDir() / f);
    ASSERT_GT(text.size(), 500u) << f;
    for (int i = 0; i < 700; ++i) {
      std::string s = text;
      const int edits = 1 + static_cast<int>(rng() % 4);
      for (int k = 0; k < edits && !s.empty(); ++k) {
        const std::size_t pos = rng() % s.size();
        switch (rng() % 4) {
          case 0: s[pos] = punct[rng() % (sizeof punct - 1)]; break;
          case 1: s.insert(pos, 1, punct[rng() % (sizeof punct - 1)]); break;
          case 2: s.resize(pos); break;
          default: s[pos] = static_cast<char>(1 + rng() % 255); break;
        }
      }
      try {
        const Scenario sc = parseScenario(s, f);
        ++accepted;
        EXPECT_GT(sc.flight.speed, 0.0);
      } catch (const ParseError& e) {
        ++errors;
        EXPECT_EQ(e.file(), f);
        EXPECT_GE(e.line(), 0);
      }
    }
  }
  std::printf("damaged scenarios: %d accepted, %d parse errors\n", accepted, errors);
  EXPECT_GT(errors, 300);
  EXPECT_GT(accepted, 100);
}

}  // namespace
}  // namespace gvins::sim
