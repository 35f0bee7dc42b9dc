// gvins-rtk end to end (GEONET against RTKLIB's stored solution, doctored base files, options and
// errors) and the RTK YAML options (every key, every malformed case names file, line and key).
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "gvins/base/parse_error.hpp"
#include "gvins/base/rinex_obs_reader.hpp"
#include "gvins/base/rinex_obs_writer.hpp"
#include "gvins/gnss/pos_reader.hpp"
#include "gvins/gnss/rtk_config.hpp"
#include "gvins/gnss/spp_config.hpp"

using namespace gvins;

namespace {
const std::string kData = GVINS_TEST_DATA;
const std::string kBin = std::string(GVINS_BIN_DIR) + "/gvins-rtk";
const std::string kGeonet = kData + "/gnss/geonet_0759_3040_2005/";

struct CliRun {
  int code = -1;
  std::string err;
};

std::string tmp(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("gvins_rtk_cli_" + std::to_string(::getpid()) + "_" + name)).string();
}

CliRun run(const std::string& args) {
  const std::string errFile = tmp("stderr");
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

int countQ(const PosFile& f, SolutionQuality q) {
  int n = 0;
  for (const auto& s : f.solutions) n += s.quality == q;
  return n;
}

/// Writes a copy of a RINEX observation file with epochs changed or dropped by `edit` (returns
/// false to drop) and the header changed by `editHeader`.
template <class F, class H = void (*)(RinexObsHeader&)>
void doctor(const std::string& in, const std::string& out, F&& edit, H&& editHeader = [](RinexObsHeader&) {}) {
  RinexObsHeader h;
  const auto epochs = readRinexObs(in, &h);
  editHeader(h);
  std::ofstream f(out);
  RinexObsWriter w(f, h);
  int i = 0;
  for (ObsEpoch e : epochs) {
    if (edit(e, i++)) w.write(e);
  }
}

}  // namespace

