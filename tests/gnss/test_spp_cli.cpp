// gvins-spp end to end: output layout, summary, accuracy table, options and error handling.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

#include "gvins/base/geodetic.hpp"
#include "gvins/base/rinex_obs_reader.hpp"
#include "gvins/base/rinex_obs_writer.hpp"
#include "gvins/ephemeris/broadcast_sp3.hpp"
#include "gvins/ephemeris/ephemeris_store.hpp"
#include "gvins/ephemeris/rinex_nav.hpp"
#include "gvins/ephemeris/sp3.hpp"
#include "gvins/ephemeris/ssr_from_products.hpp"
#include "gvins/rtcm/ssr_file.hpp"
#include "gvins/gnss/accuracy_statistics.hpp"
#include "gvins/gnss/pos_reader.hpp"
#include "nagoya_recording.hpp"

namespace {
const std::string kData = GVINS_TEST_DATA;
const std::string kBin = std::string(GVINS_BIN_DIR) + "/gvins-spp";

struct CliRun {
  int code = -1;
  std::string err;
};

CliRun run(const std::string& args) {
  const std::string errFile = std::filesystem::temp_directory_path() / ("gvins_spp_cli_" + std::to_string(::getpid()) + ".err");
  const int rc = std::system((kBin + " " + args + " 2>" + errFile + " >/dev/null").c_str());
  CliRun r;
  r.code = WEXITSTATUS(rc);
  std::ifstream f(errFile);
  std::stringstream ss;
  ss << f.rdbuf();
  r.err = ss.str();
  std::filesystem::remove(errFile);
  return r;
}

std::string tmp(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("gvins_spp_cli_" + std::to_string(::getpid()) + "_" + name)).string();
}
}  // namespace

