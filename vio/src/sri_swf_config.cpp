// SriSwfConfig validation and YAML loading (yaml-cpp, as sensor_yaml.cpp; every error is a
// gvins::ParseError naming file, line and field).
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>

#include <yaml-cpp/yaml.h>

#include "gvins/base/parse_error.hpp"
#include "gvins/base/yaml_reader.hpp"
#include "gvins/base/text_fields.hpp"
#include "gvins/vio/sri_swf_estimator.hpp"

namespace gvins::vio {

void SriSwfConfig::validate() const {
  auto req = [](bool ok, const std::string& what) {
    if (!ok) throw std::invalid_argument("SriSwfConfig: " + what);
  };
  // No camera: an IMU-only state (GNSS/INS through the backend's clients), frames without features.
  req(cameras.size() <= 2, "cameras: at most 2 (stereo)");
  for (const CameraCalibration& c : cameras) {
    req(c.intrinsics.fx > 0 && c.intrinsics.fy > 0, "cameras: focal lengths must be positive");
  }
  req(std::isfinite(gravity) && gravity > 0, "gravity must be positive");
  req(imu.gyroscope_noise_density > 0 && imu.accelerometer_noise_density > 0 && imu.gyroscope_random_walk > 0 &&
          imu.accelerometer_random_walk > 0 && imu.rate_hz > 0,
      "imu noise parameters must be positive");
  req(pixel_noise > 0 && std::isfinite(pixel_noise), "pixel_noise must be positive");
  req(surface_noise >= 0 && std::isfinite(surface_noise), "surface_noise must be >= 0");
  req(window >= 3 && window <= 100, "window must be in [3, 100]");
  req(max_slam_features >= 0 && max_slam_features <= 1000, "max_slam_features must be in [0, 1000]");
  req(min_track_msckf >= 2, "min_track_msckf must be >= 2");
  req(min_depth > 0 && max_depth > min_depth, "need 0 < min_depth < max_depth");
  req(min_baseline_ratio >= 0, "min_baseline_ratio must be >= 0");
  req(chi2_probability > 0, "chi2_probability must be > 0 (>= 1 disables the gate)");
  req(max_msckf_per_frame >= 0, "max_msckf_per_frame must be >= 0");
  req(reanchor_sigma >= 0, "reanchor_sigma must be >= 0 (0: exact change of variables)");
  req(lockout_reset_s >= 0 && std::isfinite(lockout_reset_s), "lockout_reset_s must be >= 0");
  req(position_random_walk >= 0 && std::isfinite(position_random_walk), "position_random_walk must be >= 0");
  req(attitude_random_walk >= 0 && std::isfinite(attitude_random_walk), "attitude_random_walk must be >= 0");
  req(zero_velocity_sigma > 0, "zero_velocity_sigma must be positive");
  req(first_estimate_delay >= 0, "first_estimate_delay must not be negative");
  req(imu_bias_renewal >= 0 && imu_bias_renewal <= 10, "imu_bias_renewal must be in [0, 10] s");
  req(init_window > 0.05 && init_window <= 30, "init.window must be in (0.05, 30] s");
  req(static_max_accel_std > 0 && static_max_gyro_std > 0 && static_max_parallax > 0,
      "init static thresholds must be positive");
  req(init_motion_frames >= 3, "init.motion_frames must be >= 3");
  req(init_mono_motion_frames >= 5, "init.mono_motion_frames must be >= 5");
  req(init_mono_max_scale_sigma > 0 && std::isfinite(init_mono_max_scale_sigma), "init.mono_max_scale_sigma must be > 0");
  req(init_mono_max_gyro_bias > 0 && std::isfinite(init_mono_max_gyro_bias), "init.mono_max_gyro_bias must be > 0");
  req(init_mono_accel_error >= 0 && std::isfinite(init_mono_accel_error), "init.mono_accel_error must be >= 0");
  req(init_mono_min_accel_change >= 0 && init_mono_min_accel_change <= 50, "init.mono_min_accel_change must be in [0, 50] m/s^2");
  req(init_mono_attempt_interval >= 0 && init_mono_attempt_interval <= 10, "init.mono_attempt_interval must be in [0, 10] s");
  req(init_position_sigma > 0 && init_yaw_sigma > 0 && init_tilt_sigma > 0 && init_velocity_sigma > 0 &&
          init_gyro_bias_sigma > 0 && init_accel_bias_sigma > 0,
      "init sigmas must be positive");
  req(extrinsic_rotation_sigma > 0 && extrinsic_translation_sigma > 0, "extrinsic sigmas must be positive");
  req(std::isfinite(time_offset) && std::abs(time_offset) <= 1.0, "time_offset must be in [-1, 1] s");
  req(std::isfinite(time_offset_sigma) && time_offset_sigma > 0 && time_offset_sigma <= 0.1,
      "time_offset_sigma must be in (0, 0.1] s");
}

namespace {

struct Ctx {
  std::string file;
  std::string base;
};

std::int64_t lineOf(const YAML::Node& n) {
  const YAML::Mark m = n.Mark();
  return m.is_null() ? 0 : m.line + 1;
}

[[noreturn]] void fail(const Ctx& c, std::int64_t line, const std::string& field, const std::string& what) {
  throw ParseError(c.file, line, field, what);
}

double num(const YAML::Node& n, const Ctx& c, const std::string& field) {
  if (!n.IsScalar()) fail(c, lineOf(n), field, "expected a number");
  return parseDouble(n.Scalar(), TextLocation{c.file, lineOf(n)}, field);
}

int integer(const YAML::Node& n, const Ctx& c, const std::string& field) {
  const double v = num(n, c, field);
  if (v != std::floor(v) || std::abs(v) > 1e6) fail(c, lineOf(n), field, "expected an integer");
  return static_cast<int>(v);
}

bool boolean(const YAML::Node& n, const Ctx& c, const std::string& field) {
  if (!n.IsScalar()) fail(c, lineOf(n), field, "expected true or false");
  const std::string& s = n.Scalar();
  if (s == "true" || s == "True" || s == "1" || s == "on") return true;
  if (s == "false" || s == "False" || s == "0" || s == "off") return false;
  fail(c, lineOf(n), field, "expected true or false, found '" + s + "'");
}

std::string str(const YAML::Node& n, const Ctx& c, const std::string& field) {
  if (!n.IsScalar()) fail(c, lineOf(n), field, "expected a string");
  return n.Scalar();
}

std::string resolve(const Ctx& c, const std::string& p) {
  const std::filesystem::path path(p);
  return path.is_absolute() ? p : (std::filesystem::path(c.base) / path).string();
}

using Handler = std::function<void(const YAML::Node&)>;

void walk(const YAML::Node& map, const Ctx& c, const std::string& prefix, const std::map<std::string, Handler>& h) {
  if (!map.IsMap()) fail(c, lineOf(map), prefix, "expected a mapping");
  for (const auto& kv : map) {
    if (!kv.first.IsScalar()) fail(c, lineOf(kv.first), prefix, "keys must be names");
    const std::string key = kv.first.Scalar();
    auto it = h.find(key);
    if (it == h.end()) fail(c, lineOf(kv.first), prefix + key, "unknown key");
    if (kv.second.IsNull()) fail(c, lineOf(kv.first), prefix + key, "missing value");
    it->second(kv.second);
  }
}

SriSwfConfig parseRoot(const YAML::Node& root, const Ctx& c, const SriSwfConfig* defaults) {
  SriSwfConfig cfg = defaults ? *defaults : SriSwfConfig{};
  bool have_cams = false;
  auto d = [&](double& x, const std::string& f) { return [&x, &c, f](const YAML::Node& n) { x = num(n, c, f); }; };
  auto i = [&](int& x, const std::string& f) { return [&x, &c, f](const YAML::Node& n) { x = integer(n, c, f); }; };
  auto b = [&](bool& x, const std::string& f) { return [&x, &c, f](const YAML::Node& n) { x = boolean(n, c, f); }; };
  std::map<std::string, Handler> init = {
      {"window", d(cfg.init_window, "init.window")},
      {"static_max_accel_std", d(cfg.static_max_accel_std, "init.static_max_accel_std")},
      {"static_max_gyro_std", d(cfg.static_max_gyro_std, "init.static_max_gyro_std")},
      {"static_max_parallax", d(cfg.static_max_parallax, "init.static_max_parallax")},
      {"static_without_tracks", b(cfg.init_static_without_tracks, "init.static_without_tracks")},
      {"in_motion", b(cfg.init_in_motion, "init.in_motion")},
      {"motion_frames", i(cfg.init_motion_frames, "init.motion_frames")},
      {"mono_in_motion", b(cfg.init_mono_in_motion, "init.mono_in_motion")},
      {"mono_motion_frames", i(cfg.init_mono_motion_frames, "init.mono_motion_frames")},
      {"mono_max_scale_sigma", d(cfg.init_mono_max_scale_sigma, "init.mono_max_scale_sigma")},
      {"mono_gyro_bias", b(cfg.init_mono_gyro_bias, "init.mono_gyro_bias")},
      {"mono_max_gyro_bias", d(cfg.init_mono_max_gyro_bias, "init.mono_max_gyro_bias")},
      {"mono_accel_error", d(cfg.init_mono_accel_error, "init.mono_accel_error")},
      {"mono_min_accel_change", d(cfg.init_mono_min_accel_change, "init.mono_min_accel_change")},
      {"mono_attempt_interval", d(cfg.init_mono_attempt_interval, "init.mono_attempt_interval")},
      {"position_sigma", d(cfg.init_position_sigma, "init.position_sigma")},
      {"yaw_sigma", d(cfg.init_yaw_sigma, "init.yaw_sigma")},
      {"tilt_sigma", d(cfg.init_tilt_sigma, "init.tilt_sigma")},
      {"velocity_sigma", d(cfg.init_velocity_sigma, "init.velocity_sigma")},
      {"gyro_bias_sigma", d(cfg.init_gyro_bias_sigma, "init.gyro_bias_sigma")},
      {"accel_bias_sigma", d(cfg.init_accel_bias_sigma, "init.accel_bias_sigma")},
  };
  std::map<std::string, Handler> imu = {
      {"gyroscope_noise_density", d(cfg.imu.gyroscope_noise_density, "imu.gyroscope_noise_density")},
      {"gyroscope_random_walk", d(cfg.imu.gyroscope_random_walk, "imu.gyroscope_random_walk")},
      {"accelerometer_noise_density", d(cfg.imu.accelerometer_noise_density, "imu.accelerometer_noise_density")},
      {"accelerometer_random_walk", d(cfg.imu.accelerometer_random_walk, "imu.accelerometer_random_walk")},
      {"rate_hz", d(cfg.imu.rate_hz, "imu.rate_hz")},
  };
  std::map<std::string, Handler> top = {
      {"gravity", d(cfg.gravity, "gravity")},
      {"pixel_noise", d(cfg.pixel_noise, "pixel_noise")},
      {"surface_noise", d(cfg.surface_noise, "surface_noise")},
      {"window", i(cfg.window, "window")},
      {"max_slam_features", i(cfg.max_slam_features, "max_slam_features")},
      {"min_track_msckf", i(cfg.min_track_msckf, "min_track_msckf")},
      {"min_depth", d(cfg.min_depth, "min_depth")},
      {"max_depth", d(cfg.max_depth, "max_depth")},
      {"min_baseline_ratio", d(cfg.min_baseline_ratio, "min_baseline_ratio")},
      {"chi2_probability", d(cfg.chi2_probability, "chi2_probability")},
      {"max_msckf_per_frame", i(cfg.max_msckf_per_frame, "max_msckf_per_frame")},
      {"reanchor_sigma", d(cfg.reanchor_sigma, "reanchor_sigma")},
      {"lockout_reset_s", d(cfg.lockout_reset_s, "lockout_reset_s")},
      {"position_random_walk", d(cfg.position_random_walk, "position_random_walk")},
      {"attitude_random_walk", d(cfg.attitude_random_walk, "attitude_random_walk")},
      {"zero_velocity_update", b(cfg.zero_velocity_update, "zero_velocity_update")},
      {"zero_velocity_sigma", d(cfg.zero_velocity_sigma, "zero_velocity_sigma")},
      {"first_estimate_jacobians", b(cfg.first_estimate_jacobians, "first_estimate_jacobians")},
      {"first_estimate_delay", d(cfg.first_estimate_delay, "first_estimate_delay")},
      {"calibrate_extrinsics", b(cfg.calibrate_extrinsics, "calibrate_extrinsics")},
      {"extrinsic_rotation_sigma", d(cfg.extrinsic_rotation_sigma, "extrinsic_rotation_sigma")},
      {"extrinsic_translation_sigma", d(cfg.extrinsic_translation_sigma, "extrinsic_translation_sigma")},
      {"time_offset", d(cfg.time_offset, "time_offset")},
      {"calibrate_time_offset", b(cfg.calibrate_time_offset, "calibrate_time_offset")},
      {"time_offset_sigma", d(cfg.time_offset_sigma, "time_offset_sigma")},
      {"float_householder", b(cfg.float_householder, "float_householder")},
      {"imu_extra_first", b(cfg.imu_extra_first, "imu_extra_first")},
      {"imu_bias_renewal", d(cfg.imu_bias_renewal, "imu_bias_renewal")},
      {"precision",
       [&](const YAML::Node& n) {
         const std::string s = str(n, c, "precision");
         if (s == "double") {
           cfg.use_float = false;
         } else if (s == "float") {
           cfg.use_float = true;
         } else {
           fail(c, lineOf(n), "precision", "expected double or float, found '" + s + "'");
         }
       }},
      {"init", [&](const YAML::Node& n) { walk(n, c, "init.", init); }},
      {"imu", [&](const YAML::Node& n) { walk(n, c, "imu.", imu); }},
      {"imu_yaml",
       [&](const YAML::Node& n) { cfg.imu = readImuSensorYaml(resolve(c, str(n, c, "imu_yaml"))).noise; }},
      {"cameras",
       [&](const YAML::Node& n) {
         if (!n.IsSequence() || n.size() < 1 || n.size() > 2) {
           fail(c, lineOf(n), "cameras", "expected a list of 1 or 2 camera sensor.yaml paths");
         }
         cfg.cameras.clear();
         for (std::size_t k = 0; k < n.size(); ++k) {
           cfg.cameras.push_back(readCameraSensorYaml(resolve(c, str(n[k], c, "cameras"))));
         }
         have_cams = true;
       }},
      {"camchain",
       [&](const YAML::Node& n) {
         cfg.cameras = readKalibrCamchain(resolve(c, str(n, c, "camchain")));
         if (cfg.cameras.empty() || cfg.cameras.size() > 2) {
           fail(c, lineOf(n), "camchain", "expected 1 or 2 cameras in the camchain");
         }
         have_cams = true;
       }},
  };
  walk(root, c, "", top);
  // A Kalibr camchain's timeshift_cam_imu is the time offset unless `time_offset` is given.
  if (have_cams && !root["time_offset"]) cfg.time_offset = cfg.cameras.front().time_offset;
  // Defaults without cameras are a camera-less rig (IMU-only dataset); a file read alone must name them.
  if (!have_cams && cfg.cameras.empty() && defaults == nullptr)
    fail(c, lineOf(root), "cameras", "missing (cameras: [...] or camchain: ...)");
  try {
    cfg.validate();
  } catch (const std::invalid_argument& e) {
    fail(c, lineOf(root), "", e.what());
  }
  return cfg;
}

}  // namespace

SriSwfConfig parseSriSwfConfig(std::string_view text, const std::string& name, const std::string& base_dir,
                               const SriSwfConfig* defaults) {
  const Ctx c{name, base_dir};
  if (text.size() > (1u << 20)) fail(c, 0, "", "file larger than 1 MiB");
  for (const char ch : text) {
    if (ch == '\0') fail(c, 0, "", "binary data (NUL byte) in a YAML file");
  }
  try {
    const YAML::Node root = YamlReader::loadText(std::string(text), name);
    if (!root.IsMap()) fail(c, lineOf(root), "", "expected a YAML mapping at the top level");
    return parseRoot(root, c, defaults);
  } catch (const YAML::Exception& e) {
    fail(c, e.mark.is_null() ? 0 : e.mark.line + 1, "YAML", e.msg);
  }
}

SriSwfConfig loadSriSwfConfig(const std::string& path, const SriSwfConfig* defaults) {
  const std::string text = YamlReader::readFile(path);
  const std::string dir = std::filesystem::path(path).parent_path().string();
  return parseSriSwfConfig(text, path, dir.empty() ? "." : dir, defaults);
}

}  // namespace gvins::vio
