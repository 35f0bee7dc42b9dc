// YAML options of SPP: values reach the configuration, every mistake names file, line and key.
#include <gtest/gtest.h>

#include "gvins/gnss/spp_config.hpp"

using namespace gvins;

TEST(SppConfig, ParsesEveryKey) {
  const std::string y =
      "rtk:\n"
      "  ignored: 1\n"
      "spp:\n"
      "  systems: GEC\n"
      "  elevation_mask_deg: 10\n"
      "  snr_mask_dbhz: 30\n"
      "  frequencies: 2\n"
      "  bands: {G: \"15\", E: \"17\"}\n"
      "  ionosphere: dual-frequency\n"
      "  troposphere: off\n"
      "  meteo: climatology\n"
      "  relative_humidity: 0.7\n"
      "  weighting: {scheme: elevation-snr, a_m: 0.5, b_m: 0.2, snr_reference_dbhz: 40,\n"
      "              doppler_sigma_mps: 0.1, system_factor: {R: 2, C: 1.2}}\n"
      "  ionosphere_model_error: 0.4\n"
      "  troposphere_zenith_error_m: 0.2\n"
      "  ephemeris_error_m: {G: 1.0}\n"
      "  ephemeris_alarm_accuracy_m: 20\n"
      "  fault_exclusion: {enabled: false, false_alarm_probability: 0.01, max_exclusions: 3,\n"
      "                    max_candidates: 5, min_redundancy: 2}\n"
      "  robust: {enabled: false, k0: 1.5, k1: 4, k0_failed: 1.2, k1_failed: 2.5, min_scale: 0.3, max_iterations: 3}\n"
      "  ionosphere_estimation: {enabled: false, prior_fraction: 0.5, min_prior_sigma_m: 0.2}\n"
      "  max_gdop: 20\n"
      "  isb_prior_sigma_m: 5\n"
      "  isb_random_walk_m2ps: 0.1\n"
      "  qzss_gps_clock: false\n"
      "  max_iterations: 12\n"
      "  velocity: false\n"
      "  carrier_smoothing_s: 60\n"
      "  allow_unhealthy: true\n"
      "  reported_error: {enabled: false, noise_scale: 0.5, ionosphere_correlation_km: 1500, min_variance_factor: 0.5,\n"
      "                   excess_correlation: 0.25}\n";
  const SppConfig c = parseSppConfig(y, "all.yaml");
  EXPECT_TRUE(c.useSystem(System::Gps) && c.useSystem(System::Galileo) && c.useSystem(System::BeiDou));
  EXPECT_FALSE(c.useSystem(System::Glonass) || c.useSystem(System::Qzss));
  EXPECT_NEAR(c.elevationMask, 10.0 * constants::kDegToRad, 1e-15);
  EXPECT_EQ(c.snrMask, 30.0);
  EXPECT_EQ(c.frequencies, 2);
  EXPECT_EQ(c.bands[systemIndex(System::Gps)], "15");
  EXPECT_EQ(c.bands[systemIndex(System::Galileo)], "17");
  EXPECT_EQ(c.bands[systemIndex(System::BeiDou)], "276");
  EXPECT_EQ(c.ionosphere, IonosphereOption::DualFrequency);
  EXPECT_EQ(c.troposphere, TroposphereOption::Off);
  EXPECT_TRUE(c.climatologicalMeteo);
  EXPECT_EQ(c.relativeHumidity, 0.7);
  EXPECT_EQ(c.weighting.scheme, WeightingScheme::ElevationSnr);
  EXPECT_EQ(c.weighting.a, 0.5);
  EXPECT_EQ(c.weighting.systemFactor[systemIndex(System::Glonass)], 2.0);
  EXPECT_EQ(c.weighting.systemFactor[systemIndex(System::BeiDou)], 1.2);
  EXPECT_EQ(c.ephemerisError[systemIndex(System::Gps)], 1.0);
  EXPECT_FALSE(c.faultExclusion.enabled);
  EXPECT_EQ(c.faultExclusion.maxCandidates, 5);
  EXPECT_FALSE(c.robust.enabled);
  EXPECT_EQ(c.robust.k1, 4.0);
  EXPECT_EQ(c.robust.k0Failed, 1.2);
  EXPECT_EQ(c.robust.k1Failed, 2.5);
  EXPECT_FALSE(c.reportedError.enabled);
  EXPECT_EQ(c.reportedError.noiseScale, 0.5);
  EXPECT_DOUBLE_EQ(c.reportedError.ionosphereCorrelationLength, 1500e3);
  EXPECT_EQ(c.reportedError.minVarianceFactor, 0.5);
  EXPECT_EQ(c.reportedError.excessCorrelation, 0.25);
  EXPECT_FALSE(c.ionosphereEstimation.enabled);
  EXPECT_EQ(c.maxGdop, 20.0);
  EXPECT_FALSE(c.qzssUsesGpsClock);
  EXPECT_EQ(c.maxIterations, 12);
  EXPECT_FALSE(c.velocity);
  EXPECT_DOUBLE_EQ(c.carrierSmoothing, 60.0);
  EXPECT_TRUE(c.ephemeris.allowUnhealthy);
  // Missing keys keep the base values; an empty document is the defaults.
  EXPECT_EQ(parseSppConfig("", "e.yaml").frequencies, 1);
  EXPECT_EQ(parseSppConfig("spp:\n  max_gdop: 5\n", "b.yaml", c).frequencies, 2);
}

