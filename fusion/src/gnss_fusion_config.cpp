#include "gvins/fusion/gnss_fusion_config.hpp"

#include <fstream>
#include <limits>
#include <set>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "gvins/base/parse_error.hpp"
#include "gvins/base/yaml_reader.hpp"

namespace gvins::fusion {
namespace {

struct ModeName {
  GnssFusionMode mode;
  const char* name;
};
constexpr ModeName kModes[] = {
    {GnssFusionMode::kVio, "vio"},
    {GnssFusionMode::kGpsVel, "vio+gpsvel"},
    {GnssFusionMode::kDopp, "vio+dopp"},
    {GnssFusionMode::kDoppPsr, "vio+dopp+psr"},
    {GnssFusionMode::kDoppDpsr, "vio+dopp+dpsr"},
    {GnssFusionMode::kDoppDdcp, "vio+dopp+ddcp"},
    {GnssFusionMode::kDoppPsrNoInt, "vio+dopp+psr-nointegration"},
    {GnssFusionMode::kDoppPpp, "vio+dopp+ppp"},
};

}  // namespace

const char* toString(GnssFusionMode m) {
  for (const ModeName& n : kModes) {
    if (n.mode == m) return n.name;
  }
  return "?";
}

std::optional<GnssFusionMode> gnssFusionModeFromString(std::string_view s) {
  for (const ModeName& n : kModes) {
    if (s == n.name) return n.mode;
  }
  return std::nullopt;
}

bool GnssFusionConfig::usesDoppler() const {
  return mode != GnssFusionMode::kVio && mode != GnssFusionMode::kGpsVel;
}
bool GnssFusionConfig::usesPseudorange() const {
  return mode == GnssFusionMode::kDoppPsr || mode == GnssFusionMode::kDoppPsrNoInt || mode == GnssFusionMode::kDoppPpp;
}
bool GnssFusionConfig::usesDifferences() const {
  return mode == GnssFusionMode::kDoppDpsr || mode == GnssFusionMode::kDoppDdcp;
}

namespace {

constexpr double kMax = std::numeric_limits<double>::max();

/// Typed values of one gnss_fusion key, each failing with file, line and field.
struct Fields {
  const YamlReader& rd;
  double number(const YAML::Node& v, const std::string& f) const { return rd.number(v, f, -kMax, kMax); }
  double positive(const YAML::Node& v, const std::string& f) const {
    const double x = number(v, f);
    if (!(x > 0.0)) rd.fail(v, f, "'" + f + "' must be > 0");
    return x;
  }
  double probability(const YAML::Node& v, const std::string& f) const {
    const double x = number(v, f);
    if (!(x > 0.0 && x <= 1.0)) rd.fail(v, f, "'" + f + "' must be a probability in (0, 1] (1: no gate)");
    return x;
  }
  Eigen::Vector3d vec3(const YAML::Node& v, const std::string& f) const {
    const std::vector<double> x = rd.numbers(v, f, 3, -kMax, kMax);
    return Eigen::Vector3d(x[0], x[1], x[2]);
  }
};

/// The keys of the mode, the signals and the measurement and state noise; false if `key` is not one.
bool measurementKey(GnssFusionConfig& c, const Fields& F, const std::string& key, const std::string& f, const YAML::Node& v) {
  const YamlReader& rd = F.rd;
  auto number = [&](const YAML::Node& x, const std::string& g) { return F.number(x, g); };
  auto positive = [&](const YAML::Node& x, const std::string& g) { return F.positive(x, g); };
  auto probability = [&](const YAML::Node& x, const std::string& g) { return F.probability(x, g); };
  auto vec3 = [&](const YAML::Node& x, const std::string& g) { return F.vec3(x, g); };
  (void)number;
  (void)probability;
  if (key == "mode") {
    const std::string s = rd.text(v, f);
    const auto m = gnssFusionModeFromString(s);
    if (!m) {
      rd.fail(v, f,
              "unknown mode '" + s +
                  "' (vio, vio+gpsvel, vio+dopp, vio+dopp+psr, vio+dopp+dpsr, vio+dopp+ddcp, "
                  "vio+dopp+psr-nointegration, vio+dopp+ppp)");
    }
    c.mode = *m;
  } else if (key == "lever_arm") {
    c.leverArm = vec3(v, f);
    c.leverArmGiven = true;
  } else if (key == "calibrate_lever_arm") {
    c.calibrateLeverArm = rd.boolean(v, f);
  } else if (key == "lever_arm_sigma") {
    c.leverArmSigma = positive(v, f);
  } else if (key == "min_rotation_rate") {
    c.minRotationRate = rd.number(v, f, 0.0, kMax);
  } else if (key == "systems") {
    c.systems = rd.systems(v, f);
  } else if (key == "elevation_mask_deg") {
    c.elevationMaskDeg = rd.number(v, f, 0.0, 90.0);
    if (!(c.elevationMaskDeg < 90.0)) rd.fail(v, f, "'" + f + "' must be below 90");
  } else if (key == "ionosphere") {
    c.ionosphere = rd.choice(v, f, {"broadcast", "dual-frequency"}) == "broadcast" ? GnssIonosphere::kBroadcast
                                                                                    : GnssIonosphere::kDualFrequency;
  } else if (key == "bands") {
    rd.perSystem(v, f, [&](System sys, const std::string& fs, const YAML::Node& b) {
      const std::string t = rd.text(b, fs);
      if (const std::string err = bandListError(sys, t); !err.empty()) rd.fail(b, fs, err);
      c.bands[static_cast<std::size_t>(systemIndex(sys))] = t;
    });
  } else if (key == "ephemeris_error_m") {
    rd.perSystem(v, f, [&](System sys, const std::string& fs, const YAML::Node& e) {
      c.ephemerisError[static_cast<std::size_t>(systemIndex(sys))] = rd.number(e, fs, 0.0, kMax);
    });
  } else if (key == "precise_ephemeris_error_m") {
    rd.perSystem(v, f, [&](System sys, const std::string& fs, const YAML::Node& e) {
      c.preciseEphemerisError[static_cast<std::size_t>(systemIndex(sys))] = rd.number(e, fs, 0.0, kMax);
    });
  } else if (key == "code_sigma") {
    c.codeSigma = positive(v, f);
  } else if (key == "code_weighting") {
    c.codeWeighting = rd.choice(v, f, {"elevation", "elevation-cn0"}) == "elevation" ? GnssCodeWeighting::kElevation
                                                                                     : GnssCodeWeighting::kElevationCn0;
  } else if (key == "cn0_mask_dbhz") {
    c.cn0MaskDbHz = rd.number(v, f, 0.0, 100.0);
  } else if (key == "carrier_smoothing") {
    c.carrierSmoothing = rd.number(v, f, 0.0, 3600.0);
  } else if (key == "smoothed_code_factor") {
    c.smoothedCodeFactor = rd.number(v, f, 0.01, 1.0);
  } else if (key == "phase_sigma") {
    c.phaseSigma = positive(v, f);
  } else if (key == "ambiguity_sigma") {
    c.ambiguitySigma = positive(v, f);
  } else if (key == "ambiguity_reset_rejections") {
    c.ambiguityResetRejections = static_cast<int>(rd.number(v, f, 1.0, 1000.0));
  } else if (key == "broadcast_ambiguity_random_walk") {
    c.broadcastAmbiguityRandomWalk = rd.number(v, f, 0.0, 10.0);
  } else if (key == "broadcast_record_changes") {
    c.broadcastRecordChanges = rd.boolean(v, f);
  } else if (key == "phase_windup") {
    c.phaseWindup = rd.boolean(v, f);
  } else if (key == "rtk_hold_fix") {
    c.rtkHoldFix = rd.boolean(v, f);
  } else if (key == "rtk_revalidate_interval") {
    c.rtkRevalidateInterval = rd.number(v, f, 0.0, 3600.0);
  } else if (key == "max_ambiguities") {
    c.maxAmbiguities = static_cast<int>(rd.number(v, f, 0.0, 1000.0));
  } else if (key == "estimate_zwd") {
    c.estimateZwd = rd.boolean(v, f);
  } else if (key == "zwd_sigma") {
    c.zwdSigma = positive(v, f);
  } else if (key == "zwd_random_walk") {
    c.zwdRandomWalk = positive(v, f);
  } else if (key == "doppler_sigma") {
    c.dopplerSigma = positive(v, f);
  } else if (key == "clock_bias_random_walk") {
    c.clockBiasRandomWalk = positive(v, f);
  } else if (key == "clock_drift_random_walk") {
    c.clockDriftRandomWalk = positive(v, f);
  } else if (key == "isb_random_walk") {
    c.isbRandomWalk = rd.number(v, f, 0.0, 100.0);
  } else if (key == "isb_renewal_interval") {
    c.isbRenewalInterval = positive(v, f);
  } else if (key == "row_gate") {
    c.rowGate = probability(v, f);
  } else if (key == "epoch_gate") {
    c.epochGate = probability(v, f);
  } else {
    return false;
  }
  return true;
}

/// The keys of the stages (frame, GNSS/INS start, re-anchoring, outages), the clocks' start and
/// the base; false if `key` is not one.
bool stageKey(GnssFusionConfig& c, const Fields& F, const std::string& key, const std::string& f, const YAML::Node& v) {
  const YamlReader& rd = F.rd;
  auto number = [&](const YAML::Node& x, const std::string& g) { return F.number(x, g); };
  auto positive = [&](const YAML::Node& x, const std::string& g) { return F.positive(x, g); };
  auto vec3 = [&](const YAML::Node& x, const std::string& g) { return F.vec3(x, g); };
  if (key == "frame_yaw_sigma_deg") {
    c.frameYawSigmaDeg = positive(v, f);
  } else if (key == "frame_min_speed") {
    c.frameMinSpeed = number(v, f);
  } else if (key == "frame_reanchor_yaw_sigma_deg") {
    c.frameReanchorYawSigmaDeg = positive(v, f);
  } else if (key == "frame_start_at_rest") {
    c.frameStartAtRest = rd.boolean(v, f);
  } else if (key == "ins_start") {
    c.insStart = rd.boolean(v, f);
  } else if (key == "ins_start_window") {
    c.insStartWindow = positive(v, f);
  } else if (key == "ins_start_yaw_sigma_deg") {
    c.insStartYawSigmaDeg = positive(v, f);
  } else if (key == "frame_reanchor") {
    c.frameReanchor = rd.boolean(v, f);
  } else if (key == "frame_reanchor_position_sigma") {
    c.frameReanchorPositionSigma = positive(v, f);
  } else if (key == "outage_reset") {
    c.outageReset = positive(v, f);
  } else if (key == "reacquire_after") {
    c.reacquireAfter = rd.number(v, f, 0.0, 3600.0);
  } else if (key == "reacquire_acceleration") {
    c.reacquireAcceleration = positive(v, f);
  } else if (key == "late_system_min_satellites") {
    c.lateSystemMinSatellites = static_cast<int>(rd.number(v, f, 1.0, 100.0));
  } else if (key == "clock_ransac_threshold") {
    c.clockRansacThreshold = positive(v, f);
  } else if (key == "base_position") {
    c.basePosition = vec3(v, f);
  } else if (key == "max_base_age") {
    c.maxBaseAge = positive(v, f);
  } else {
    return false;
  }
  return true;
}

}  // namespace

GnssFusionConfig parseGnssFusionConfig(std::string_view yaml, const std::string& file) {
  const YamlReader rd(file);
  const YAML::Node root = YamlReader::loadText(std::string(yaml), file);
  GnssFusionConfig c;
  if (root.IsNull()) return c;
  if (!root.IsMap()) rd.fail(root, "", "expected a mapping");
  const Fields fields{rd};
  auto entry = [&](const std::string& key, const std::string& f, const YAML::Node& v) {
    if (!measurementKey(c, fields, key, f, v)) stageKey(c, fields, key, f, v);
  };
  static const std::set<std::string> kKeys = {
      "mode", "lever_arm", "calibrate_lever_arm", "lever_arm_sigma", "min_rotation_rate", "systems",
      "elevation_mask_deg", "ionosphere", "bands", "ephemeris_error_m", "precise_ephemeris_error_m", "code_sigma",
      "code_weighting", "cn0_mask_dbhz",
      "carrier_smoothing", "smoothed_code_factor", "phase_sigma", "ambiguity_sigma", "ambiguity_reset_rejections", "max_ambiguities", "phase_windup", "rtk_hold_fix", "rtk_revalidate_interval", "broadcast_ambiguity_random_walk", "broadcast_record_changes", "estimate_zwd", "zwd_sigma", "zwd_random_walk",
      "doppler_sigma",
      "clock_bias_random_walk", "clock_drift_random_walk", "isb_random_walk", "isb_renewal_interval", "row_gate", "epoch_gate", "frame_yaw_sigma_deg",
      "frame_min_speed", "frame_start_at_rest", "ins_start", "ins_start_window", "ins_start_yaw_sigma_deg", "frame_reanchor", "frame_reanchor_position_sigma", "frame_reanchor_yaw_sigma_deg", "outage_reset", "reacquire_after", "reacquire_acceleration", "late_system_min_satellites", "clock_ransac_threshold", "base_position", "max_base_age"};
  if (const YAML::Node section = root["gnss_fusion"]) {
    if (!section.IsMap()) rd.fail(section, "gnss_fusion", "'gnss_fusion' must be a map");
    rd.map(section, "", kKeys, entry);
    return c;
  }
  // A top-level document (no gnss_fusion: section) may hold other sections: known keys only.
  for (auto it = root.begin(); it != root.end(); ++it) {
    const std::string k = rd.key(it->first, "");
    if (kKeys.count(k)) entry(k, k, it->second);
  }
  return c;
}

GnssFusionConfig loadGnssFusionConfig(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw ParseError(path, 0, "", "cannot open file");
  std::stringstream ss;
  ss << in.rdbuf();
  return parseGnssFusionConfig(ss.str(), path);
}

}  // namespace gvins::fusion