TEST(RtkCli, GeonetStaticMatchesRtklib) {
  const std::string out = tmp("g.pos");
  const CliRun r = run("-q --mode static --systems G --xyz -o " + out + " " + kGeonet + "07590920.05o.gz " + kGeonet +
                       "30400920.05o.gz " + kGeonet + "30400920.05n.gz");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("rover epochs                120"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("fixed   (Q=1)               120  100.00 %"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("base position          -3978242.4348 3382841.1715 3649902.7667 (RINEX header)"), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("ratio                  min"), std::string::npos);
  const PosFile ours = readPosFile(out);
  const PosFile ref = readPosFile(kData + "/reference/rtklib-2.4.3/geonet_0759_rtk_static.pos");
  ASSERT_TRUE(ours.ecef);
  ASSERT_EQ(ours.solutions.size(), 120u);
  EXPECT_GE(countQ(ours, SolutionQuality::Fix), countQ(ref, SolutionQuality::Fix));
  // Same time tags as RTKLIB (receiver-clock corrected) and positions within 2 cm (the file prints
  // 0.1 mm).
  for (std::size_t i = 0; i < ref.solutions.size(); ++i) {
    EXPECT_NEAR(ours.solutions[i].time - ref.solutions[i].time, 0.0, 1e-3) << i;
    EXPECT_LT((ours.solutions[i].position - ref.solutions[i].position).norm(), 0.02) << i;
    EXPECT_GT(ours.solutions[i].ratio, 3.0);
  }
  std::filesystem::remove(out);
}

// Combined mode on GEONET, GPS L1 only, kinematic: the backward pass fixes the first epochs the
// forward pass spends converging. Rows in increasing time, one per epoch as forward; no fixed
// epoch more than 0.10 m from RTKLIB's static solution; more fixes than the forward run.
TEST(RtkCli, CombinedGeonetL1FixesMoreThanForwardAndNoneWrong) {
  const std::string fwd = tmp("gf.pos"), comb = tmp("gc.pos");
  const std::string inputs = " --systems G --freq 1 --xyz " + kGeonet + "07590920.05o.gz " + kGeonet + "30400920.05o.gz " +
                             kGeonet + "30400920.05n.gz";
  const CliRun f = run("-q -o " + fwd + inputs);
  const CliRun c = run("--combined -o " + comb + inputs);
  ASSERT_EQ(f.code, 0) << f.err;
  ASSERT_EQ(c.code, 0) << c.err;
  EXPECT_NE(c.err.find("backward pass:"), std::string::npos) << c.err;
  EXPECT_NE(c.err.find("combined fixes"), std::string::npos) << c.err;
  EXPECT_NE(c.err.find("0 disagreements (both fixed)"), std::string::npos) << c.err;
  const PosFile a = readPosFile(fwd), b = readPosFile(comb);
  ASSERT_EQ(a.solutions.size(), 120u);
  ASSERT_EQ(b.solutions.size(), 120u);
  const Eigen::Vector3d truth = readPosFile(kData + "/reference/rtklib-2.4.3/geonet_0759_rtk_static.pos").solutions.back().position;
  for (std::size_t i = 0; i < b.solutions.size(); ++i) {
    EXPECT_NEAR(b.solutions[i].time - a.solutions[i].time, 0.0, 1e-6) << i;
    if (b.solutions[i].quality == SolutionQuality::Fix) {
      EXPECT_LT((b.solutions[i].position - truth).norm(), 0.10) << i;
    }
  }
  EXPECT_GT(countQ(b, SolutionQuality::Fix), countQ(a, SolutionQuality::Fix));
  std::filesystem::remove(fwd);
  std::filesystem::remove(comb);
}

// Base epochs 30..59 missing (15 minutes at 30 s): beyond max age the tool writes single-point rows
// and says why; the rover's last epochs after the gap are fixed again.
TEST(RtkCli, DoctoredBaseDegradesWithCountedReasons) {
  const std::string base = tmp("base_gap.obs"), out = tmp("gap.pos");
  doctor(kGeonet + "30400920.05o.gz", base, [](ObsEpoch&, int i) { return i < 30 || i >= 60; });
  CliRun r = run("-q --systems G -o " + out + " " + kGeonet + "07590920.05o.gz " + base + " " + kGeonet + "30400920.05n.gz");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("no RTK: base data too old"), std::string::npos) << r.err;
  PosFile f = readPosFile(out);
  ASSERT_EQ(f.solutions.size(), 120u);
  // Epochs 30..59: the rover is stamped 00:15:00.001 and base epoch 29 00:14:29.999, so already
  // at epoch 30 the base is 30.002 s old (> 30 s; RTKLIB's maxage test rejects it as well).
  EXPECT_EQ(countQ(f, SolutionQuality::Single), 30);
  // 85 before the fixed solution had to determine the position to 0.1 m (3-D sigma): the last
  // epochs, with five satellites, fix to 0.12-0.16 m sigma and stay float.
  EXPECT_GE(countQ(f, SolutionQuality::Fix), 84);

  // Base with the GPS L2 observations renamed to another tracking code (L2/P2 -> "2X", in the
  // header too, else the writer drops them): the tool counts the mismatches and solves on L1.
  doctor(
      kGeonet + "30400920.05o.gz", base,
      [](ObsEpoch& e, int) {
        for (SatObs& so : e.sats) {
          for (SignalObs& s : so.signals) {
            if (s.code.band == '2') s.code = ObsCode('2', 'X');
          }
        }
        return true;
      },
      [](RinexObsHeader& h) {
        for (ObsDescriptor& d : h.types(System::Gps)) {
          if (d.code.band == '2') d.code = ObsCode('2', 'X');
        }
      });
  r = run("-q --systems G -o " + out + " " + kGeonet + "07590920.05o.gz " + base + " " + kGeonet + "30400920.05n.gz");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("signal mismatches"), std::string::npos) << r.err;
  f = readPosFile(out);
  EXPECT_EQ(countQ(f, SolutionQuality::Single), 0);

  // Base with an hour's offset: nothing in common in time, every row single.
  doctor(kGeonet + "30400920.05o.gz", base, [](ObsEpoch& e, int) {
    e.time += 3600.0;
    return true;
  });
  r = run("-q --systems G -o " + out + " " + kGeonet + "07590920.05o.gz " + base + " " + kGeonet + "30400920.05n.gz");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("no RTK: no base data"), std::string::npos) << r.err;
  f = readPosFile(out);
  EXPECT_EQ(countQ(f, SolutionQuality::Single), static_cast<int>(f.solutions.size()));
  EXPECT_GE(f.solutions.size(), 110u);
  std::filesystem::remove(base);
  std::filesystem::remove(out);
}