// The example file shipped with gvins-spp parses and equals the built-in defaults.
TEST(SppConfig, ShippedExampleIsTheDefaults) {
  const SppConfig c = loadSppConfig(std::string(GVINS_SOURCE_DIR) + "/apps/spp/spp.yaml");
  const SppConfig d;
  EXPECT_EQ(c.systems, d.systems);
  EXPECT_EQ(c.elevationMask, d.elevationMask);
  EXPECT_EQ(c.bands, d.bands);
  EXPECT_EQ(c.frequencies, d.frequencies);
  EXPECT_EQ(c.ionosphere, d.ionosphere);
  EXPECT_EQ(c.climatologicalMeteo, d.climatologicalMeteo);
  EXPECT_EQ(c.weighting.systemFactor, d.weighting.systemFactor);
  EXPECT_EQ(c.ephemerisError, d.ephemerisError);
  EXPECT_EQ(c.faultExclusion.falseAlarmProbability, d.faultExclusion.falseAlarmProbability);
  EXPECT_EQ(c.robust.k1, d.robust.k1);
  EXPECT_EQ(c.ionosphereEstimation.priorFraction, d.ionosphereEstimation.priorFraction);
  EXPECT_EQ(c.isbPriorSigma, d.isbPriorSigma);
  EXPECT_EQ(c.qzssUsesGpsClock, d.qzssUsesGpsClock);
}

namespace {
void expectError(const std::string& yaml, std::int64_t line, const std::string& key, const std::string& what) {
  try {
    parseSppConfig(yaml, "bad.yaml");
    FAIL() << yaml;
  } catch (const ParseError& e) {
    EXPECT_EQ(e.file(), "bad.yaml");
    EXPECT_EQ(e.line(), line) << e.what();
    EXPECT_NE(e.field().find(key), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
  }
}
}  // namespace

TEST(SppConfig, ErrorsNameFileLineAndKey) {
  expectError("spp:\n  elevation_mask: 10\n", 2, "spp.elevation_mask", "unknown key");
  expectError("spp:\n  elevation_mask_deg: high\n", 2, "spp.elevation_mask_deg", "wrong type");
  expectError("spp:\n  elevation_mask_deg: 95\n", 2, "spp.elevation_mask_deg", "outside");
  expectError("spp:\n  systems: GXZ\n", 2, "spp.systems", "unknown system letter 'X'");
  expectError("spp:\n  frequencies: 4\n", 2, "spp.frequencies", "outside");
  expectError("spp:\n  ionosphere: klobuchar\n", 2, "spp.ionosphere", "must be off, broadcast");
  expectError("spp:\n\n  weighting: {scheme: elevation, c_m: 1}\n", 3, "spp.weighting.c_m", "unknown key");
  expectError("spp:\n  bands: {G: \"19\"}\n", 2, "spp.bands.G", "band '9'");
  expectError("spp:\n  bands: {X: \"1\"}\n", 2, "spp.bands.X", "unknown system");
  expectError("spp:\n  robust: {k0: 3, k1: 2}\n", 2, "spp.robust", "larger");
  expectError("spp:\n  robust: {k0_failed: 3, k1_failed: 2}\n", 2, "spp.robust", "k1_failed must be larger");
  expectError("spp:\n  velocity: maybe\n", 2, "spp.velocity", "wrong type");
  expectError("spp:\n  reported_error: {noise_scale: -1}\n", 2, "spp.reported_error.noise_scale", "outside");
  expectError("spp:\n  reported_error: {scale: 1}\n", 2, "spp.reported_error.scale", "unknown key");
  expectError("spp:\n  reported_error: {min_variance_factor: 2}\n", 2, "spp.reported_error.min_variance_factor", "outside");
  expectError("spp:\n  reported_error: {excess_correlation: -0.1}\n", 2, "spp.reported_error.excess_correlation", "outside");
  expectError("spp:\n  carrier_smoothing_s: -1\n", 2, "spp.carrier_smoothing_s", "");
  expectError("spp: [1, 2\n", 2, "YAML", "");
  expectError("- a\n- b\n", 1, "", "map");
  expectError("spp:\n  weighting: 3\n", 2, "spp.weighting", "must be a map");
  expectError("spp:\n  weighting: { {R: 2}}\n", 2, "spp.weighting", "plain names");  // found by fuzzing
  try {
    loadSppConfig("/nonexistent/spp.yaml");
    FAIL();
  } catch (const ParseError& e) {
    EXPECT_EQ(e.file(), "/nonexistent/spp.yaml");
  }
  EXPECT_THROW(parseSystemLetters("GQ"), std::invalid_argument);
}
