// Ground scenarios (config/car_city_drive.yaml, config/handheld_walk.yaml) and what they must
// not change:
// - a 40-second cut of the city drive (one block) simulates in seconds, its forward cameras observe
//   landmarks at every range from a few metres to 120 m (distances from truth/landmarks.csv and
//   truth/camN_poses.csv), and the rover's GNSS truth records blockages and NLOS receptions
//   caused by the buildings;
// - the walk pattern's gait: the vertical bob of `gait_bob_m` once per `gait_step_m` walked,
//   none at rest;
// - the ground-plane path of the UAV flights is unchanged: a short UAV flight (feature tracks and
//   GNSS) and a drive give byte-identical folders to those of the simulator before the 3-D
//   structure existed (commit d25df54; the hashes below were computed from its output, skipping
//   the RINEX "PGM / RUN BY / DATE" lines that carry the run's date).
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <unistd.h>
#include <vector>

#include "gvins/sim/dataset_generator.hpp"
#include "gvins/sim/flight_pattern.hpp"
#include "gvins/sim/scenario.hpp"

namespace gvins::sim {
namespace {

namespace fs = std::filesystem;

fs::path configDir() { return fs::path(GVINS_TEST_DATA) / ".." / ".." / "config"; }

class TempDir {
 public:
  explicit TempDir(const std::string& name)
      : path_(fs::temp_directory_path() / ("gvins_ground_" + name + "_" + std::to_string(::getpid()))) {
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

std::vector<std::vector<std::string>> readCsv(const fs::path& f) {
  std::ifstream in(f);
  std::vector<std::vector<std::string>> rows;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> cols;
    std::stringstream ss(line);
    std::string c;
    while (std::getline(ss, c, ',')) cols.push_back(c);
    rows.push_back(cols);
  }
  return rows;
}

/// FNV-1a 64 over the files of a folder in path order: relative path, NUL, then the content
/// without the lines holding "PGM / RUN BY / DATE".
std::uint64_t folderHash(const fs::path& dir) {
  std::vector<std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) files.push_back(fs::relative(e.path(), dir).generic_string());
  std::sort(files.begin(), files.end());
  std::uint64_t h = 0xCBF29CE484222325ULL;
  auto add = [&h](const std::string& s) {
    for (const unsigned char c : s) {
      h ^= c;
      h *= 0x100000001B3ULL;
    }
  };
  for (const std::string& f : files) {
    add(f);
    add(std::string(1, '\0'));
    std::ifstream in(dir / f, std::ios::binary);
    std::string line;
    while (std::getline(in, line)) {
      if (line.find("PGM / RUN BY / DATE") != std::string::npos) continue;
      add(line);
      if (!in.eof()) add("\n");
    }
  }
  return h;
}

TEST(GroundScenarios, CityDriveCutSeesNearAndFarLandmarksAndUrbanGnss) {
  Scenario sc = loadScenario((configDir() / "car_city_drive.yaml").string());
  ASSERT_TRUE(sc.structure.has_value());
  sc.flight.length = 320.0;  // a block of 56 m x 112 m: about 40 s
  sc.flight.cornerStopSeconds = 0.0;
  sc.text.clear();
  TempDir dir("drive");
  GenerationOptions opt;
  opt.seed = sc.seed;
  const auto t0 = std::chrono::steady_clock::now();
  const GenerationSummary sum = generateDataset(sc, dir.path(), opt);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_GT(sum.duration, 25.0);
  EXPECT_LT(sum.duration, 60.0);
  EXPECT_LT(seconds, sum.duration) << "faster than real time";
  EXPECT_GT(sum.buildings, 4u);

  std::map<std::string, Eigen::Vector3d> landmarks;
  for (const auto& r : readCsv(dir.path() / "truth" / "landmarks.csv"))
    landmarks[r[0]] = Eigen::Vector3d(std::stod(r[1]), std::stod(r[2]), std::stod(r[3]));
  const double edges[] = {0.0, 10.0, 30.0, 60.0, 120.0};
  for (const char* cam : {"cam0", "cam1"}) {
    std::map<std::string, Eigen::Vector3d> poses;
    for (const auto& r : readCsv(dir.path() / "truth" / (std::string(cam) + "_poses.csv")))
      poses[r[0]] = Eigen::Vector3d(std::stod(r[1]), std::stod(r[2]), std::stod(r[3]));
    int bins[4] = {0, 0, 0, 0};
    std::size_t n = 0;
    for (const auto& r : readCsv(dir.path() / "mav0" / cam / "features.csv")) {
      ++n;
      const double d = (landmarks.at(r[1]) - poses.at(r[0])).norm();
      ASSERT_LE(d, 120.0 + 1e-6) << "beyond max_range_m";
      for (int b = 0; b < 4; ++b)
        if (d >= edges[b] && d < edges[b + 1]) ++bins[b];
    }
    for (int b = 0; b < 4; ++b) EXPECT_GT(bins[b], 0) << cam << " range bin " << edges[b] << "-" << edges[b + 1] << " m";
    EXPECT_GT(static_cast<double>(n) / static_cast<double>(sum.framesPerCamera), 100.0) << "features per image";
  }
  // Blockage and NLOS of the rover, from the buildings (random events are off in this scenario).
  int blockages = 0, nlos = 0;
  for (const auto& r : readCsv(dir.path() / "gnss" / "truth" / "events.csv")) {
    if (r.size() < 2) continue;
    for (const std::string& c : r) {
      if (c == "blockage") ++blockages;
      if (c == "nlos") ++nlos;
    }
  }
  EXPECT_GT(blockages, 0);
  EXPECT_GT(nlos, 0);
}

TEST(GroundScenarios, WalkBobsOncePerStepAndNotAtRest) {
  const Scenario sc = loadScenario((configDir() / "handheld_walk.yaml").string());
  ASSERT_EQ(sc.flight.pattern, FlightPattern::Walk);
  FlightSpec f = sc.flight;
  f.length = 120.0;
  f.wobbleDeg = 0.0;
  const auto traj = buildFlight(f, 1);
  // At rest before walking: exactly the hand height.
  for (double t = 0.0; t < f.hoverStart - 0.5; t += 0.1) EXPECT_NEAR(traj->evaluate(t).p_WB.z(), f.restHeight, 1e-9);
  // Along the first straight, at cruise speed: z - rest oscillates with the bob's amplitude
  // (slightly smoothed by the spline), crossing zero twice per step.
  double zMin = 1e9, zMax = -1e9, walked = 0.0;
  int crossings = 0;
  double prevZ = 0.0;
  Eigen::Vector3d prevP = traj->evaluate(f.hoverStart + 3.0).p_WB;
  for (double t = f.hoverStart + 3.0; t < f.hoverStart + 10.0; t += 0.005) {
    const TrajectoryState s = traj->evaluate(t);
    ASSERT_GT(s.v_WB.head<2>().norm(), 1.0);
    const double z = s.p_WB.z() - f.restHeight;
    zMin = std::min(zMin, z);
    zMax = std::max(zMax, z);
    if (t > f.hoverStart + 3.0 && ((prevZ < 0.0) != (z < 0.0))) ++crossings;
    walked += (s.p_WB - prevP).head<2>().norm();
    prevP = s.p_WB;
    prevZ = z;
  }
  EXPECT_NEAR(zMax, f.gait.bob, 0.2 * f.gait.bob);
  EXPECT_NEAR(zMin, -f.gait.bob, 0.2 * f.gait.bob);
  EXPECT_NEAR(crossings, 2.0 * walked / f.gait.stepLength, 2.0);
}

TEST(GroundScenarios, UavAndDriveOutputsUnchanged) {
  // Hashes of the same scenarios simulated by commit d25df54 (before the 3-D structure); the UAV's
  // since the GPS/QZSS L5 group delay is T_GD (IS-GPS-705), which changes its simulated L5 codes.
  const std::string uav =
      "name: regress_uav\nseed: 7\n"
      "trajectory: {type: flight, pattern: figure_eight, height_m: 30, length_m: 60, speed_mps: 6, laps: 1,\n"
      "             takeoff_landing: false, hover_start_s: 2, hover_end_s: 2, wobble_deg: 0.3}\n"
      "imu: {rate_hz: 200}\n"
      "cameras:\n  rate_hz: 20\n  output: features\n  list:\n"
      "    - {name: cam0, look: down, position_m: [0.06, 0.06, -0.04], mount_rpy_deg: [0.4, -0.3, 0.2]}\n"
      "    - {name: cam1, look: down, position_m: [0.06, -0.06, -0.04], mount_rpy_deg: [-0.2, 0.3, -0.4]}\n"
      "gnss:\n  rover: {rate_hz: 5}\n";
  const std::string drive =
      "name: regress_drive\nseed: 9\n"
      "trajectory: {type: flight, pattern: drive, length_m: 300, speed_mps: 8, laps: 2, rest_height_m: 0.5, stop_s: 2}\n"
      "imu: {rate_hz: 100}\ncameras:\n  output: features\n  list: []\ngnss: none\n";
  struct Case {
    const std::string* text;
    std::uint64_t hash;
  };
  for (const Case& c : {Case{&uav, 0x9300288ed9439e14ULL}, Case{&drive, 0x8d0d91cde6440bcfULL}}) {
    const Scenario sc = parseScenario(*c.text, "regress.yaml");
    TempDir dir("regress_" + sc.name);
    GenerationOptions opt;
    opt.seed = sc.seed;
    generateDataset(sc, dir.path() / "d", opt);
    EXPECT_EQ(folderHash(dir.path() / "d"), c.hash) << sc.name << " " << std::hex << folderHash(dir.path() / "d");
  }
}

}  // namespace
}  // namespace gvins::sim