TEST(RtkCli, OptionsConfigAndErrors) {
  const std::string out = tmp("o.pos"), cfg = tmp("c.yaml");
  const std::string files = kGeonet + "07590920.05o.gz " + kGeonet + "30400920.05o.gz " + kGeonet + "30400920.05n.gz";
  // Instantaneous AR from a config file, base position given, geodetic output, truth table.
  std::ofstream(cfg) << "rtk:\n  systems: G\n  ambiguity_mode: instantaneous\nspp:\n  systems: G\n";
  CliRun r = run("-q --config " + cfg + " --base-xyz -3978242.4348,3382841.1715,3649902.7667 --truth -3976219.6637,3382372.5413,3652513.0541 -o " +
                 out + " " + files);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("AR instantaneous"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("(command line)"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("fixed solutions vs truth"), std::string::npos) << r.err;
  const PosFile f = readPosFile(out);
  EXPECT_FALSE(f.ecef);
  // RTKLIB instantaneous: 115 (up to 00:57:00). Ours: 114, every epoch up to 00:56:30; at
  // 00:57:00 (five satellites) the fixed position's 3-D sigma is 0.12 m > max_fixed_sigma_m.
  EXPECT_GE(countQ(f, SolutionQuality::Fix), 114);
  // Errors: bad config (file and line named), bad option, missing input, no base position.
  std::ofstream(cfg) << "rtk:\n  mode: static\n  ar:\n    ratio_threshold: 0.5\n";
  r = run("--config " + cfg + " -o " + out + " " + files);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find(cfg + ":4"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("rtk.ar.ratio_threshold"), std::string::npos) << r.err;
  r = run("--armode sometimes -o " + out + " " + files);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--armode"), std::string::npos);
  r = run("-o " + out + " " + kGeonet + "07590920.05o.gz " + kGeonet + "30400920.05n.gz");
  EXPECT_EQ(r.code, 2);
  r = run("-o " + out + " " + kGeonet + "07590920.05o.gz /nonexistent/base.obs " + kGeonet + "30400920.05n.gz");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("/nonexistent/base.obs"), std::string::npos);
  // A base file without a header position and no --base-xyz: single-point rows, reason stated.
  const std::string base = tmp("nopos.obs");
  {
    RinexObsHeader h;
    const auto epochs = readRinexObs(kGeonet + "30400920.05o.gz", &h);
    h.station.approxPosition.reset();
    std::ofstream o(base);
    RinexObsWriter w(o, h);
    for (const auto& e : epochs) w.write(e);
  }
  r = run("-q --systems G -o " + out + " " + kGeonet + "07590920.05o.gz " + base + " " + kGeonet + "30400920.05n.gz");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("no RTK: base position unknown"), std::string::npos) << r.err;
  std::filesystem::remove(base);
  std::filesystem::remove(cfg);
  std::filesystem::remove(out);
}

// ---------------------------------------------------------------------------------------------
// YAML options.

