// GnssFusionConfig YAML: every mode name, values, and errors with line and field.
#include <gtest/gtest.h>

#include "gvins/base/parse_error.hpp"
#include "gvins/fusion/gnss_fusion_config.hpp"

namespace gvins::fusion {
namespace {

TEST(GnssFusionConfig, ParsesAllKeys) {
  const GnssFusionConfig c = parseGnssFusionConfig(
      "other: 1\n"
      "gnss_fusion:\n"
      "  mode: vio+dopp+ddcp\n"
      "  lever_arm: [0.1, -0.2, 0.3]\n"
      "  calibrate_lever_arm: true\n"
      "  systems: GE\n"
      "  code_sigma: 0.8\n"
      "  code_weighting: elevation-cn0\n"
      "  cn0_mask_dbhz: 35\n"
      "  carrier_smoothing: 60\n"
      "  smoothed_code_factor: 0.5\n"
      "  ionosphere: broadcast\n"
      "  base_position: [1, 2, 3]\n"
      "  row_gate: 0.99\n"
      "  bands: {G: \"152\", J: \"15\"}\n"
      "  ephemeris_error_m: {R: 5, E: 0.25}\n");
  EXPECT_EQ(c.ionosphere, GnssIonosphere::kBroadcast);
  EXPECT_EQ(c.bands[static_cast<std::size_t>(systemIndex(System::Gps))], "152");
  EXPECT_EQ(c.bands[static_cast<std::size_t>(systemIndex(System::Qzss))], "15");
  EXPECT_EQ(c.bands[static_cast<std::size_t>(systemIndex(System::Galileo))], SppConfig{}.bands[2]);
  EXPECT_DOUBLE_EQ(c.ephemerisError[static_cast<std::size_t>(systemIndex(System::Glonass))], 5.0);
  EXPECT_DOUBLE_EQ(c.ephemerisError[static_cast<std::size_t>(systemIndex(System::Galileo))], 0.25);
  EXPECT_DOUBLE_EQ(c.ephemerisError[static_cast<std::size_t>(systemIndex(System::Gps))], SppConfig{}.ephemerisError[0]);
  EXPECT_EQ(GnssFusionConfig{}.bands[static_cast<std::size_t>(systemIndex(System::Gps))], SppConfig{}.bands[0]);
  EXPECT_EQ(GnssFusionConfig{}.bands[static_cast<std::size_t>(systemIndex(System::Qzss))], "152");  // L5 before L2
  EXPECT_EQ(GnssFusionConfig{}.bands[static_cast<std::size_t>(systemIndex(System::BeiDou))], SppConfig{}.bands[3]);
  EXPECT_TRUE(c.leverArmGiven);
  const GnssFusionConfig d = parseGnssFusionConfig("gnss_fusion:\n  mode: vio+dopp+psr\n");
  EXPECT_EQ(d.ionosphere, GnssIonosphere::kDualFrequency);
  EXPECT_FALSE(d.leverArmGiven);
  EXPECT_EQ(c.mode, GnssFusionMode::kDoppDdcp);
  EXPECT_EQ(c.leverArm, Eigen::Vector3d(0.1, -0.2, 0.3));
  EXPECT_TRUE(c.calibrateLeverArm);
  EXPECT_TRUE(c.useSystem(System::Gps));
  EXPECT_TRUE(c.useSystem(System::Galileo));
  EXPECT_FALSE(c.useSystem(System::BeiDou));
  EXPECT_DOUBLE_EQ(c.codeSigma, 0.8);
  EXPECT_EQ(c.codeWeighting, GnssCodeWeighting::kElevationCn0);
  EXPECT_DOUBLE_EQ(c.cn0MaskDbHz, 35.0);
  EXPECT_EQ(d.codeWeighting, GnssCodeWeighting::kElevation);
  EXPECT_DOUBLE_EQ(d.cn0MaskDbHz, 0.0);
  EXPECT_DOUBLE_EQ(c.carrierSmoothing, 60.0);
  EXPECT_DOUBLE_EQ(c.smoothedCodeFactor, 0.5);
  EXPECT_DOUBLE_EQ(c.rowGate, 0.99);
  ASSERT_TRUE(c.basePosition);
  EXPECT_EQ(*c.basePosition, Eigen::Vector3d(1, 2, 3));
  EXPECT_TRUE(c.usesDifferences());
}

TEST(GnssFusionConfig, FloatPppKeys) {
  const GnssFusionConfig c = parseGnssFusionConfig(
      "gnss_fusion:\n"
      "  mode: vio+dopp+ppp\n"
      "  phase_sigma: 0.004\n"
      "  ambiguity_sigma: 20\n"
      "  ambiguity_reset_rejections: 5\n"
      "  zwd_sigma: 0.08\n"
      "  zwd_random_walk: 0.0001\n"
      "  phase_windup: false\n"
      "  max_ambiguities: 25\n"
      "  broadcast_ambiguity_random_walk: 0.01\n"
      "  broadcast_record_changes: false\n"
      "  rtk_hold_fix: false\n"
      "  frame_reanchor: false\n"
      "  frame_reanchor_position_sigma: 0.2\n");
  EXPECT_EQ(c.mode, GnssFusionMode::kDoppPpp);
  EXPECT_FALSE(c.frameReanchor);
  EXPECT_TRUE(GnssFusionConfig{}.frameReanchor);
  EXPECT_DOUBLE_EQ(c.frameReanchorPositionSigma, 0.2);
  EXPECT_TRUE(c.usesPseudorange());
  EXPECT_FALSE(c.usesDifferences());
  EXPECT_TRUE(c.integration());
  EXPECT_DOUBLE_EQ(c.phaseSigma, 0.004);
  EXPECT_DOUBLE_EQ(c.ambiguitySigma, 20.0);
  EXPECT_EQ(c.ambiguityResetRejections, 5);
  EXPECT_DOUBLE_EQ(c.zwdSigma, 0.08);
  EXPECT_DOUBLE_EQ(c.zwdRandomWalk, 1e-4);
  EXPECT_FALSE(c.phaseWindup);
  EXPECT_TRUE(GnssFusionConfig{}.phaseWindup);
  EXPECT_EQ(c.maxAmbiguities, 25);
  EXPECT_DOUBLE_EQ(c.broadcastAmbiguityRandomWalk, 0.01);
  EXPECT_FALSE(c.broadcastRecordChanges);
  EXPECT_TRUE(GnssFusionConfig{}.broadcastRecordChanges);
  EXPECT_FALSE(c.rtkHoldFix);
  EXPECT_TRUE(GnssFusionConfig{}.rtkHoldFix);
  EXPECT_DOUBLE_EQ(GnssFusionConfig{}.rtkRevalidateInterval, 10.0);
  EXPECT_DOUBLE_EQ(parseGnssFusionConfig("gnss_fusion:\n  rtk_revalidate_interval: 0\n").rtkRevalidateInterval, 0.0);
  EXPECT_THROW(parseGnssFusionConfig("gnss_fusion:\n  rtk_revalidate_interval: -2\n"), ParseError);
  // The wet delay state: on by default in vio+dopp+ppp only; estimate_zwd switches it for the
  // other pseudorange modes (never for modes without undifferenced codes).
  EXPECT_TRUE(c.zwdState());
  EXPECT_FALSE(parseGnssFusionConfig("gnss_fusion:\n  mode: vio+dopp+ppp\n  estimate_zwd: false\n").zwdState());
  EXPECT_FALSE(parseGnssFusionConfig("gnss_fusion:\n  mode: vio+dopp+psr\n").zwdState());
  EXPECT_TRUE(parseGnssFusionConfig("gnss_fusion:\n  mode: vio+dopp+psr\n  estimate_zwd: true\n").zwdState());
  EXPECT_FALSE(parseGnssFusionConfig("gnss_fusion:\n  mode: vio+dopp+dpsr\n  estimate_zwd: true\n").zwdState());
}

TEST(GnssFusionConfig, InterSystemBiasRandomWalkKeys) {
  const GnssFusionConfig c =
      parseGnssFusionConfig("gnss_fusion:\n  isb_random_walk: 0.01\n  isb_renewal_interval: 5\n");
  EXPECT_DOUBLE_EQ(c.isbRandomWalk, 0.01);
  EXPECT_DOUBLE_EQ(c.isbRenewalInterval, 5.0);
  EXPECT_DOUBLE_EQ(parseGnssFusionConfig("gnss_fusion:\n  isb_random_walk: 0\n").isbRandomWalk, 0.0);  // constant
  EXPECT_THROW(parseGnssFusionConfig("gnss_fusion:\n  isb_random_walk: -1\n"), ParseError);
  EXPECT_THROW(parseGnssFusionConfig("gnss_fusion:\n  isb_renewal_interval: 0\n"), ParseError);
}

TEST(GnssFusionConfig, ReacquisitionAndLateSystemKeys) {
  const GnssFusionConfig d;
  EXPECT_DOUBLE_EQ(d.reacquireAfter, 2.0);
  EXPECT_EQ(d.lateSystemMinSatellites, 2);
  const GnssFusionConfig c = parseGnssFusionConfig(
      "gnss_fusion:\n  reacquire_after: 0\n  reacquire_acceleration: 0.5\n  late_system_min_satellites: 4\n");
  EXPECT_DOUBLE_EQ(c.reacquireAfter, 0.0);  // never
  EXPECT_DOUBLE_EQ(c.reacquireAcceleration, 0.5);
  EXPECT_EQ(c.lateSystemMinSatellites, 4);
  EXPECT_THROW(parseGnssFusionConfig("gnss_fusion:\n  reacquire_after: -1\n"), ParseError);
  EXPECT_THROW(parseGnssFusionConfig("gnss_fusion:\n  reacquire_acceleration: 0\n"), ParseError);
  EXPECT_THROW(parseGnssFusionConfig("gnss_fusion:\n  late_system_min_satellites: 0\n"), ParseError);
}

TEST(GnssFusionConfig, ModeNamesRoundTrip) {
  for (const char* n : {"vio", "vio+gpsvel", "vio+dopp", "vio+dopp+psr", "vio+dopp+dpsr", "vio+dopp+ddcp",
                        "vio+dopp+psr-nointegration", "vio+dopp+ppp"}) {
    const auto m = gnssFusionModeFromString(n);
    ASSERT_TRUE(m) << n;
    EXPECT_STREQ(toString(*m), n);
  }
  EXPECT_FALSE(gnssFusionModeFromString("vio+psr"));
  EXPECT_FALSE(parseGnssFusionConfig("gnss_fusion:\n  mode: vio+dopp+psr-nointegration\n").integration());
}

TEST(GnssFusionConfig, ErrorsNameFileLineAndField) {
  try {
    parseGnssFusionConfig("gnss_fusion:\n  mode: vio+dopp\n  code_sigma: -1\n", "f.yaml");
    FAIL() << "no error";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.file(), "f.yaml");
    EXPECT_EQ(e.line(), 3);
    EXPECT_EQ(e.field(), "code_sigma");
  }
  try {
    parseGnssFusionConfig("gnss_fusion:\n  mode: bogus\n", "g.yaml");
    FAIL() << "no error";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.line(), 2);
    EXPECT_EQ(e.field(), "mode");
  }
  try {
    parseGnssFusionConfig("gnss_fusion:\n  lever_arm: [1, 2]\n  typo_key: 3\n");
    FAIL() << "no error";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.field(), "lever_arm");
  }
  try {
    parseGnssFusionConfig("gnss_fusion:\n  typo_key: 3\n");
    FAIL() << "no error";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.line(), 2);
    EXPECT_EQ(e.field(), "typo_key");
  }
  try {
    parseGnssFusionConfig("gnss_fusion:\n  mode: vio+dopp\n  ionosphere: klobuchar\n", "i.yaml");
    FAIL() << "no error";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.line(), 3);
    EXPECT_EQ(e.field(), "ionosphere");
  }
  for (const char* bad : {"  bands: {G: \"19\"}\n", "  bands: {X: \"12\"}\n", "  bands: \"12\"\n",
                          "  ephemeris_error_m: {G: -1}\n", "  carrier_smoothing: -5\n",
                          "  smoothed_code_factor: 2\n", "  phase_sigma: 0\n", "  ambiguity_sigma: -1\n",
                          "  ambiguity_reset_rejections: 0\n", "  estimate_zwd: maybe\n", "  zwd_sigma: -0.1\n",
                          "  phase_windup: 2\n", "  max_ambiguities: -1\n",
                          "  broadcast_ambiguity_random_walk: -1\n", "  broadcast_record_changes: 3\n",
                          "  rtk_hold_fix: sometimes\n", "  frame_reanchor: 1.5\n",
                          "  frame_reanchor_position_sigma: 0\n", "  code_weighting: cn0\n",
                          "  cn0_mask_dbhz: -3\n"}) {
    try {
      parseGnssFusionConfig(std::string("gnss_fusion:\n  mode: vio+dopp+psr\n") + bad, "b.yaml");
      FAIL() << "no error for " << bad;
    } catch (const ParseError& e) {
      EXPECT_EQ(e.line(), 3) << bad;
      EXPECT_NE(e.field().find(std::string(bad).substr(2, 5)), std::string::npos) << e.field();
    }
  }
  EXPECT_THROW(parseGnssFusionConfig("gnss_fusion: [\n"), ParseError);
  EXPECT_THROW(loadGnssFusionConfig("/nonexistent/gnss.yaml"), ParseError);
}

}  // namespace
}  // namespace gvins::fusion
