#include "gvins/fusion/gnss_fusion_config.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "gvins/base/parse_error.hpp"

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
};

std::int64_t lineOf(const YAML::Node& n) {
  const YAML::Mark m = n.Mark();
  return m.is_null() ? 0 : m.line + 1;
}

struct Reader {
  const std::string& file;

  [[noreturn]] void fail(const YAML::Node& n, const std::string& field, const std::string& what) const {
    throw ParseError(file, lineOf(n), field, what);
  }
  std::string scalar(const YAML::Node& n, const std::string& field) const {
    if (!n.IsScalar()) fail(n, field, "expected a scalar value");
    return n.Scalar();
  }
  double number(const YAML::Node& n, const std::string& field) const {
    const std::string s = scalar(n, field);
    errno = 0;
    char* end = nullptr;
    const double v = std::strtod(s.c_str(), &end);
    if (s.empty() || end != s.c_str() + s.size() || errno == ERANGE || !std::isfinite(v)) {
      fail(n, field, "not a finite number: '" + s + "'");
    }
    return v;
  }
  double positive(const YAML::Node& n, const std::string& field) const {
    const double v = number(n, field);
    if (!(v > 0.0)) fail(n, field, "must be > 0");
    return v;
  }
  double probability(const YAML::Node& n, const std::string& field) const {
    const double v = number(n, field);
    if (!(v > 0.0 && v <= 1.0)) fail(n, field, "must be a probability in (0, 1] (1: no gate)");
    return v;
  }
  bool boolean(const YAML::Node& n, const std::string& field) const {
    const std::string s = scalar(n, field);
    if (s == "true" || s == "True" || s == "yes" || s == "on" || s == "1") return true;
    if (s == "false" || s == "False" || s == "no" || s == "off" || s == "0") return false;
    fail(n, field, "expected true or false, got '" + s + "'");
  }
  Eigen::Vector3d vec3(const YAML::Node& n, const std::string& field) const {
    if (!n.IsSequence() || n.size() != 3) fail(n, field, "expected a sequence of 3 numbers");
    return {number(n[0], field), number(n[1], field), number(n[2], field)};
  }
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
  return mode == GnssFusionMode::kDoppPsr || mode == GnssFusionMode::kDoppPsrNoInt;
}
bool GnssFusionConfig::usesDifferences() const {
  return mode == GnssFusionMode::kDoppDpsr || mode == GnssFusionMode::kDoppDdcp;
}