TEST(RtkConfig, ExampleFileHoldsTheDefaultsAndEveryKeyParses) {
  const RtkConfig def;
  const RtkConfig ex = loadRtkConfig(std::string(GVINS_SOURCE_DIR) + "/apps/rtk/rtk.yaml");
  EXPECT_EQ(ex.mode, def.mode);
  EXPECT_EQ(ex.ambiguityMode, def.ambiguityMode);
  EXPECT_EQ(ex.systems, def.systems);
  EXPECT_EQ(ex.arSystems, def.arSystems);
  EXPECT_EQ(ex.bands, def.bands);
  EXPECT_EQ(ex.frequencies, def.frequencies);
  EXPECT_DOUBLE_EQ(ex.elevationMask, def.elevationMask);
  EXPECT_DOUBLE_EQ(ex.ar.ratioThreshold, def.ar.ratioThreshold);
  EXPECT_EQ(ex.arMinSatellites, def.arMinSatellites);
  EXPECT_DOUBLE_EQ(ex.phaseSigmaA, def.phaseSigmaA);
  EXPECT_DOUBLE_EQ(ex.maxAge, def.maxAge);
  EXPECT_DOUBLE_EQ(ex.slip.geometryFreeThreshold, def.slip.geometryFreeThreshold);
  EXPECT_DOUBLE_EQ(ex.dopplerAidedSigma, def.dopplerAidedSigma);
  EXPECT_EQ(ex.extrapolateBase, def.extrapolateBase);

  const RtkConfig c = parseRtkConfig(
      "rtk:\n  mode: static\n  dynamics: constant-velocity\n  ambiguity_mode: fix-and-hold\n  systems: GE\n"
      "  frequencies: 3\n  bands: {E: \"175\"}\n  elevation_mask_deg: 10\n"
      "  ar: {systems: G, validation: ratio+success-rate, ratio_threshold: 2.5, max_failure_rate: 0.01,\n"
      "       partial: false, min_fixed: 6, min_satellites: 5, hold_min_fixes: 3, hold_sigma_cycles: 0.001, validation_sigmas: 5}\n"
      "  phase_sigma_m: {a: 0.002, b: 0.004}\n  code_phase_ratio: 200\n  code_system_factor: {E: 2}\n"
      "  troposphere: false\n  base: {max_age_s: 5, interpolate: false, extrapolate: false}\n"
      "  cycle_slip: {doppler: false, geometry_free_m: 0.03}\n  ambiguity_outage_s: 10\n"
      "  outliers: {phase_sigmas: 8, max_rounds: 1}\n  filter: {doppler_aided: false, acceleration_h_mps2: 1}\n"
      "spp: {systems: G}\nother_tool: [1, 2]\n",
      "inline.yaml");
  EXPECT_EQ(c.mode, RtkMode::Static);
  EXPECT_EQ(c.dynamics, RtkDynamics::ConstantVelocity);
  EXPECT_EQ(c.ambiguityMode, AmbiguityMode::FixAndHold);
  EXPECT_EQ(c.systems, parseSystemLetters("GE"));
  EXPECT_EQ(c.frequencies, 3);
  EXPECT_EQ(c.bands[systemIndex(System::Galileo)], "175");
  EXPECT_NEAR(c.elevationMask, 10.0 * constants::kDegToRad, 1e-15);
  EXPECT_EQ(c.arSystems, parseSystemLetters("G"));
  EXPECT_EQ(c.ar.validation, AmbiguityValidation::RatioAndSuccessRate);
  EXPECT_DOUBLE_EQ(c.ar.ratioThreshold, 2.5);
  EXPECT_FALSE(c.ar.partial);
  EXPECT_EQ(c.ar.minFixed, 6);
  EXPECT_EQ(c.arMinSatellites, 5);
  EXPECT_EQ(c.holdMinFixes, 3);
  EXPECT_DOUBLE_EQ(c.fixValidationSigmas, 5.0);
  EXPECT_DOUBLE_EQ(c.phaseSigmaB, 0.004);
  EXPECT_DOUBLE_EQ(c.codePhaseRatio, 200.0);
  EXPECT_DOUBLE_EQ(c.codeSystemFactor[systemIndex(System::Galileo)], 2.0);
  EXPECT_FALSE(c.troposphere);
  EXPECT_FALSE(c.interpolateBase);
  EXPECT_FALSE(c.extrapolateBase);
  EXPECT_DOUBLE_EQ(c.maxAge, 5.0);
  EXPECT_FALSE(c.slip.doppler);
  EXPECT_DOUBLE_EQ(c.slip.geometryFreeThreshold, 0.03);
  EXPECT_DOUBLE_EQ(c.ambiguityOutage, 10.0);
  EXPECT_EQ(c.maxOutlierRounds, 1);
  EXPECT_FALSE(c.dopplerAided);
  EXPECT_DOUBLE_EQ(c.accelerationSigmaHorizontal, 1.0);
  // Empty document, no rtk section: defaults.
  EXPECT_EQ(parseRtkConfig("", "e.yaml").frequencies, 2);
  EXPECT_EQ(parseRtkConfig("spp: {systems: G}\n", "e.yaml").frequencies, 2);
}

