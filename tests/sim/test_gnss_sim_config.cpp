// The `gnss:` section of a scenario: every key is read into GnssSimConfig, defaults stay where a
// key is missing, and every malformed input throws gvins::ParseError naming the file, the line and
// the key (never anything else, never a crash).
#include <gtest/gtest.h>

#include <cmath>

#include <yaml-cpp/yaml.h>

#include "gvins/base/constants.hpp"
#include "gvins/base/parse_error.hpp"
#include "gvins/base/yaml_reader.hpp"
#include "gvins/sim/gnss_random.hpp"
#include "gvins/sim/gnss_sim_config.hpp"

namespace gvins::sim {
namespace {

const char* kFull = R"(gnss:
  navigation: ../nav/brdc.rnx
  systems: GEC
  signals: {G: [1C, 2L], E: [1C, 5Q], C: [2I, 6I]}
  signal_satellites: {G2L: [1, 3, 5]}
  cn0_offset_db: {G2L: -3.5}
  code_noise_factor: {E5Q: 0.4}
  include_unhealthy: true
  satellite_errors: {blend_records: false, sisre_m: {G: 0.7, C: 1.2}}
  precise_products: {orbit_interval_s: 900, sisre_m: {E: 0.04}, centre_of_mass: false}
  troposphere:
    relative_humidity: 0.6
    hydrostatic_scale_sigma: 0.02
    wet_scale_sigma: 0.4
    layer_height_m: 1200
    residual: [{sigma_m: 0.02, correlation_km: 30, covariance: gaussian, speed_mps: 8}]
  ionosphere:
    model_scale_sigma: 0.5
    shell_height_km: 400
    residual:
      - {sigma_tecu: 2, correlation_km: 800, covariance: gaussian, speed_mps: 40}
      - {sigma_tecu: 0.3, correlation_km: 100, covariance: exponential, speed_mps: 120}
  shapiro: false
  phase_windup: false
  rover:
    rate_hz: 5
    elevation_mask_deg: 12
    clock: {h0: 2.0e-19, h_minus2: 2.0e-20, initial_bias_max_s: 1.0e-3, initial_drift_sigma: 2.0e-7,
            isb_sigma_ns: {R: 80, E: 5}, glonass_ifb_m_per_channel: 0.3, report_offset: false, report_sigma_ns: 5}
    cn0: {zenith_dbhz: 50, horizon_dbhz: 30, satellite_sigma_db: 2, noise_db: 1, minimum_dbhz: 25}
    noise: {code_m: 0.5, phase_cycles: 0.01, doppler_mps: 0.05}
    multipath: {code_m: 0.3, phase_m: 0.003, time_constant_s: 20}
    nlos: {rate_per_min: 1, max_elevation_deg: 30, mean_duration_s: 2, bias_min_m: 5, bias_max_m: 80, cn0_drop_db: 12}
    blockage: {rate_per_min: 0.5, max_elevation_deg: 45, mean_duration_s: 3}
    cycle_slips: {rate_per_min: 0.2, max_cycles: 3, flagged_fraction: 0.5}
    outages:
      - {start_s: 60, duration_s: 60}
      - {start_s: 10, duration_s: 5, systems: GE}
    marker: DRONE
    receiver_type: UBLOX-F9P
    antenna_type: PATCH
  base:
    enabled: true
    distance_m: 5000
    azimuth_deg: 120
    height_m: 2.5
    position_llh: [35.1, 137.0, 50.0]
    rate_hz: 2
    multipath: {code_m: 0.05}
  rtcm: {msm: 4, station_id: 77, station_interval_s: 5, antenna_height_m: 1.5, ephemeris_interval_s: 30}
  error_terms: true
)";

TEST(GnssSimConfig, ReadsEveryKey) {
  const GnssSimConfig c = parseGnssSimConfigText(kFull, "/data/scenarios/s.yaml");
  EXPECT_EQ(c.navigationFile, std::filesystem::path("/data/nav/brdc.rnx"));
  EXPECT_TRUE(c.useSystem(System::Gps) && c.useSystem(System::Galileo) && c.useSystem(System::BeiDou));
  EXPECT_FALSE(c.useSystem(System::Glonass) || c.useSystem(System::Qzss));
  ASSERT_EQ(c.signals[systemIndex(System::Gps)].size(), 2u);
  EXPECT_EQ(c.signals[systemIndex(System::Gps)][1].str(), "2L");
  EXPECT_TRUE(c.transmits(SatId(System::Gps, 3), {'2', 'L'}));
  EXPECT_FALSE(c.transmits(SatId(System::Gps, 4), {'2', 'L'}));
  EXPECT_TRUE(c.transmits(SatId(System::Gps, 4), {'1', 'C'}));
  EXPECT_FALSE(c.transmits(SatId(System::BeiDou, 30), {'7', 'I'}));  // default rule kept
  EXPECT_DOUBLE_EQ(c.cn0Offset(System::Gps, {'2', 'L'}), -3.5);
  EXPECT_DOUBLE_EQ(c.preciseProducts.orbitInterval, 900.0);
  EXPECT_DOUBLE_EQ(c.preciseProducts.sisre[systemIndex(System::Galileo)], 0.04);
  EXPECT_FALSE(c.preciseProducts.centreOfMass);
  EXPECT_TRUE(GnssPreciseProductsConfig{}.centreOfMass);
  EXPECT_DOUBLE_EQ(c.cn0Offset(System::Gps, {'2', 'W'}), -6.0);  // default kept
  EXPECT_DOUBLE_EQ(c.codeNoiseFactor(System::Galileo, {'5', 'Q'}), 0.4);
  EXPECT_TRUE(c.includeUnhealthy);
  EXPECT_FALSE(c.satelliteErrors.blendRecords);
  EXPECT_DOUBLE_EQ(c.satelliteErrors.sisre[systemIndex(System::BeiDou)], 1.2);
  EXPECT_DOUBLE_EQ(c.satelliteErrors.sisre[systemIndex(System::Galileo)], 0.25);
  EXPECT_DOUBLE_EQ(c.troposphere.relativeHumidity, 0.6);
  EXPECT_DOUBLE_EQ(c.troposphere.layerHeight, 1200.0);
  ASSERT_EQ(c.troposphere.residual.size(), 1u);
  EXPECT_DOUBLE_EQ(c.troposphere.residual[0].correlationLength, 30e3);
  EXPECT_EQ(c.troposphere.residual[0].covariance, GnssRandomFieldConfig::Covariance::Gaussian);
  ASSERT_EQ(c.ionosphere.residual.size(), 2u);
  EXPECT_EQ(c.ionosphere.residual[1].covariance, GnssRandomFieldConfig::Covariance::Exponential);
  EXPECT_DOUBLE_EQ(c.ionosphere.residual[1].speed, 120.0);
  EXPECT_DOUBLE_EQ(c.ionosphere.shellHeight, 400e3);
  EXPECT_FALSE(c.shapiroDelay);
  EXPECT_FALSE(c.phaseWindup);
  EXPECT_TRUE(GnssSimConfig{}.phaseWindup);
  const GnssReceiverConfig& r = c.rover;
  EXPECT_DOUBLE_EQ(r.rate, 5.0);
  EXPECT_DOUBLE_EQ(r.elevationMaskDeg, 12.0);
  EXPECT_DOUBLE_EQ(r.clock.h0, 2.0e-19);
  EXPECT_DOUBLE_EQ(r.clock.isbSigma[systemIndex(System::Glonass)], 80e-9);
  EXPECT_DOUBLE_EQ(r.clock.isbSigma[systemIndex(System::BeiDou)], 20e-9);  // default kept
  EXPECT_DOUBLE_EQ(r.clock.glonassIfbPerChannel, 0.3);
  EXPECT_FALSE(r.clock.reportOffset);
  EXPECT_DOUBLE_EQ(r.clock.reportSigma, 5e-9);
  EXPECT_DOUBLE_EQ(r.cn0.minimum, 25.0);
  EXPECT_DOUBLE_EQ(r.noise.phase, 0.01);
  EXPECT_DOUBLE_EQ(r.multipath.timeConstant, 20.0);
  EXPECT_DOUBLE_EQ(r.nlos.biasMax, 80.0);
  EXPECT_DOUBLE_EQ(r.blockage.maxElevationDeg, 45.0);
  EXPECT_EQ(r.slips.maxCycles, 3);
  ASSERT_EQ(r.outages.size(), 2u);
  EXPECT_DOUBLE_EQ(r.outages[0].duration, 60.0);
  EXPECT_TRUE(r.outages[0].systems[systemIndex(System::Glonass)]);
  EXPECT_FALSE(r.outages[1].systems[systemIndex(System::Glonass)]);
  EXPECT_TRUE(r.outages[1].systems[systemIndex(System::Galileo)]);
  EXPECT_EQ(r.markerName, "DRONE");
  EXPECT_EQ(r.receiverType, "UBLOX-F9P");
  EXPECT_DOUBLE_EQ(c.base.distance, 5000.0);
  ASSERT_TRUE(c.base.positionLlh);
  EXPECT_DOUBLE_EQ(c.base.positionLlh->z(), 50.0);
  EXPECT_DOUBLE_EQ(c.base.receiver.rate, 2.0);
  EXPECT_DOUBLE_EQ(c.base.receiver.multipath.code, 0.05);
  EXPECT_DOUBLE_EQ(c.base.receiver.multipath.timeConstant, 60.0);  // base default kept
  EXPECT_EQ(c.rtcm.msm, 4);
  EXPECT_EQ(c.rtcm.stationId, 77);
  ASSERT_TRUE(c.rtcm.antennaHeight);
  EXPECT_DOUBLE_EQ(*c.rtcm.antennaHeight, 1.5);
  EXPECT_TRUE(c.writeErrorTerms);
}

TEST(GnssSimConfig, DefaultsAreRealisticReceivers) {
  const GnssSimConfig c = parseGnssSimConfigText("gnss:\n  rover: {rate_hz: 10}\n", "d.yaml");
  const GnssSimConfig d;
  EXPECT_EQ(c.rover.rate, 10.0);
  EXPECT_EQ(parseGnssSimConfigText("", "e.yaml").rover.rate, d.rover.rate);
  EXPECT_EQ(parseGnssSimConfigText("imu: {rate_hz: 200}\n", "e.yaml").base.distance, 3000.0);
  // Five systems, three frequencies where the system has them, BeiDou B2I only on BDS-2.
  EXPECT_EQ(d.signals[systemIndex(System::Gps)].size(), 3u);
  EXPECT_EQ(d.signals[systemIndex(System::Glonass)].size(), 2u);
  EXPECT_TRUE(d.transmits(SatId(System::BeiDou, 14), {'7', 'I'}));
  EXPECT_FALSE(d.transmits(SatId(System::BeiDou, 24), {'7', 'I'}));
  EXPECT_TRUE(d.transmits(SatId(System::BeiDou, 24), {'6', 'I'}));
  // Rover 10 Hz, base 1 Hz at 3 km; the rover's errors harsher than the base's.
  EXPECT_EQ(d.rover.rate, 10.0);
  EXPECT_EQ(d.base.receiver.rate, 1.0);
  EXPECT_GT(d.rover.multipath.code, d.base.receiver.multipath.code);
  EXPECT_GT(d.rover.nlos.ratePerMinute, 0.0);
  EXPECT_EQ(d.base.receiver.nlos.ratePerMinute, 0.0);
  EXPECT_EQ(d.rtcm.msm, 7);
  // A relative navigation path without a scenario folder stays relative.
  EXPECT_EQ(parseGnssSimConfigText("gnss: {navigation: a/b.nav}\n", "").navigationFile, std::filesystem::path("a/b.nav"));
}

TEST(GnssSimConfig, TheSectionNodeOfALargerScenario) {
  const YAML::Node root = YamlReader::loadText("name: test\ngnss:\n  rover: {elevation_mask_deg: 15}\n", "test.yaml");
  const GnssSimConfig c = parseGnssSimConfig(root["gnss"], "scenario.yaml");
  EXPECT_DOUBLE_EQ(c.rover.elevationMaskDeg, 15.0);
  EXPECT_DOUBLE_EQ(parseGnssSimConfig(YAML::Node(), "scenario.yaml").rover.elevationMaskDeg, 5.0);
}

struct BadCase {
  const char* yaml;
  std::int64_t line;
  const char* key;
};

TEST(GnssSimConfig, MalformedInputNamesFileLineAndKey) {
  const BadCase cases[] = {
      {"gnss:\n  bogus: 1\n", 2, "gnss.bogus"},
      {"gnss:\n  rover:\n    rate_hz: fast\n", 3, "gnss.rover.rate_hz"},
      {"gnss:\n  rover:\n    rate_hz: 0\n", 3, "gnss.rover.rate_hz"},
      {"gnss:\n  rover:\n    rate_hz: .nan\n", 3, "gnss.rover.rate_hz"},
      {"gnss:\n  rover:\n    rate_hz: 1e400\n", 3, "gnss.rover.rate_hz"},
      {"gnss:\n  rover:\n    rate_hz: [1]\n", 3, "gnss.rover.rate_hz"},
      {"gnss:\n  rover:\n    clock: {h1: 1}\n", 3, "gnss.rover.clock.h1"},
      {"gnss:\n  rover:\n    clock:\n      isb_sigma_ns: {X: 3}\n", 4, "gnss.rover.clock.isb_sigma_ns.X"},
      {"gnss:\n  rover:\n    cn0: {zenith_dbhz: 30, horizon_dbhz: 40}\n", 3, "gnss.rover.cn0"},
      {"gnss:\n  rover:\n    noise: {phase_cycles: 0.5}\n", 3, "gnss.rover.noise.phase_cycles"},
      {"gnss:\n  rover:\n    nlos: {bias_min_m: 50, bias_max_m: 10}\n", 3, "gnss.rover.nlos"},
      {"gnss:\n  rover:\n    cycle_slips: {max_cycles: 2.5}\n", 3, "gnss.rover.cycle_slips.max_cycles"},
      {"gnss:\n  rover:\n    outages:\n      - {start_s: 5}\n", 4, "gnss.rover.outages[0]"},
      {"gnss:\n  rover:\n    outages: {start_s: 5}\n", 3, "gnss.rover.outages"},
      {"gnss:\n  rover:\n    outages:\n      - {start_s: 5, duration_s: 1, systems: GQ}\n", 4,
       "gnss.rover.outages[0].systems"},
      {"gnss:\n  systems: XYZ\n", 2, "gnss.systems"},
      {"gnss:\n  systems: ''\n", 2, "gnss.systems"},
      {"gnss:\n  signals: {G: [1C, 1W]}\n", 2, "gnss.signals.G[1]"},
      {"gnss:\n  signals: {G: [1C, 1C]}\n", 2, "gnss.signals.G[1]"},
      {"gnss:\n  signals: {C: [8I]}\n", 2, "gnss.signals.C[0]"},
      {"gnss:\n  signals: {G: 1C}\n", 2, "gnss.signals.G"},
      {"gnss:\n  signals: {G: [C1]}\n", 2, "gnss.signals.G[0]"},
      {"gnss:\n  signal_satellites: {G9Q: [1]}\n", 2, "gnss.signal_satellites.G9Q"},
      {"gnss:\n  signal_satellites: {G5Q: [40]}\n", 2, "gnss.signal_satellites.G5Q[0]"},
      {"gnss:\n  cn0_offset_db: {Q1C: 1}\n", 2, "gnss.cn0_offset_db.Q1C"},
      {"gnss:\n  satellite_errors: {sisre_m: {G: -1}}\n", 2, "gnss.satellite_errors.sisre_m.G"},
      {"gnss:\n  precise_products: {centre_of_mass: maybe}\n", 2, "gnss.precise_products.centre_of_mass"},
      {"gnss:\n  troposphere:\n    residual: [{sigma_m: 0.01, covariance: matern}]\n", 3,
       "gnss.troposphere.residual[0].covariance"},
      {"gnss:\n  troposphere:\n    residual: [{sigma_tecu: 1}]\n", 3, "gnss.troposphere.residual[0].sigma_tecu"},
      {"gnss:\n  ionosphere:\n    shell_height_km: 5\n", 3, "gnss.ionosphere.shell_height_km"},
      {"gnss:\n  base:\n    position_llh: [35, 137]\n", 3, "gnss.base.position_llh"},
      {"gnss:\n  base:\n    position_llh: [95, 137, 0]\n", 3, "gnss.base.position_llh"},
      {"gnss:\n  base:\n    enabled: maybe\n", 3, "gnss.base.enabled"},
      {"gnss:\n  rtcm: {msm: 5}\n", 2, "gnss.rtcm.msm"},
      {"gnss:\n  rtcm: {station_id: 5000}\n", 2, "gnss.rtcm.station_id"},
      {"gnss:\n  navigation: ''\n", 2, "gnss.navigation"},
      {"gnss:\n  navigation: [a]\n", 2, "gnss.navigation"},
      {"gnss: 5\n", 1, "gnss"},
      {"gnss:\n  rover: [1, 2]\n", 2, "gnss.rover"},
      {"gnss:\n  ? [a, b]\n  : 1\n", 2, "gnss"},
      {"- a\n- b\n", 1, ""},
      {"gnss:\n  rover: {rate_hz: 1\n", 3, "YAML"},
      {"gnss:\n  rover: *nothing\n", 2, "YAML"},
  };
  for (const BadCase& c : cases) {
    try {
      parseGnssSimConfigText(c.yaml, "bad.yaml");
      ADD_FAILURE() << "accepted:\n" << c.yaml;
    } catch (const ParseError& e) {
      EXPECT_EQ(e.file(), "bad.yaml") << c.yaml;
      EXPECT_EQ(e.line(), c.line) << c.yaml << "\n" << e.what();
      EXPECT_EQ(e.field(), c.key) << c.yaml << "\n" << e.what();
      EXPECT_FALSE(e.reason().empty());
    }
  }
}

// gnss.precise_products.ssr_interval_s: 0 (no gnss/ssr.rtcm3) or one of the RTCM DF391 update
// intervals, default 5 s; anything else names the key and the line of the value.
TEST(GnssSimConfig, SsrIntervalIsZeroOrAnRtcmUpdateInterval) {
  EXPECT_DOUBLE_EQ(GnssPreciseProductsConfig{}.ssrInterval, 5.0);
  EXPECT_DOUBLE_EQ(parseGnssSimConfigText("gnss:\n  rover: {rate_hz: 5}\n", "d.yaml").preciseProducts.ssrInterval, 5.0);
  EXPECT_DOUBLE_EQ(parseGnssSimConfigText(kFull, "f.yaml").preciseProducts.ssrInterval, 5.0);
  for (double v : {0.0, 1.0, 5.0, 60.0, 10800.0}) {
    const std::string y = "gnss:\n  precise_products: {ssr_interval_s: " + std::to_string(v) + "}\n";
    EXPECT_DOUBLE_EQ(parseGnssSimConfigText(y, "ok.yaml").preciseProducts.ssrInterval, v) << y;
  }
  // Other keys of the section are kept alongside.
  const GnssSimConfig c =
      parseGnssSimConfigText("gnss:\n  precise_products: {ssr_interval_s: 60, orbit_interval_s: 900}\n", "ok.yaml");
  EXPECT_DOUBLE_EQ(c.preciseProducts.ssrInterval, 60.0);
  EXPECT_DOUBLE_EQ(c.preciseProducts.orbitInterval, 900.0);

  const BadCase cases[] = {
      {"gnss:\n  precise_products: {ssr_interval_s: 3}\n", 2, "gnss.precise_products.ssr_interval_s"},
      {"gnss:\n  precise_products: {ssr_interval_s: -1}\n", 2, "gnss.precise_products.ssr_interval_s"},
      {"gnss:\n  precise_products: {ssr_interval_s: often}\n", 2, "gnss.precise_products.ssr_interval_s"},
      {"gnss:\n  precise_products: {ssr_interval_s: 2.5}\n", 2, "gnss.precise_products.ssr_interval_s"},
      {"gnss:\n  precise_products: {ssr_interval_s: 20000}\n", 2, "gnss.precise_products.ssr_interval_s"},
      {"gnss:\n  precise_products: {ssr_interval_s: .nan}\n", 2, "gnss.precise_products.ssr_interval_s"},
      {"gnss:\n  precise_products: {ssr_interval_s: [5]}\n", 2, "gnss.precise_products.ssr_interval_s"},
      // Block style: the line of the value.
      {"gnss:\n  rover: {rate_hz: 5}\n  precise_products:\n    write: true\n    ssr_interval_s: 3\n", 5,
       "gnss.precise_products.ssr_interval_s"},
      {"gnss:\n  precise_products: {ssr_intervall_s: 5}\n", 2, "gnss.precise_products.ssr_intervall_s"},
  };
  for (const BadCase& b : cases) {
    try {
      parseGnssSimConfigText(b.yaml, "bad.yaml");
      ADD_FAILURE() << "accepted:\n" << b.yaml;
    } catch (const ParseError& e) {
      EXPECT_EQ(e.file(), "bad.yaml") << b.yaml;
      EXPECT_EQ(e.line(), b.line) << b.yaml << "\n" << e.what();
      EXPECT_EQ(e.field(), b.key) << b.yaml << "\n" << e.what();
      EXPECT_NE(e.reason().find(b.key), std::string::npos) << e.what();
    }
  }
  // Not an update interval: the message lists the allowed ones.
  try {
    parseGnssSimConfigText("gnss:\n  precise_products: {ssr_interval_s: 3}\n", "bad.yaml");
    ADD_FAILURE() << "3 s accepted";
  } catch (const ParseError& e) {
    EXPECT_NE(e.reason().find("1, 2, 5, 10"), std::string::npos) << e.what();
    EXPECT_NE(e.reason().find("0 or"), std::string::npos) << e.what();
  }
}

TEST(GnssSimConfig, RandomlyDamagedScenariosThrowOnlyParseErrors) {
  // Byte flips, truncations and insertions of YAML punctuation into the full scenario: every
  // result is either a valid configuration or a ParseError; nothing else escapes.
  GnssRandom rng(99);
  const std::string full = kFull;
  const char punct[] = "{}[]:,-?*&!|>'\"#% \n\t0.e";
  int errors = 0, accepted = 0;
  for (int i = 0; i < 1500; ++i) {
    std::string s = full;
    const int edits = 1 + static_cast<int>(rng.integer(0, 3));
    for (int k = 0; k < edits && !s.empty(); ++k) {
      const std::size_t pos = static_cast<std::size_t>(rng.integer(0, static_cast<std::int64_t>(s.size()) - 1));
      switch (rng.integer(0, 3)) {
        case 0: s[pos] = punct[rng.integer(0, sizeof punct - 2)]; break;
        case 1: s.insert(pos, 1, punct[rng.integer(0, sizeof punct - 2)]); break;
        case 2: s.resize(pos); break;
        default: s[pos] = static_cast<char>(rng.integer(1, 255)); break;
      }
    }
    try {
      const GnssSimConfig c = parseGnssSimConfigText(s, "fuzz.yaml");
      ++accepted;
      EXPECT_GT(c.rover.rate, 0.0);
      EXPECT_TRUE(std::isfinite(c.rover.noise.code));
    } catch (const ParseError& e) {
      ++errors;
      EXPECT_EQ(e.file(), "fuzz.yaml");
      EXPECT_GE(e.line(), 0);
    }
  }
  EXPECT_GT(errors, 250);
  EXPECT_GT(accepted, 50);
}

}  // namespace
}  // namespace gvins::sim