GnssFusionConfig parseGnssFusionConfig(std::string_view yaml, const std::string& file) {
  const Reader rd{file};
  YAML::Node root;
  try {
    root = YAML::Load(std::string(yaml));
  } catch (const YAML::Exception& e) {
    throw ParseError(file, e.mark.is_null() ? 0 : e.mark.line + 1, "YAML", e.msg);
  }
  GnssFusionConfig c;
  if (root.IsNull()) return c;
  if (!root.IsMap()) rd.fail(root, "", "expected a mapping");
  YAML::Node map = root["gnss_fusion"] ? root["gnss_fusion"] : root;
  if (!map.IsMap()) rd.fail(map, "gnss_fusion", "expected a mapping");
  static const std::set<std::string> kKeys = {
      "mode", "lever_arm", "calibrate_lever_arm", "lever_arm_sigma", "min_rotation_rate", "systems",
      "elevation_mask_deg", "ionosphere", "bands", "ephemeris_error_m", "code_sigma", "doppler_sigma", "clock_bias_random_walk", "clock_drift_random_walk",
      "row_gate", "epoch_gate", "frame_yaw_sigma_deg", "frame_min_speed", "outage_reset",
      "clock_ransac_threshold", "base_position", "max_base_age"};
  for (const auto& kv : map) {
    if (!kv.first.IsScalar()) rd.fail(kv.first, "", "keys must be names");
    const std::string key = kv.first.Scalar();
    const YAML::Node& v = kv.second;
    if (root["gnss_fusion"] && !kKeys.count(key)) rd.fail(kv.first, key, "unknown key");
    if (key == "mode") {
      const std::string s = rd.scalar(v, key);
      const auto m = gnssFusionModeFromString(s);
      if (!m) {
        rd.fail(v, key,
                "unknown mode '" + s +
                    "' (vio, vio+gpsvel, vio+dopp, vio+dopp+psr, vio+dopp+dpsr, vio+dopp+ddcp, "
                    "vio+dopp+psr-nointegration)");
      }
      c.mode = *m;
    } else if (key == "lever_arm") {
      c.leverArm = rd.vec3(v, key);
      c.leverArmGiven = true;
    } else if (key == "calibrate_lever_arm") {
      c.calibrateLeverArm = rd.boolean(v, key);
    } else if (key == "lever_arm_sigma") {
      c.leverArmSigma = rd.positive(v, key);
    } else if (key == "min_rotation_rate") {
      c.minRotationRate = rd.number(v, key);
      if (c.minRotationRate < 0.0) rd.fail(v, key, "must be >= 0");
    } else if (key == "systems") {
      const std::string s = rd.scalar(v, key);
      c.systems.fill(false);
      for (char ch : s) {
        const auto sys = systemFromLetter(ch);
        if (!sys) rd.fail(v, key, std::string("unknown system letter '") + ch + "'");
        c.systems[static_cast<std::size_t>(systemIndex(*sys))] = true;
      }
    } else if (key == "elevation_mask_deg") {
      c.elevationMaskDeg = rd.number(v, key);
      if (c.elevationMaskDeg < 0.0 || c.elevationMaskDeg >= 90.0) rd.fail(v, key, "must be in [0, 90)");
    } else if (key == "ionosphere") {
      const std::string s = rd.scalar(v, key);
      if (s == "broadcast") c.ionosphere = GnssIonosphere::kBroadcast;
      else if (s == "dual-frequency") c.ionosphere = GnssIonosphere::kDualFrequency;
      else rd.fail(v, key, "expected broadcast or dual-frequency, got '" + s + "'");
    } else if (key == "bands" || key == "ephemeris_error_m") {
      if (!v.IsMap()) rd.fail(v, key, "expected a mapping of system letters, e.g. {G: ..., E: ...}");
      for (const auto& e : v) {
        const std::string letter = rd.scalar(e.first, key);
        const auto sys = letter.size() == 1 ? systemFromLetter(letter[0]) : std::nullopt;
        const std::string field = key + "." + letter;
        if (!sys) rd.fail(e.first, field, "unknown system letter '" + letter + "'");
        const auto i = static_cast<std::size_t>(systemIndex(*sys));
        if (key == "ephemeris_error_m") {
          c.ephemerisError[i] = rd.number(e.second, field);
          if (!(c.ephemerisError[i] >= 0.0)) rd.fail(e.second, field, "must be >= 0");
          continue;
        }
        const std::string b = rd.scalar(e.second, field);
        if (const std::string err = bandListError(*sys, b); !err.empty()) rd.fail(e.second, field, err);
        c.bands[i] = b;
      }
    } else if (key == "code_sigma") {
      c.codeSigma = rd.positive(v, key);
    } else if (key == "doppler_sigma") {
      c.dopplerSigma = rd.positive(v, key);
    } else if (key == "clock_bias_random_walk") {
      c.clockBiasRandomWalk = rd.positive(v, key);
    } else if (key == "clock_drift_random_walk") {
      c.clockDriftRandomWalk = rd.positive(v, key);
    } else if (key == "row_gate") {
      c.rowGate = rd.probability(v, key);
    } else if (key == "epoch_gate") {
      c.epochGate = rd.probability(v, key);
    } else if (key == "frame_yaw_sigma_deg") {
      c.frameYawSigmaDeg = rd.positive(v, key);
    } else if (key == "frame_min_speed") {
      c.frameMinSpeed = rd.number(v, key);
    } else if (key == "outage_reset") {
      c.outageReset = rd.positive(v, key);
    } else if (key == "clock_ransac_threshold") {
      c.clockRansacThreshold = rd.positive(v, key);
    } else if (key == "base_position") {
      c.basePosition = rd.vec3(v, key);
    } else if (key == "max_base_age") {
      c.maxBaseAge = rd.positive(v, key);
    } else if (!root["gnss_fusion"]) {
      continue;  // a top-level document may hold other sections
    }
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