TEST(RtkConfig, MalformedInputNamesFileLineAndKey) {
  struct Case {
    const char* yaml;
    int line;
    const char* key;
  };
  const Case cases[] = {
      {"rtk:\n  mode: moving\n", 2, "rtk.mode"},
      {"rtk:\n  frequencies: 4\n", 2, "rtk.frequencies"},
      {"rtk:\n  frequency: 2\n", 2, "rtk.frequency"},
      {"rtk:\n  systems: GXE\n", 2, "rtk.systems"},
      {"rtk:\n  systems: \"\"\n", 2, "rtk.systems"},
      {"rtk:\n  bands: {G: \"19\"}\n", 2, "rtk.bands.G"},
      {"rtk:\n  bands: {G: \"11\"}\n", 2, "rtk.bands.G"},
      {"rtk:\n  bands: {Q: \"1\"}\n", 2, "rtk.bands.Q"},
      {"rtk:\n  ar:\n    validation: maybe\n", 3, "rtk.ar.validation"},
      {"rtk:\n  ar:\n    ratio_threshold: [3]\n", 3, "rtk.ar.ratio_threshold"},
      {"rtk:\n  ar: 3\n", 2, "rtk.ar"},
      {"rtk:\n  phase_sigma_m: {a: 0, b: 0}\n", 2, "rtk.phase_sigma_m"},
      {"rtk:\n  base: {max_age_s: -1}\n", 2, "rtk.base.max_age_s"},
      {"rtk:\n  cycle_slip: {lli: perhaps}\n", 2, "rtk.cycle_slip.lli"},
      {"rtk:\n  filter: {unknown: 1}\n", 2, "rtk.filter.unknown"},
      {"rtk:\n  outliers: {max_rounds: 1.5}\n", 2, "rtk.outliers.max_rounds"},
      {"rtk:\n  mode: [static\n", 3, "YAML"},  // found at the end of the input
      {"- rtk\n", 1, ""},
      {"rtk:\n  ? [a, b]\n  : 1\n", 2, "rtk"},
  };
  for (const Case& c : cases) {
    try {
      parseRtkConfig(c.yaml, "bad.yaml");
      ADD_FAILURE() << "accepted: " << c.yaml;
    } catch (const ParseError& e) {
      EXPECT_EQ(e.file(), "bad.yaml") << c.yaml;
      EXPECT_EQ(e.line(), c.line) << c.yaml << " -> " << e.what();
      EXPECT_EQ(e.field(), c.key) << c.yaml << " -> " << e.what();
    }
  }
  EXPECT_THROW(loadRtkConfig("/nonexistent/rtk.yaml"), ParseError);
}