TEST(SppCli, NagoyaWithTruthWritesPosAndAccuracyTable) {
  const std::string out = tmp("n.pos");
  const CliRun r = run("-q --truth-llh 35.13469901,136.97757549,104.8626 -o " + out + " " + kData +
                    "/gnss/nagoya_static_2024/rover.obs.gz " + kData + "/gnss/nagoya_static_2024/base.nav.gz");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("epochs read                 301"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("solutions                   301"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("position error vs truth (301 epochs, m)"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("velocity error vs truth"), std::string::npos) << r.err;
  const gvins::PosFile f = gvins::readPosFile(out);
  EXPECT_FALSE(f.ecef);
  ASSERT_EQ(f.solutions.size(), 301u);
  // The file's positions give the same horizontal RMS as the tool's table (to print resolution).
  gvins::AccuracyStatistics st(gvins::geodeticToEcef(gvins::geodeticFromDegrees(35.13469901, 136.97757549, 104.8626)));
  for (const auto& s : f.solutions) st.addPosition(s.position);
  char expect[64];
  std::snprintf(expect, sizeof expect, "%10.3f", st.position().horizontalRms);
  EXPECT_NE(r.err.find(expect), std::string::npos) << expect << "\n" << r.err;
  std::filesystem::remove(out);
}

TEST(SppCli, XyzLayoutOptionsAndConfig) {
  const std::string out = tmp("g.pos"), cfg = tmp("c.yaml");
  std::ofstream(cfg) << "spp:\n  systems: GE\n  velocity: false\n";
  const CliRun r = run("-q --config " + cfg + " --elmask 10 --xyz --time-decimals 1 -o " + out + " " + kData +
                    "/gnss/kamakura_static_2021/SEPT078M.21O.gz " + kData + "/gnss/kamakura_static_2021/SEPT078M.21P.gz");
  ASSERT_EQ(r.code, 0) << r.err;
  std::ifstream f(out);
  std::string line, header;
  int rows = 0;
  while (std::getline(f, line)) {
    if (line.rfind("%  GPST", 0) == 0) header = line;
    if (!line.empty() && line[0] != '%') ++rows;
    if (rows == 1 && line[0] != '%') {
      EXPECT_EQ(line.substr(0, 21), "2021/03/19 12:00:00.0");
    }
  }
  EXPECT_EQ(rows, 900);
  EXPECT_NE(header.find("x-ecef(m)"), std::string::npos);
  // Velocity disabled: no velocity columns, and the header says why.
  EXPECT_EQ(header.find("vx(m/s)"), std::string::npos);
  EXPECT_NE(header.find(" test"), std::string::npos);
  std::filesystem::remove(out);
  std::filesystem::remove(cfg);
}

TEST(SppCli, ScoresAnExistingPosFile) {
  // RTKLIB's kamakura solution scored by the tool: the 0.29/1.44 m quoted in the data README.
  const CliRun r = run("--score " + kData + "/reference/rtklib-2.4.3/kamakura_sept078_spp.pos --truth -3962108.673,3381309.574,3668678.638");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("     0.287      1.437"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("velocity error"), std::string::npos) << r.err;
  EXPECT_EQ(run("--score x.pos").code, 2);  // needs a truth
}

TEST(SppCli, BadArgumentsAndBadFiles) {
  EXPECT_EQ(run("").code, 2);
  EXPECT_EQ(run("-o x.pos onlyone.obs").code, 2);
  EXPECT_EQ(run("--elmask abc -o x.pos a b").code, 2);
  EXPECT_EQ(run("--systems GX -o x.pos a b").code, 2);
  EXPECT_EQ(run("--frobnicate -o x.pos a b").code, 2);
  EXPECT_EQ(run("--smooth -1 -o x.pos a b").code, 2);
  EXPECT_EQ(run("--smooth abc -o x.pos a b").code, 2);
  // A clock product without an orbit product is a mistake, not something to ignore silently.
  const CliRun clkOnly = run("-q -o " + tmp("c.pos") + " " + kData + "/gnss/nagoya_static_2024/rover.obs.gz " + kData +
                             "/gnss/nagoya_static_2024/base.nav.gz " + tmp("only.clk"));
  EXPECT_EQ(clkOnly.code, 2);
  EXPECT_NE(clkOnly.err.find("clock files need an SP3 orbit file"), std::string::npos) << clkOnly.err;
  const CliRun missing = run("-o " + tmp("m.pos") + " /nonexistent.obs " + kData + "/gnss/nagoya_static_2024/base.nav.gz");
  EXPECT_EQ(missing.code, 1);
  EXPECT_NE(missing.err.find("/nonexistent.obs"), std::string::npos);
  // A navigation file given as observations: clear error naming the file and line 1.
  const CliRun swapped = run("-o " + tmp("s.pos") + " " + kData + "/gnss/nagoya_static_2024/base.nav.gz " + kData +
                          "/gnss/nagoya_static_2024/base.nav.gz");
  EXPECT_EQ(swapped.code, 1);
  EXPECT_NE(swapped.err.find("base.nav.gz:1"), std::string::npos) << swapped.err;
  EXPECT_NE(swapped.err.find("not an observation file"), std::string::npos) << swapped.err;
  // Truncated observation file: earlier epochs are solved, the broken epoch is skipped and counted.
  const std::string cut = tmp("cut.obs");
  {
    std::ofstream o(cut);
    std::string l;
    FILE* p = popen(("gzip -dc " + kData + "/gnss/nagoya_static_2024/rover.obs.gz | head -n 400").c_str(), "r");
    char buf[4096];
    while (fgets(buf, sizeof buf, p)) o << buf;
    pclose(p);
    o << "G05  2061";  // cut mid-record
  }
  const CliRun trunc = run("-q -o " + tmp("t.pos") + " " + cut + " " + kData + "/gnss/nagoya_static_2024/base.nav.gz");
  EXPECT_EQ(trunc.code, 0) << trunc.err;
  EXPECT_NE(trunc.err.find("1 malformed epochs skipped"), std::string::npos) << trunc.err;
  const CliRun strict = run("-q --strict -o " + tmp("t.pos") + " " + cut + " " + kData + "/gnss/nagoya_static_2024/base.nav.gz");
  EXPECT_EQ(strict.code, 1);
  EXPECT_NE(strict.err.find(cut), std::string::npos) << strict.err;
  // Observations without any matching ephemeris: runs, no solution, exit code 3.
  const CliRun noeph = run("-q -o " + tmp("e.pos") + " " + kData + "/gnss/kamakura_static_2021/SEPT078M.21O.gz " + kData +
                        "/gnss/nagoya_static_2024/base.nav.gz");
  EXPECT_EQ(noeph.code, 3) << noeph.err;
  EXPECT_NE(noeph.err.find("no ephemeris"), std::string::npos) << noeph.err;
  for (const char* n : {"m.pos", "s.pos", "cut.obs", "t.pos", "e.pos", "c.pos"}) std::filesystem::remove(tmp(n));
}

// --smooth: carrier-smoothed dual-frequency SPP on the Nagoya rover, against the same run on raw
// codes. Measured: 3-D RMS 1.174 -> 0.782 m, up standard deviation 0.88 -> 0.27 m. The header
// says so.
TEST(SppCli, CarrierSmoothingOption) {
  const std::string obs = kData + "/gnss/nagoya_static_2024/rover.obs.gz";
  const std::string nav = kData + "/gnss/nagoya_static_2024/base.nav.gz";
  const Eigen::Vector3d truth =
      gvins::geodeticToEcef(gvins::geodeticFromDegrees(35.13469901, 136.97757549, 104.8626));
  auto upStd = [&](const std::string& pos) {
    gvins::AccuracyStatistics st(truth);
    for (const auto& s : gvins::readPosFile(pos).solutions) st.addPosition(s.position);
    return st.position().enu[2].stddev;
  };
  const std::string a = tmp("raw.pos"), b = tmp("smooth.pos");
  const CliRun raw = run("-q --freq 2 --iono dual-frequency -o " + a + " " + obs + " " + nav);
  const CliRun sm = run("-q --freq 2 --iono dual-frequency --smooth 100 -o " + b + " " + obs + " " + nav);
  ASSERT_EQ(raw.code, 0) << raw.err;
  ASSERT_EQ(sm.code, 0) << sm.err;
  const double ra = upStd(a), sb = upStd(b);
  std::printf("up standard deviation: raw %.3f m, smoothed %.3f m\n", ra, sb);
  EXPECT_LT(sb, 0.4 * ra);
  std::ifstream f(b);
  const std::string text((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("carrier smoothing"), std::string::npos);
  std::filesystem::remove(a);
  std::filesystem::remove(b);
}

// Precise products among the inputs (told apart by name): an SP3 file holding the broadcast
// orbits and clocks of the GPS satellites (clocks without the relativistic term, as SP3 clocks
// are; 300 s nodes) gives the broadcast solution again to interpolation accuracy, and the tool
// says it used them; a broken SP3 file stops it with the file and line.
TEST(SppCli, PreciseProductsAmongTheInputs) {
  using namespace gvins;
  const std::string nav = kData + "/gnss/nagoya_static_2024/base.nav.gz";
  const std::string obs = kData + "/gnss/nagoya_static_2024/rover.obs.gz";
  EphemerisStore store;
  store.add(readRinexNav(nav));
  const GpsTime t0 = gvins::test::nagoyaTime(8, 0);
  std::vector<SatId> gps;
  for (SatId s : store.satellites())
    if (s.system == System::Gps) gps.push_back(s);
  const Sp3Data d = broadcastSp3(store, t0, t0 + 3600.0, 300.0, gps);
  const std::string sp3 = tmp("p.sp3"), broken = tmp("b.sp3");
  {
    std::ofstream f(sp3);
    writeSp3(f, d);
    std::ofstream g(broken);
    std::ostringstream ss;
    writeSp3(ss, d);
    g << ss.str().substr(0, ss.str().size() / 2) << "*  2024  6 24  8 59  0.00000000\nPG99 x\n";
  }
  // GPS only, and the broadcast error budget for the precise states too: the same weights, so
  // only the satellite states can differ.
  const std::string cfg = tmp("p.yaml");
  std::ofstream(cfg) << "spp:\n  precise_ephemeris_error_m: {G: 0.6}\n";
  const std::string a = tmp("a.pos"), b = tmp("b.pos");
  const CliRun plain = run("--config " + cfg + " --systems G -o " + a + " " + obs + " " + nav);
  const CliRun precise = run("--config " + cfg + " --systems G -o " + b + " " + obs + " " + nav + " " + sp3);
  ASSERT_EQ(plain.code, 0) << plain.err;
  ASSERT_EQ(precise.code, 0) << precise.err;
  EXPECT_NE(precise.err.find("precise products: " + std::to_string(d.satellites.size()) + " satellites"),
            std::string::npos)
      << precise.err;
  const PosFile fa = readPosFile(a), fb = readPosFile(b);
  ASSERT_EQ(fa.solutions.size(), fb.solutions.size());
  double maxDiff = 0.0;
  for (std::size_t i = 0; i < fa.solutions.size(); ++i)
    maxDiff = std::max(maxDiff, (fa.solutions[i].position - fb.solutions[i].position).norm());
  std::printf("largest position difference broadcast vs SP3 of the same orbits: %.4f m\n", maxDiff);
  EXPECT_LT(maxDiff, 0.01);  // mm-level SP3 rounding and interpolation
  const CliRun bad = run("-q -o " + b + " " + obs + " " + nav + " " + broken);
  EXPECT_EQ(bad.code, 1);
  EXPECT_NE(bad.err.find(broken), std::string::npos) << bad.err;
  for (const std::string& f : {sp3, broken, a, b, cfg}) std::filesystem::remove(f);
}

// --ssr: a recorded stream of SSR corrections made by the test (ssrFromProducts, as a correction
// service would: combined orbit/clock messages every 5 s) from "products" that are the broadcast
// GPS orbits moved by a fixed ECEF offset with clocks 0.8 m late. Applied to the broadcast
// records, the whole GPS constellation moves by the offset and every clock by the same amount, so
// the GPS-only solution moves by exactly the offset (the receiver clock absorbs the clock shift).
// A missing --ssr file stops the tool with its name.
TEST(SppCli, SsrCorrectionsFromARecordedStream) {
  using namespace gvins;
  const std::string nav = kData + "/gnss/nagoya_static_2024/base.nav.gz";
  const std::string obs = kData + "/gnss/nagoya_static_2024/rover.obs.gz";
  EphemerisStore store;
  store.add(readRinexNav(nav));
  const GpsTime t0 = gvins::test::nagoyaTime(8, 20);  // observations 08:20-08:25
  std::vector<SatId> gps;
  for (SatId s : store.satellites())
    if (s.system == System::Gps) gps.push_back(s);
  const Eigen::Vector3d offset(1.5, -0.7, 2.0);
  const double clockShift = 0.8;  // m
  // 30 s nodes: the GPS records of the file are valid from 08:00, and a correction for the first
  // epoch (08:19:55, reference time 08:19:57.5) needs the interpolation window around it.
  Sp3Data sp3 = broadcastSp3(store, t0 - 1200.0, t0 + 1200.0, 30.0, gps);
  for (Sp3Epoch& ep : sp3.epochs)
    for (Sp3Record& r : ep.records) {
      r.position += offset;
      r.clock += clockShift / 299792458.0;
    }
  auto precise = std::make_shared<PreciseEphemeris>();
  precise->add(sp3);
  EphemerisStore products;
  products.setPrecise(precise);
  const std::vector<SsrMessage> messages = ssrFromProducts(store, products, t0 - 10.0, t0 + 320.0, SsrServiceConfig{});
  ASSERT_GE(messages.size(), 60u);
  const std::string ssr = tmp("g.rtcm3");
  {
    const std::vector<std::uint8_t> bytes = rtcm::encodeSsrFrames(messages);
    std::ofstream f(ssr, std::ios::binary);
    f.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  }
  // The broadcast error budget for the SSR-corrected states too: the same weights.
  const std::string cfg = tmp("ssr.yaml");
  std::ofstream(cfg) << "spp:\n  precise_ephemeris_error_m: {G: 0.6}\n";
  const std::string a = tmp("bc.pos"), b = tmp("ssr.pos");
  const CliRun plain = run("-q --config " + cfg + " --systems G -o " + a + " " + obs + " " + nav);
  const CliRun corrected = run("--config " + cfg + " --systems G --ssr " + ssr + " -o " + b + " " + obs + " " + nav);
  ASSERT_EQ(plain.code, 0) << plain.err;
  ASSERT_EQ(corrected.code, 0) << corrected.err;
  EXPECT_NE(corrected.err.find("SSR corrections: " + std::to_string(messages.size()) + " messages"), std::string::npos)
      << corrected.err;
  const PosFile fa = readPosFile(a), fb = readPosFile(b);
  ASSERT_EQ(fa.solutions.size(), 301u);
  ASSERT_EQ(fb.solutions.size(), fa.solutions.size());
  double worst = 0.0;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < fa.solutions.size(); ++i) {
    const PositionSolution& x = fa.solutions[i];
    const PositionSolution& y = fb.solutions[i];
    EXPECT_EQ(x.time, y.time);
    EXPECT_EQ(x.numSatellites, y.numSatellites) << x.time.toString(1);
    const Eigen::Vector3d shift = y.position - x.position;
    worst = std::max(worst, (shift - offset).norm());
    mean += shift / static_cast<double>(fa.solutions.size());
  }
  std::printf("--ssr: mean solution shift %.4f %.4f %.4f m (products moved by %.1f %.1f %.1f m), worst deviation %.4f m\n",
              mean.x(), mean.y(), mean.z(), offset.x(), offset.y(), offset.z(), worst);
  EXPECT_LT(worst, 0.005);  // SP3 interpolation, 0.1-0.4 mm RTCM resolution, pos-file rounding

  const std::string missingFile = tmp("missing.rtcm3");
  const CliRun missing = run("-q --ssr " + missingFile + " -o " + tmp("m.pos") + " " + obs + " " + nav);
  EXPECT_EQ(missing.code, 1);
  EXPECT_NE(missing.err.find(missingFile), std::string::npos) << missing.err;
  EXPECT_FALSE(std::filesystem::exists(tmp("m.pos")));
  for (const std::string& f : {ssr, cfg, a, b}) std::filesystem::remove(f);
}

// Epochs whose residual test fails even after fault exclusion are written with test = 1 in the
// last column (Q stays 5, RTKLIB's "single"), told apart from the good ones, and --drop-failed
// omits them. Real Nagoya epochs; in five of them the pseudoranges of every third satellite are
// moved by +-100 m, more faults than fault exclusion removes (at most six per epoch).
TEST(SppCli, FailedResidualTestIsFlaggedAndDropFailedOmitsIt) {
  const std::string obs = tmp("fault.obs"), out = tmp("fault.pos"), dropped = tmp("fault_drop.pos");
  std::vector<gvins::GpsTime> faulty;
  {
    gvins::RinexObsReader in(kData + "/gnss/nagoya_static_2024/rover.obs.gz");
    std::ofstream f(obs);
    gvins::RinexObsWriter w(f, in.header());
    gvins::ObsEpoch e;
    for (int i = 0; i < 60 && in.next(e); ++i) {
      if (i >= 30 && i < 35) {
        ASSERT_GE(e.sats.size(), 20u);
        // Every third satellite (14 of 42, about 11 of them above the mask with ephemerides).
        for (std::size_t k = 0; k < e.sats.size(); k += 3) {
          for (auto& sig : e.sats[k].signals) {
            if (sig.hasCode()) sig.pseudorange += k % 2 ? 100.0 : -100.0;
          }
        }
        faulty.push_back(e.time);
      }
      w.write(e);
    }
    w.finish();
  }
  const std::string nav = kData + "/gnss/nagoya_static_2024/base.nav.gz";
  const CliRun r = run("-q -o " + out + " " + obs + " " + nav);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("written with test = 1"), std::string::npos) << r.err;
  const gvins::PosFile f = gvins::readPosFile(out);
  ASSERT_EQ(f.solutions.size(), 60u);
  int failed = 0, passed = 0;
  for (const auto& s : f.solutions) {
    ASSERT_TRUE(s.residualTest.has_value());
    EXPECT_EQ(s.quality, gvins::SolutionQuality::Single);
    // Solution time = tag minus the receiver clock (< 1 ms here).
    bool isFaulty = false;
    for (const auto& t : faulty) isFaulty = isFaulty || std::abs(s.time - t) < 0.01;
    if (isFaulty) {
      EXPECT_EQ(*s.residualTest, gvins::ResidualTest::Failed);
    }
    failed += *s.residualTest == gvins::ResidualTest::Failed;
    passed += *s.residualTest == gvins::ResidualTest::Passed;
  }
  // The clean epochs of this recording pass (RTKLIB solves all of them too).
  EXPECT_EQ(failed, 5);
  EXPECT_EQ(passed, 55);
  // The flag as text: the last field of the rows.
  {
    std::ifstream in(out);
    std::string line, title;
    int ones = 0;
    while (std::getline(in, line)) {
      if (line.rfind("%  GPST", 0) == 0) title = line;
      if (line.empty() || line[0] == '%') continue;
      ones += line.substr(line.find_last_not_of(' ') - 1) == " 1";
    }
    EXPECT_EQ(title.substr(title.size() - 5), " test");
    EXPECT_EQ(ones, 5);
  }
  const CliRun d = run("-q --drop-failed -o " + dropped + " " + obs + " " + nav);
  ASSERT_EQ(d.code, 0) << d.err;
  EXPECT_NE(d.err.find("omitted: --drop-failed"), std::string::npos) << d.err;
  const gvins::PosFile g = gvins::readPosFile(dropped);
  ASSERT_EQ(g.solutions.size(), 55u);
  for (const auto& s : g.solutions) {
    EXPECT_EQ(*s.residualTest, gvins::ResidualTest::Passed);
    for (const auto& t : faulty) EXPECT_GT(std::abs(s.time - t), 0.5);
  }
  if (!::testing::Test::HasFailure()) std::filesystem::remove(obs);
  std::filesystem::remove(out);
  std::filesystem::remove(dropped);
}

// A rover without Doppler (Kamakura) has no velocity columns and says so; one with Doppler has
// them, with a velocity in every epoch here.
TEST(SppCli, VelocityColumnsOnlyWithDoppler) {
  const std::string out = tmp("nodopp.pos");
  const CliRun r = run("-q -o " + out + " " + kData + "/gnss/kamakura_static_2021/SEPT078M.21O.gz " + kData +
                       "/gnss/kamakura_static_2021/SEPT078M.21P.gz");
  ASSERT_EQ(r.code, 0) << r.err;
  std::ifstream in(out);
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  EXPECT_NE(text.find("% (no velocity columns: no Doppler observations in the input)"), std::string::npos);
  EXPECT_EQ(text.find("vn(m/s)"), std::string::npos);
  const gvins::PosFile f = gvins::readPosFile(out);
  ASSERT_EQ(f.solutions.size(), 900u);
  for (const auto& s : f.solutions) {
    EXPECT_FALSE(s.velocity.has_value());
    EXPECT_TRUE(s.residualTest.has_value());
  }
  std::filesystem::remove(out);
}
