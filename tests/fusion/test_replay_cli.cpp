// gvins-replay end to end as a user runs it: gvins-sim's generator writes a short stereo
// feature-track flight with rover GNSS, precise products and the SSR stream gnss/ssr.rtcm3; the
// tool replays it in vio+dopp+psr mode with the folder's products and with --broadcast --ssr
// (the real-time counterpart of the same products) and with --broadcast alone. Checked from
// metrics.csv: the SSR messages were used, and the global accuracy is that of the products
// (within 5 cm), not that of the broadcast records. An --ssr file that does not exist stops the
// tool with its name.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>
#include <algorithm>

#include "gvins/base/geodetic.hpp"
#include "gvins/gnss/pos_reader.hpp"
#include "gvins/sim/dataset_generator.hpp"
#include "gvins/sim/scenario.hpp"
#include "generate_scenario.hpp"
#include "process_scratch_folder.hpp"

namespace gvins::fusion {
namespace {

namespace fs = std::filesystem;

const std::string kBin = std::string(GVINS_BIN_DIR) + "/gvins-replay";

const fs::path& scratch() { return test::processScratchFolder("gvins_replay_cli_"); }

/// A 40 s figure-eight at 30 m and 6 m/s, stereo feature tracks, rover 5 Hz, no base.
const fs::path& dataset() {
  static const fs::path dir = [] {
    const fs::path d = scratch() / "dataset";
    const std::string y =
        "name: replay_cli_test\n"
        "origin: {latitude_deg: 35.134707705, longitude_deg: 136.977577939, height_m: 104.853}\n"
        "start_gpst: \"2024-06-24 08:20:00\"\n"
        "trajectory: {type: flight, pattern: figure_eight, height_m: 30, length_m: 220, speed_mps: 6, laps: 1,\n"
        "             takeoff_landing: false, hover_start_s: 3, hover_end_s: 2, wobble_deg: 2}\n"
        "imu: {rate_hz: 200}\n"
        "cameras:\n"
        "  rate_hz: 20\n"
        "  output: features\n"
        "  list:\n"
        "    - {name: cam0, look: down, position_m: [0.06, 0.06, -0.04]}\n"
        "    - {name: cam1, look: down, position_m: [0.06, -0.06, -0.04]}\n"
        "lever_arm_m: [0.08, 0.0, 0.18]\n"
        "gnss:\n"
        "  rover: {rate_hz: 5}\n"
        "  base: {enabled: false}\n";
    const sim::GenerationSummary s = test::generateScenario(d, y, "replay_cli_test", 21);
    std::fprintf(stderr, "dataset: %.1f s, %.0f m, %zu frames per camera\n", s.duration, s.pathLength, s.framesPerCamera);
    return d;
  }();
  return dir;
}

struct CliRun {
  int code = -1;
  std::string err;
  std::map<std::string, double> metrics;
};

CliRun replay(const std::string& name, const std::string& args) {
  const fs::path out = scratch() / name;
  const fs::path err = scratch() / (name + ".err");
  const std::string cmd = kBin + " " + dataset().string() + " -q " + args + " -o " + out.string() + " 2>" +
                          err.string() + " >/dev/null";
  const int rc = std::system(cmd.c_str());
  CliRun r;
  r.code = WEXITSTATUS(rc);
  std::ifstream e(err);
  std::stringstream ss;
  ss << e.rdbuf();
  r.err = ss.str();
  std::ifstream m(out / "metrics.csv");
  std::string line;
  while (std::getline(m, line)) {
    if (line.empty() || line[0] == '#') continue;
    const auto comma = line.find(',');
    if (comma == std::string::npos) continue;
    r.metrics[line.substr(0, comma)] = std::strtod(line.c_str() + comma + 1, nullptr);
  }
  return r;
}

TEST(ReplayCli, BroadcastWithTheSsrStreamIsAsGoodAsTheProducts) {
  const fs::path ssr = dataset() / "gnss" / "ssr.rtcm3";
  ASSERT_TRUE(fs::exists(ssr));
  const CliRun products = replay("products", "--mode vio+dopp+psr");
  const CliRun corrected = replay("ssr", "--mode vio+dopp+psr --broadcast --ssr " + ssr.string());
  const CliRun broadcast = replay("broadcast", "--mode vio+dopp+psr --broadcast");
  ASSERT_EQ(products.code, 0) << products.err;
  ASSERT_EQ(corrected.code, 0) << corrected.err;
  ASSERT_EQ(broadcast.code, 0) << broadcast.err;
  for (const CliRun* r : {&products, &corrected, &broadcast}) {
    ASSERT_TRUE(r->metrics.count("ssr_messages") && r->metrics.count("global_position_rmse_m") &&
                r->metrics.count("precise_satellites"))
        << r->err;
  }
  EXPECT_GT(products.metrics.at("precise_satellites"), 0.0);
  EXPECT_EQ(products.metrics.at("ssr_messages"), 0.0);
  EXPECT_EQ(corrected.metrics.at("precise_satellites"), 0.0);
  EXPECT_GT(corrected.metrics.at("ssr_messages"), 0.0);
  EXPECT_GT(corrected.metrics.at("gnss_epochs_updated"), 100.0);
  const double p = products.metrics.at("global_position_rmse_m"), s = corrected.metrics.at("global_position_rmse_m");
  const double b = broadcast.metrics.at("global_position_rmse_m");
  std::printf("vio+dopp+psr global position RMSE: products %.4f m, --broadcast --ssr %.4f m (%.0f SSR messages), "
              "--broadcast %.4f m\n",
              p, s, corrected.metrics.at("ssr_messages"), b);
  ASSERT_TRUE(std::isfinite(p) && std::isfinite(s) && std::isfinite(b));
  EXPECT_NEAR(s, p, 0.05);
  EXPECT_EQ(broadcast.metrics.at("ssr_messages"), 0.0);
  // The corrections matter: broadcast orbits and clocks alone are about 0.8 m worse (measured
  // 1.486 m against 0.693 m).
  EXPECT_GT(b - p, 0.2);

  const std::string missing = (scratch() / "missing.rtcm3").string();
  const CliRun bad = replay("missing", "--mode vio+dopp+psr --broadcast --ssr " + missing);
  EXPECT_EQ(bad.code, 1) << bad.err;
  EXPECT_NE(bad.err.find(missing), std::string::npos) << bad.err;
}

// Float PPP as a user runs it, in post-processing (the folder's products) and in real time
// (broadcast records + the SSR stream): the carrier-phase rows are used on (nearly) every
// satellite, gnss_epochs.csv counts them, and the antenna velocity is better than with the
// carrier-smoothed psr rows of the same products.
TEST(ReplayCli, FloatPppWithProductsAndWithTheSsrStream) {
  const fs::path ssr = dataset() / "gnss" / "ssr.rtcm3";
  const CliRun psr = replay("ppp_psr", "--mode vio+dopp+psr");
  const CliRun ppp = replay("ppp", "--mode vio+dopp+ppp");
  const CliRun rt = replay("ppp_ssr", "--mode vio+dopp+ppp --broadcast --ssr " + ssr.string());
  for (const CliRun* r : {&psr, &ppp, &rt}) {
    ASSERT_EQ(r->code, 0) << r->err;
    ASSERT_TRUE(r->metrics.count("global_position_rmse_m") && r->metrics.count("global_velocity_rmse_mps")) << r->err;
  }
  // Phase rows and ambiguity states from gnss_epochs.csv (columns 20-22).
  long used = 0, rejected = 0, tight = 0, maxAmbiguities = 0;
  {
    std::ifstream in(scratch() / "ppp" / "gnss_epochs.csv");
    std::string line;
    while (std::getline(in, line)) {
      if (line.empty() || line[0] == '#') continue;
      std::vector<std::string> c;
      std::stringstream ls(line);
      for (std::string f; std::getline(ls, f, ',');) c.push_back(f);
      ASSERT_EQ(c.size(), 22u) << line;
      if (c[2] != "tight") continue;
      ++tight;
      used += std::stol(c[19]);
      rejected += std::stol(c[20]);
      maxAmbiguities = std::max(maxAmbiguities, std::stol(c[21]));
    }
  }
  const double vPsr = psr.metrics.at("global_velocity_rmse_mps"), vPpp = ppp.metrics.at("global_velocity_rmse_mps");
  const double vRt = rt.metrics.at("global_velocity_rmse_mps");
  std::printf("float PPP: %ld tight epochs, %ld phase rows used, %ld rejected, up to %ld ambiguities; position %.3f m "
              "(SSR %.3f m, psr %.3f m), antenna velocity %.4f m/s (SSR %.4f, psr %.4f)\n",
              tight, used, rejected, maxAmbiguities, ppp.metrics.at("global_position_rmse_m"),
              rt.metrics.at("global_position_rmse_m"), psr.metrics.at("global_position_rmse_m"), vPpp, vRt, vPsr);
  ASSERT_GT(tight, 100);
  EXPECT_GT(used, 8 * tight);
  EXPECT_LT(rejected, used / 50);
  EXPECT_GE(maxAmbiguities, 8);
  // The phases lower the antenna velocity error: measured 0.0208 (PPP and SSR) against 0.0234 m/s
  // (psr) with the frame started at rest during the climb; the margin was larger while the frame
  // waited for the horizontal motion, since the psr run's velocity then converged later.
  EXPECT_LT(vPpp, 0.95 * vPsr);
  EXPECT_LT(vRt, 0.95 * vPsr);
  EXPECT_LT(ppp.metrics.at("global_position_rmse_m"), 1.0);
  EXPECT_NEAR(rt.metrics.at("global_position_rmse_m"), ppp.metrics.at("global_position_rmse_m"), 0.1);
  EXPECT_GT(rt.metrics.at("ssr_messages"), 0.0);
  // The summary's totals (metrics.csv) are the sums of the per-epoch file.
  EXPECT_EQ(ppp.metrics.at("phase_rows_used"), static_cast<double>(used));
  EXPECT_EQ(ppp.metrics.at("phase_rows_rejected"), static_cast<double>(rejected));
  EXPECT_EQ(ppp.metrics.at("ambiguity_states_max"), static_cast<double>(maxAmbiguities));
  EXPECT_EQ(psr.metrics.at("phase_rows_used"), 0.0);
}

}  // namespace
// gvins-eval on a trajectory with gvins-replay's reset mark: the poses before the mark are in
// another VIO frame (here 90° of yaw and 100 m away); by default only the poses after it are
// evaluated, --whole takes all (and the 4-DoF fit then cannot match both frames).
TEST(EvalCli, ResetMarksSelectTheLastState) {
  const fs::path d = scratch() / "eval_reset";
  fs::create_directories(d);
  std::ofstream gt(d / "gt.tum"), est(d / "est.tum");
  gt << "# t x y z qx qy qz qw\n";
  est << "# t x y z qx qy qz qw\n";
  for (int i = 0; i < 200; ++i) {
    const double t = 1.0 + 0.05 * i, x = 0.5 * i, y = 0.02 * i * i;
    gt << t << " " << x << " " << y << " 1 0 0 0 1\n";
    if (i == 80) est << "# VIO reset after a visual lock-out: the poses below are in a new VIO world frame\n";
    const double e = 0.01 * std::sin(0.3 * i);  // 1 cm of error
    if (i < 80) {
      est << t << " " << -(y + e) + 100.0 << " " << x << " 1 0 0 0.7071067811865476 0.7071067811865476\n";
    } else {
      est << t << " " << x + e << " " << y << " 1 0 0 0 1\n";
    }
  }
  gt.close();
  est.close();
  auto run = [&](const std::string& extra) {
    const fs::path out = d / ("out" + extra + ".txt");
    const std::string cmd = std::string(GVINS_BIN_DIR) + "/gvins-eval --align 4dof --no-cov " + extra + " " +
                            (d / "est.tum").string() + " " + (d / "gt.tum").string() + " > " + out.string() + " 2>&1";
    EXPECT_EQ(WEXITSTATUS(std::system(cmd.c_str())), 0) << cmd;
    std::ifstream in(out);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  };
  auto rmse = [](const std::string& text) {
    const auto k = text.find("position [m]");
    return k == std::string::npos ? -1.0 : std::strtod(text.c_str() + k + 12, nullptr);
  };
  const std::string last = run("");
  const std::string all = run("--whole");
  EXPECT_NE(last.find("1 VIO reset mark(s): evaluating the 120 poses"), std::string::npos) << last;
  EXPECT_GT(rmse(last), 0.0);
  EXPECT_LT(rmse(last), 0.02) << last;
  EXPECT_GT(rmse(all), 1.0) << all;
}


TEST(ReplayCli, NmeaHasOneGgaAndRmcPerGlobalSolution) {
  // --nmea: the GGA of every global.pos row, parsed back independently, gives its position to
  // < 1 mm (7-decimal minutes; altitude + separation = ellipsoidal height).
  const fs::path nmea = scratch() / "global.nmea";
  const CliRun r = replay("nmea", "--mode vio+dopp+psr --nmea " + nmea.string());
  ASSERT_EQ(r.code, 0) << r.err;
  const gvins::PosFile pos = gvins::readPosFile((scratch() / "nmea" / "global.pos").string());
  std::ifstream f(nmea);
  std::vector<std::string> gga;
  std::size_t rmc = 0;
  for (std::string l; std::getline(f, l);) {
    if (l.rfind("$GNGGA,", 0) == 0) gga.push_back(l);
    rmc += l.rfind("$GNRMC,", 0) == 0;
  }
  ASSERT_GT(pos.solutions.size(), 50u);
  ASSERT_EQ(gga.size(), pos.solutions.size());
  EXPECT_EQ(rmc, gga.size());
  for (std::size_t i = 0; i < gga.size(); ++i) {
    std::vector<std::string> v(1);
    for (std::size_t k = 1; k < gga[i].size() && gga[i][k] != '*'; ++k) {
      if (gga[i][k] == ',') v.emplace_back();
      else v.back() += gga[i][k];
    }
    ASSERT_EQ(v.size(), 15u) << gga[i];
    const double lat = (std::stod(v[2].substr(0, 2)) + std::stod(v[2].substr(2)) / 60.0) * (v[3] == "S" ? -1 : 1);
    const double lon = (std::stod(v[4].substr(0, 3)) + std::stod(v[4].substr(3)) / 60.0) * (v[5] == "W" ? -1 : 1);
    const Eigen::Vector3d p = gvins::geodeticToEcef(gvins::geodeticFromDegrees(lat, lon, std::stod(v[9]) + std::stod(v[11])));
    EXPECT_LT((p - pos.solutions[i].position).norm(), 1e-3) << gga[i];
  }
}

}  // namespace gvins::fusion
