#include "gvins/sim/scenario.hpp"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <set>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "gvins/base/parse_error.hpp"
#include "gvins/base/yaml_reader.hpp"
#include "gvins/base/text_fields.hpp"

// Where the installed data (data/gnss/...) lies relative to the folder of the running executable:
// <prefix>/bin/../share/sri_gvins; the build tree has the same layout (cmake/GvinsInstall.cmake).
#ifndef GVINS_SIM_DATA_FROM_BIN
#define GVINS_SIM_DATA_FROM_BIN "../share/sri_gvins"
#endif

namespace gvins::sim {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr std::size_t kMaxScenarioBytes = 1 << 20;

Eigen::Matrix3d rotZ(double a) {
  Eigen::Matrix3d m;
  m << std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a), 0, 0, 0, 1;
  return m;
}
Eigen::Matrix3d rotY(double a) {
  Eigen::Matrix3d m;
  m << std::cos(a), 0, std::sin(a), 0, 1, 0, -std::sin(a), 0, std::cos(a);
  return m;
}
Eigen::Matrix3d rotX(double a) {
  Eigen::Matrix3d m;
  m << 1, 0, 0, 0, std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a);
  return m;
}

/// Strict, located access to a YAML tree: every error names file, line and dotted key.
class Reader {
 public:
  explicit Reader(std::string file) : file_(std::move(file)) {}
  const std::string& file() const { return file_; }

  static std::int64_t lineOf(const YAML::Node& n) {
    const YAML::Mark m = n.Mark();
    return m.is_null() || m.line < 0 ? 0 : m.line + 1;
  }
  [[noreturn]] void fail(const YAML::Node& n, const std::string& key, const std::string& what) const {
    throw ParseError(file_, lineOf(n), key, what);
  }
  /// Requires a map whose keys are all in `allowed`.
  void map(const YAML::Node& n, const std::string& key, std::initializer_list<const char*> allowed) const {
    if (!n.IsMap()) fail(n, key, "expected a map of keys");
    std::set<std::string> ok(allowed.begin(), allowed.end());
    for (const auto& kv : n) {
      if (!kv.first.IsScalar()) fail(kv.first, key, "keys must be plain names");
      const std::string k = kv.first.Scalar();
      if (!ok.count(k)) fail(kv.first, join(key, k), "unknown key '" + k + "'");
    }
  }
  static std::string join(const std::string& a, const std::string& b) { return a.empty() ? b : a + "." + b; }

  double number(const YAML::Node& n, const std::string& key, double lo, double hi) const {
    if (!n.IsScalar()) fail(n, key, "expected a number");
    const double v = parseDouble(n.Scalar(), TextLocation{file_, lineOf(n)}, key);
    if (!(v >= lo && v <= hi)) {
      std::ostringstream s;
      s << "value " << v << " outside [" << lo << ", " << hi << "]";
      fail(n, key, s.str());
    }
    return v;
  }
  int integer(const YAML::Node& n, const std::string& key, long lo, long hi) const {
    if (!n.IsScalar()) fail(n, key, "expected an integer");
    const long v = parseInt(n.Scalar(), TextLocation{file_, lineOf(n)}, key);
    if (v < lo || v > hi) fail(n, key, "value " + std::to_string(v) + " outside [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    return static_cast<int>(v);
  }
  std::uint64_t unsigned64(const YAML::Node& n, const std::string& key) const {
    if (!n.IsScalar()) fail(n, key, "expected a non-negative integer");
    const std::string& s = n.Scalar();
    if (s.empty() || s.size() > 20 || s.find_first_not_of("0123456789") != std::string::npos)
      fail(n, key, "expected a non-negative integer, found '" + s + "'");
    try {
      return std::stoull(s);
    } catch (const std::exception&) {
      fail(n, key, "integer out of range");
    }
  }
  bool boolean(const YAML::Node& n, const std::string& key) const {
    if (!n.IsScalar()) fail(n, key, "expected true or false");
    const std::string& s = n.Scalar();
    if (s == "true" || s == "yes" || s == "on") return true;
    if (s == "false" || s == "no" || s == "off") return false;
    fail(n, key, "expected true or false, found '" + s + "'");
  }
  std::string string(const YAML::Node& n, const std::string& key, std::size_t maxLen = 4096) const {
    if (!n.IsScalar()) fail(n, key, "expected a string");
    if (n.Scalar().size() > maxLen) fail(n, key, "string too long");
    return n.Scalar();
  }
  std::vector<double> numbers(const YAML::Node& n, const std::string& key, std::size_t count, double lo, double hi) const {
    if (!n.IsSequence()) fail(n, key, "expected a list of " + std::to_string(count) + " numbers");
    if (n.size() != count) fail(n, key, "expected " + std::to_string(count) + " numbers, found " + std::to_string(n.size()));
    std::vector<double> v;
    for (std::size_t i = 0; i < count; ++i) v.push_back(number(n[i], key, lo, hi));
    return v;
  }
  Eigen::Vector3d vec3(const YAML::Node& n, const std::string& key, double lo, double hi) const {
    const auto v = numbers(n, key, 3, lo, hi);
    return {v[0], v[1], v[2]};
  }
  std::string path(const YAML::Node& n, const std::string& key) const {
    const std::string p = string(n, key);
    if (p.empty()) fail(n, key, "empty path");
    std::filesystem::path fp(p);
    if (fp.is_relative() && !file_.empty()) fp = std::filesystem::path(file_).parent_path() / fp;
    return fp.lexically_normal().string();
  }

 private:
  std::string file_;
};

void parseFlight(const Reader& r, const YAML::Node& n, Scenario& sc) {
  const std::string k = "trajectory";
  FlightSpec& f = sc.flight;
  for (const auto& kv : n) {
    const std::string name = kv.first.Scalar();
    const YAML::Node& v = kv.second;
    const std::string key = Reader::join(k, name);
    if (name == "type") continue;
    if (name == "pattern") {
      if (!flightPatternFromString(r.string(v, key), f.pattern))
        r.fail(v, key, "expected lawnmower, circle, figure_eight, waypoints, drive or walk");
    } else if (name == "height_m") f.height = r.number(v, key, 0.5, 10000.0);
    else if (name == "length_m") f.length = r.number(v, key, 1.0, 1e6);
    else if (name == "speed_mps") f.speed = r.number(v, key, 0.1, 100.0);
    else if (name == "climb_rate_mps") f.climbRate = r.number(v, key, 0.1, 20.0);
    else if (name == "heading_deg") f.headingDeg = r.number(v, key, -360.0, 360.0);
    else if (name == "rows") f.rows = r.integer(v, key, 1, 1000);
    else if (name == "row_spacing_m") f.rowSpacing = r.number(v, key, 0.5, 10000.0);
    else if (name == "turn") {
      const std::string t = r.string(v, key);
      if (t != "left" && t != "right") r.fail(v, key, "expected left or right");
      f.turnRight = t == "right";
    } else if (name == "laps") f.laps = r.integer(v, key, 1, 1000);
    else if (name == "waypoints_m") {
      if (!v.IsSequence() || v.size() == 0 || v.size() > 10000) r.fail(v, key, "expected a list of [x, y, z] points");
      f.waypoints.clear();
      for (std::size_t i = 0; i < v.size(); ++i) f.waypoints.push_back(r.vec3(v[i], key, -1e6, 1e6));
    } else if (name == "corner_radius_m") f.cornerRadius = r.number(v, key, 0.5, 1000.0);
    else if (name == "stop_s") f.stopSeconds = r.number(v, key, 0.0, 3600.0);
    else if (name == "corner_stop_s") f.cornerStopSeconds = r.number(v, key, 0.0, 3600.0);
    else if (name == "gait_step_m") f.gait.stepLength = r.number(v, key, 0.2, 2.0);
    else if (name == "gait_bob_m") f.gait.bob = r.number(v, key, 0.0, 0.2);
    else if (name == "gait_sway_m") f.gait.sway = r.number(v, key, 0.0, 0.2);
    else if (name == "gait_tilt_deg") f.gait.tiltDeg = r.number(v, key, 0.0, 20.0);
    else if (name == "rest_height_m") f.restHeight = r.number(v, key, 0.0, 100.0);
    else if (name == "takeoff_landing") f.takeoffLanding = r.boolean(v, key);
    else if (name == "hover_start_s") f.hoverStart = r.number(v, key, 2.0, 3600.0);
    else if (name == "hover_end_s") f.hoverEnd = r.number(v, key, 2.0, 3600.0);
    else if (name == "lateral_accel_mps2") f.limits.lateralAccel = r.number(v, key, 0.1, 50.0);
    else if (name == "longitudinal_accel_mps2") f.limits.longitudinalAccel = r.number(v, key, 0.1, 50.0);
    else if (name == "yaw") {
      const std::string y = r.string(v, key);
      if (y != "follow_path" && y != "fixed") r.fail(v, key, "expected follow_path or fixed");
      f.yaw = y == "fixed" ? YawMode::Fixed : YawMode::FollowPath;
    } else if (name == "yaw_deg") f.fixedYawDeg = r.number(v, key, -360.0, 360.0);
    else if (name == "knot_interval_s") f.knotInterval = r.number(v, key, 0.01, 5.0);
    else if (name == "yaw_knot_interval_s") f.yawKnotInterval = r.number(v, key, 0.01, 10.0);
    else if (name == "wobble_deg") f.wobbleDeg = r.number(v, key, 0.0, 10.0);
    else if (name == "wobble_interval_s") f.wobbleInterval = r.number(v, key, 0.05, 10.0);
    else if (name == "vehicle_roll_per_mps2") f.vehicleAttitude.rollPerLateralAccel = r.number(v, key, 0.0, 0.2);
    else if (name == "vehicle_pitch_per_mps2") f.vehicleAttitude.pitchPerLongitudinalAccel = r.number(v, key, 0.0, 0.2);
    else r.fail(kv.first, key, "unknown key '" + name + "' for a flight trajectory");
  }
  try {
    f.validate();
  } catch (const std::invalid_argument& e) {
    r.fail(n, k, e.what());
  }
}

void parseRecorded(const Reader& r, const YAML::Node& n, Scenario& sc) {
  r.map(n, "trajectory", {"type", "imu_csv", "groundtruth_csv", "start_offset_s", "duration_s", "knot_interval_s", "smoothing"});
  RecordedTrajectoryConfig& c = sc.recorded;
  if (!n["imu_csv"] || !n["groundtruth_csv"])
    r.fail(n, "trajectory", "a recorded trajectory needs imu_csv and groundtruth_csv");
  c.imuCsv = r.path(n["imu_csv"], "trajectory.imu_csv");
  c.groundTruthCsv = r.path(n["groundtruth_csv"], "trajectory.groundtruth_csv");
  if (n["start_offset_s"]) c.startOffset = r.number(n["start_offset_s"], "trajectory.start_offset_s", 0.0, 1e6);
  if (n["duration_s"]) c.duration = r.number(n["duration_s"], "trajectory.duration_s", 0.0, 1e6);
  if (n["knot_interval_s"]) c.knotInterval = r.number(n["knot_interval_s"], "trajectory.knot_interval_s", 0.005, 1.0);
  if (n["smoothing"]) c.smoothing = r.number(n["smoothing"], "trajectory.smoothing", 0.0, 1e9);
}

void parseTrack(const Reader& r, const YAML::Node& n, Scenario& sc) {
  r.map(n, "trajectory", {"type", "pos_file", "imu_csv", "max_quality", "duration_s", "attitude_window_s",
                          "gyro_bias_interval_s", "knot_interval_s", "accel_sigma_mps2", "track_sigma_floor_m",
                          "smoothing", "rover_log", "navigation_file"});
  TrackTrajectoryConfig& c = sc.track;
  if (!n["pos_file"] || !n["imu_csv"]) r.fail(n, "trajectory", "a gnss_track trajectory needs pos_file and imu_csv");
  c.posFile = r.path(n["pos_file"], "trajectory.pos_file");
  c.imuCsv = r.path(n["imu_csv"], "trajectory.imu_csv");
  if (n["max_quality"]) c.maxQuality = static_cast<int>(r.number(n["max_quality"], "trajectory.max_quality", 1.0, 6.0));
  if (n["duration_s"]) c.duration = r.number(n["duration_s"], "trajectory.duration_s", 0.0, 1e6);
  if (n["attitude_window_s"]) c.attitudeWindow = r.number(n["attitude_window_s"], "trajectory.attitude_window_s", 0.1, 10.0);
  if (n["gyro_bias_interval_s"])
    c.gyroBiasInterval = r.number(n["gyro_bias_interval_s"], "trajectory.gyro_bias_interval_s", 0.0, 1e6);
  if (n["knot_interval_s"]) c.knotInterval = r.number(n["knot_interval_s"], "trajectory.knot_interval_s", 0.005, 1.0);
  if (n["accel_sigma_mps2"]) c.accelSigma = r.number(n["accel_sigma_mps2"], "trajectory.accel_sigma_mps2", 1e-3, 100.0);
  if (n["track_sigma_floor_m"])
    c.trackSigmaFloor = r.number(n["track_sigma_floor_m"], "trajectory.track_sigma_floor_m", 1e-4, 100.0);
  if (n["smoothing"]) c.smoothing = r.number(n["smoothing"], "trajectory.smoothing", 0.0, 1e9);
  if (n["rover_log"]) c.roverLog = r.path(n["rover_log"], "trajectory.rover_log");
  if (n["navigation_file"]) c.navigationFile = r.path(n["navigation_file"], "trajectory.navigation_file");
}

void parseImu(const Reader& r, const YAML::Node& n, Scenario& sc) {
  r.map(n, "imu", {"rate_hz", "gyroscope_noise_density", "gyroscope_random_walk", "accelerometer_noise_density",
                   "accelerometer_random_walk", "white_noise", "bias_random_walk", "gyro_bias_radps", "accel_bias_mps2",
                   "gyro_bias_sigma_radps", "accel_bias_sigma_mps2", "earth", "gravity_mps2"});
  ImuSimConfig& c = sc.imu;
  auto num = [&](const char* k, double lo, double hi, double& out) {
    if (n[k]) out = r.number(n[k], std::string("imu.") + k, lo, hi);
  };
  num("rate_hz", 10.0, 2000.0, c.rateHz);
  num("gyroscope_noise_density", 0.0, 1.0, c.noise.gyroscope_noise_density);
  num("gyroscope_random_walk", 0.0, 1.0, c.noise.gyroscope_random_walk);
  num("accelerometer_noise_density", 0.0, 10.0, c.noise.accelerometer_noise_density);
  num("accelerometer_random_walk", 0.0, 10.0, c.noise.accelerometer_random_walk);
  num("gyro_bias_sigma_radps", 0.0, 1.0, c.gyroBiasSigma);
  num("accel_bias_sigma_mps2", 0.0, 10.0, c.accelBiasSigma);
  if (n["white_noise"]) c.whiteNoise = r.boolean(n["white_noise"], "imu.white_noise");
  if (n["bias_random_walk"]) c.biasRandomWalk = r.boolean(n["bias_random_walk"], "imu.bias_random_walk");
  if (n["gyro_bias_radps"]) c.gyroBias = r.vec3(n["gyro_bias_radps"], "imu.gyro_bias_radps", -10.0, 10.0);
  if (n["accel_bias_mps2"]) c.accelBias = r.vec3(n["accel_bias_mps2"], "imu.accel_bias_mps2", -50.0, 50.0);
  if (n["earth"]) {
    const std::string e = r.string(n["earth"], "imu.earth");
    if (e != "flat" && e != "rotating") r.fail(n["earth"], "imu.earth", "expected flat or rotating");
    c.earth = e == "rotating" ? EarthModel::Rotating : EarthModel::Flat;
  }
  if (n["gravity_mps2"]) {
    const YAML::Node g = n["gravity_mps2"];
    if (g.IsScalar() && g.Scalar() == "normal")
      c.gravity = 0.0;
    else
      c.gravity = r.number(g, "imu.gravity_mps2", 1.0, 30.0);
  }
}

vio::CameraCalibration parseCamera(const Reader& r, const YAML::Node& n, const std::string& key, int index) {
  r.map(n, key, {"name", "resolution", "intrinsics", "distortion_model", "distortion_coefficients", "look",
                 "position_m", "mount_rpy_deg", "T_BS"});
  vio::CameraCalibration c = downwardCamera("cam" + std::to_string(index), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                                            index == 1);
  if (n["name"]) {
    c.name = r.string(n["name"], key + ".name", 64);
    if (c.name != "cam" + std::to_string(index)) r.fail(n["name"], key + ".name", "cameras are named cam0, cam1 in order");
  }
  if (n["resolution"]) {
    const auto v = r.numbers(n["resolution"], key + ".resolution", 2, 8, 8192);
    if (v[0] != std::floor(v[0]) || v[1] != std::floor(v[1])) r.fail(n["resolution"], key + ".resolution", "expected integers");
    c.intrinsics.width = static_cast<int>(v[0]);
    c.intrinsics.height = static_cast<int>(v[1]);
  }
  if (n["intrinsics"]) {
    const auto v = r.numbers(n["intrinsics"], key + ".intrinsics", 4, -1e5, 1e5);
    if (!(v[0] > 0.0) || !(v[1] > 0.0)) r.fail(n["intrinsics"], key + ".intrinsics", "focal lengths must be positive");
    c.intrinsics.fx = v[0];
    c.intrinsics.fy = v[1];
    c.intrinsics.cx = v[2];
    c.intrinsics.cy = v[3];
  }
  if (n["distortion_model"]) {
    const std::string m = r.string(n["distortion_model"], key + ".distortion_model");
    if (m == "radtan" || m == "radial-tangential" || m == "plumb_bob")
      c.intrinsics.model = vio::DistortionModel::RadialTangential;
    else if (m == "equidistant" || m == "fisheye")
      c.intrinsics.model = vio::DistortionModel::Equidistant;
    else if (m == "none")
      c.intrinsics.model = vio::DistortionModel::None;
    else
      r.fail(n["distortion_model"], key + ".distortion_model", "expected radtan, equidistant or none");
  }
  if (n["distortion_coefficients"]) {
    const auto v = r.numbers(n["distortion_coefficients"], key + ".distortion_coefficients", 4, -10.0, 10.0);
    for (int i = 0; i < 4; ++i) c.intrinsics.distortion[static_cast<std::size_t>(i)] = v[static_cast<std::size_t>(i)];
  }
  if (n["T_BS"]) {
    if (n["look"] || n["position_m"] || n["mount_rpy_deg"])
      r.fail(n["T_BS"], key + ".T_BS", "give either T_BS or look/position_m/mount_rpy_deg");
    const auto v = r.numbers(n["T_BS"], key + ".T_BS", 16, -1e3, 1e3);
    Eigen::Matrix4d T;
    for (int i = 0; i < 16; ++i) T(i / 4, i % 4) = v[static_cast<std::size_t>(i)];
    const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
    if ((R.transpose() * R - Eigen::Matrix3d::Identity()).norm() > 1e-6 || R.determinant() < 0.0 ||
        T.row(3) != Eigen::RowVector4d(0, 0, 0, 1))
      r.fail(n["T_BS"], key + ".T_BS", "not a rigid transform (orthonormal rotation, last row 0 0 0 1)");
    c.T_BS = T;
  } else {
    bool down = true;
    if (n["look"]) {
      const std::string l = r.string(n["look"], key + ".look");
      if (l != "down" && l != "forward") r.fail(n["look"], key + ".look", "expected down or forward");
      down = l == "down";
    }
    Eigen::Vector3d pos = c.T_BS.topRightCorner<3, 1>(), rpy = Eigen::Vector3d::Zero();
    if (n["position_m"]) pos = r.vec3(n["position_m"], key + ".position_m", -100.0, 100.0);
    if (n["mount_rpy_deg"]) rpy = r.vec3(n["mount_rpy_deg"], key + ".mount_rpy_deg", -180.0, 180.0);
    c.T_BS.setIdentity();
    c.T_BS.topLeftCorner<3, 3>() = cameraMountRotation(down, rpy);
    c.T_BS.topRightCorner<3, 1>() = pos;
  }
  try {
    vio::CameraModel check(c.intrinsics);
  } catch (const std::invalid_argument& e) {
    r.fail(n, key, e.what());
  }
  return c;
}

void parseCameras(const Reader& r, const YAML::Node& n, Scenario& sc) {
  r.map(n, "cameras", {"rate_hz", "time_offset_s", "output", "png_compression", "imaging", "features", "list"});
  if (n["rate_hz"]) sc.cameraRate = r.number(n["rate_hz"], "cameras.rate_hz", 0.1, 1000.0);
  if (n["time_offset_s"]) sc.cameraTimeOffset = r.number(n["time_offset_s"], "cameras.time_offset_s", -0.5, 0.5);
  if (n["output"]) {
    const std::string o = r.string(n["output"], "cameras.output");
    if (o != "images" && o != "features") r.fail(n["output"], "cameras.output", "expected images or features");
    sc.output = o == "features" ? CameraOutput::Features : CameraOutput::Images;
  }
  if (n["png_compression"]) sc.pngCompression = r.integer(n["png_compression"], "cameras.png_compression", 0, 9);
  if (const YAML::Node im = n["imaging"]) {
    r.map(im, "cameras.imaging", {"exposure_s", "line_time_s", "motion_blur", "max_blur_samples", "blur_step_px",
                                   "psf_sigma_px", "vignetting", "gain_sigma", "gain_correlation", "read_noise_dn",
                                   "shot_noise_dn", "sky_dn", "max_range_m", "noise"});
    ImagingConfig& c = sc.imaging;
    const std::string p = "cameras.imaging.";
    if (im["exposure_s"]) c.exposure = r.number(im["exposure_s"], p + "exposure_s", 0.0, 1.0);
    if (im["line_time_s"]) c.lineTime = r.number(im["line_time_s"], p + "line_time_s", 0.0, 1e-3);
    if (im["motion_blur"]) c.motionBlur = r.boolean(im["motion_blur"], p + "motion_blur");
    if (im["max_blur_samples"]) c.maxBlurSamples = r.integer(im["max_blur_samples"], p + "max_blur_samples", 1, 64);
    if (im["blur_step_px"]) c.blurStepPx = r.number(im["blur_step_px"], p + "blur_step_px", 0.02, 100.0);
    if (im["psf_sigma_px"]) c.opticalBlurSigma = r.number(im["psf_sigma_px"], p + "psf_sigma_px", 0.0, 10.0);
    if (im["vignetting"]) c.vignetting = r.number(im["vignetting"], p + "vignetting", 0.0, 1.0);
    if (im["gain_sigma"]) c.gainSigma = r.number(im["gain_sigma"], p + "gain_sigma", 0.0, 1.0);
    if (im["gain_correlation"]) c.gainCorrelation = r.number(im["gain_correlation"], p + "gain_correlation", 0.0, 1.0);
    if (im["read_noise_dn"]) c.readNoise = r.number(im["read_noise_dn"], p + "read_noise_dn", 0.0, 100.0);
    if (im["shot_noise_dn"]) c.shotNoise = r.number(im["shot_noise_dn"], p + "shot_noise_dn", 0.0, 10.0);
    if (im["sky_dn"]) c.sky = r.number(im["sky_dn"], p + "sky_dn", 0.0, 255.0);
    if (im["max_range_m"]) c.maxRange = r.number(im["max_range_m"], p + "max_range_m", 1.0, 1e5);
    if (im["noise"]) c.noise = r.boolean(im["noise"], p + "noise");
  }
  if (const YAML::Node f = n["features"]) {
    r.map(f, "cameras.features", {"max_per_image", "landmarks_per_image", "density_per_m2", "height_sigma_m",
                                   "pixel_noise_px", "outlier_rate", "outlier_offset_px", "border_px", "max_range_m"});
    FeatureSimConfig& c = sc.features;
    const std::string p = "cameras.features.";
    if (f["max_per_image"]) c.maxPerImage = r.integer(f["max_per_image"], p + "max_per_image", 1, 100000);
    if (f["landmarks_per_image"]) c.landmarksPerImage = r.number(f["landmarks_per_image"], p + "landmarks_per_image", 1.0, 1e6);
    if (f["density_per_m2"]) c.densityPerM2 = r.number(f["density_per_m2"], p + "density_per_m2", 0.0, 1000.0);
    if (f["height_sigma_m"]) c.heightSigma = r.number(f["height_sigma_m"], p + "height_sigma_m", 0.0, 1000.0);
    if (f["pixel_noise_px"]) c.pixelNoise = r.number(f["pixel_noise_px"], p + "pixel_noise_px", 0.0, 100.0);
    if (f["outlier_rate"]) c.outlierRate = r.number(f["outlier_rate"], p + "outlier_rate", 0.0, 1.0);
    if (f["outlier_offset_px"]) c.outlierOffset = r.number(f["outlier_offset_px"], p + "outlier_offset_px", 0.0, 1000.0);
    if (f["border_px"]) c.border = r.number(f["border_px"], p + "border_px", 0.0, 100.0);
    if (f["max_range_m"]) c.maxRange = r.number(f["max_range_m"], p + "max_range_m", 1.0, 1e5);
  }
  if (const YAML::Node l = n["list"]) {
    if (!l.IsSequence() || l.size() > 2) r.fail(l, "cameras.list", "expected a list of one or two cameras (or empty)");
    sc.cameras.clear();
    for (std::size_t i = 0; i < l.size(); ++i)
      sc.cameras.push_back(parseCamera(r, l[i], "cameras.list[" + std::to_string(i) + "]", static_cast<int>(i)));
  }
}

void parseStructure(const Reader& r, const YAML::Node& n, Scenario& sc) {
  r.map(n, "scene.structure", {"street_half_width_m", "building_length_m", "building_depth_m", "building_height_m",
                               "gap_m", "facade_density_per_m2", "ground_density_per_m2", "relief_m", "pole_spacing_m",
                               "tile_m"});
  UrbanConfig c;
  const std::string p = "scene.structure.";
  auto interval = [&](const char* name, double lo, double hi, double& a, double& b) {
    if (!n[name]) return;
    const auto v = r.numbers(n[name], p + name, 2, lo, hi);
    if (v[1] < v[0]) r.fail(n[name], p + name, "expected [min, max] with min <= max");
    a = v[0];
    b = v[1];
  };
  if (n["street_half_width_m"]) c.streetHalfWidth = r.number(n["street_half_width_m"], p + "street_half_width_m", 3.0, 200.0);
  interval("building_length_m", 2.0, 1000.0, c.buildingLengthMin, c.buildingLengthMax);
  interval("building_depth_m", 2.0, 1000.0, c.buildingDepthMin, c.buildingDepthMax);
  interval("building_height_m", 1.0, 1000.0, c.buildingHeightMin, c.buildingHeightMax);
  interval("gap_m", 0.0, 1000.0, c.gapMin, c.gapMax);
  if (n["facade_density_per_m2"]) c.facadeDensity = r.number(n["facade_density_per_m2"], p + "facade_density_per_m2", 0.0, 10.0);
  if (n["ground_density_per_m2"]) c.groundDensity = r.number(n["ground_density_per_m2"], p + "ground_density_per_m2", 0.0, 10.0);
  if (n["relief_m"]) c.relief = r.number(n["relief_m"], p + "relief_m", 0.0, 100.0);
  if (n["pole_spacing_m"]) {
    c.poleSpacing = r.number(n["pole_spacing_m"], p + "pole_spacing_m", 0.0, 10000.0);
    if (c.poleSpacing > 0.0 && c.poleSpacing < 2.0) r.fail(n["pole_spacing_m"], p + "pole_spacing_m", "expected 0 (none) or >= 2 m");
  }
  if (n["tile_m"]) c.tileSize = r.number(n["tile_m"], p + "tile_m", 5.0, 1000.0);
  try {
    c.validate();
  } catch (const std::invalid_argument& e) {
    r.fail(n, "scene.structure", e.what());
  }
  sc.structure = c;
}

void parseScene(const Reader& r, const YAML::Node& n, Scenario& sc) {
  r.map(n, "scene", {"texture", "checkerboard", "structure"});
  if (const YAML::Node u = n["structure"]) parseStructure(r, u, sc);
  if (const YAML::Node t = n["texture"]) {
    r.map(t, "scene.texture", {"texel_m", "levels", "finest_feature_m", "octaves", "mean_dn", "amplitude_dn", "cache_mb"});
    GroundTextureConfig& c = sc.texture;
    const std::string p = "scene.texture.";
    if (t["texel_m"]) c.texelSize = r.number(t["texel_m"], p + "texel_m", 1e-4, 100.0);
    if (t["levels"]) c.levels = r.integer(t["levels"], p + "levels", 1, 24);
    if (t["finest_feature_m"]) c.finestFeature = r.number(t["finest_feature_m"], p + "finest_feature_m", 1e-4, 1000.0);
    if (t["octaves"]) c.octaves = r.integer(t["octaves"], p + "octaves", 1, 24);
    if (t["mean_dn"]) c.mean = r.number(t["mean_dn"], p + "mean_dn", 0.0, 255.0);
    if (t["amplitude_dn"]) c.amplitude = r.number(t["amplitude_dn"], p + "amplitude_dn", 0.0, 255.0);
    if (t["cache_mb"]) c.cacheBytes = static_cast<std::size_t>(r.integer(t["cache_mb"], p + "cache_mb", 16, 65536)) << 20;
  }
  if (const YAML::Node b = n["checkerboard"]) {
    r.map(b, "scene.checkerboard", {"enabled", "origin_m", "yaw_deg", "inner_corners", "square_m"});
    CheckerboardConfig& c = sc.texture.board;
    const std::string p = "scene.checkerboard.";
    c.enabled = true;
    if (b["enabled"]) c.enabled = r.boolean(b["enabled"], p + "enabled");
    if (b["origin_m"]) {
      const auto v = r.numbers(b["origin_m"], p + "origin_m", 2, -1e6, 1e6);
      c.origin = {v[0], v[1]};
    }
    if (b["yaw_deg"]) c.yawDeg = r.number(b["yaw_deg"], p + "yaw_deg", -360.0, 360.0);
    if (b["inner_corners"]) {
      const auto v = r.numbers(b["inner_corners"], p + "inner_corners", 2, 2, 100);
      c.innerCols = static_cast<int>(v[0]);
      c.innerRows = static_cast<int>(v[1]);
    }
    if (b["square_m"]) c.square = r.number(b["square_m"], p + "square_m", 0.001, 100.0);
  }
}

GpsTime parseStart(const Reader& r, const YAML::Node& n) {
  const std::string s = r.string(n, "start_gpst", 64);
  CalendarTime c;
  char extra = 0;
  int consumed = 0;
  if (std::sscanf(s.c_str(), "%d-%d-%d %d:%d:%lf%n%c", &c.year, &c.month, &c.day, &c.hour, &c.minute, &c.second,
                  &consumed, &extra) < 6 ||
      extra != 0)
    r.fail(n, "start_gpst", "expected \"YYYY-MM-DD HH:MM:SS\" (GPST)");
  if (c.year < 1980 || c.year > 2100 || !isValidCalendar(c) || c.second >= 60.0)
    r.fail(n, "start_gpst", "not a valid date and time between 1980 and 2100");
  if (std::abs(c.second * 1e9 - std::round(c.second * 1e9)) > 1e-3)
    r.fail(n, "start_gpst", "the start must be a whole nanosecond");
  return GpsTime::fromCalendar(c);
}

void parseRoot(const Reader& r, const YAML::Node& root, Scenario& sc) {
  if (!root.IsMap()) r.fail(root, "", "a scenario is a YAML map of sections");
  r.map(root, "", {"name", "description", "seed", "origin", "start_gpst", "trajectory", "imu", "cameras", "scene",
                   "lever_arm_m", "gnss"});
  if (root["name"]) sc.name = r.string(root["name"], "name", 200);
  if (root["description"]) sc.description = r.string(root["description"], "description");
  if (root["seed"]) sc.seed = r.unsigned64(root["seed"], "seed");
  if (const YAML::Node o = root["origin"]) {
    r.map(o, "origin", {"latitude_deg", "longitude_deg", "height_m"});
    const double lat = o["latitude_deg"] ? r.number(o["latitude_deg"], "origin.latitude_deg", -89.9, 89.9)
                                         : sc.frame.origin.lat / kDeg;
    const double lon = o["longitude_deg"] ? r.number(o["longitude_deg"], "origin.longitude_deg", -180.0, 360.0)
                                          : sc.frame.origin.lon / kDeg;
    const double h = o["height_m"] ? r.number(o["height_m"], "origin.height_m", -500.0, 9000.0) : sc.frame.origin.height;
    sc.frame.origin = geodeticFromDegrees(lat, lon, h);
  }
  if (root["start_gpst"]) sc.frame.startTime = parseStart(r, root["start_gpst"]);
  if (const YAML::Node t = root["trajectory"]) {
    if (!t.IsMap()) r.fail(t, "trajectory", "expected a map of keys");
    std::string type = "flight";
    if (t["type"]) type = r.string(t["type"], "trajectory.type");
    if (type == "flight") {
      sc.trajectory = TrajectoryKind::Flight;
      parseFlight(r, t, sc);
    } else if (type == "recorded") {
      sc.trajectory = TrajectoryKind::Recorded;
      parseRecorded(r, t, sc);
    } else if (type == "gnss_track") {
      sc.trajectory = TrajectoryKind::Track;
      parseTrack(r, t, sc);
    } else {
      r.fail(t["type"], "trajectory.type", "expected flight, recorded or gnss_track");
    }
  }
  if (const YAML::Node i = root["imu"]) parseImu(r, i, sc);
  if (const YAML::Node c = root["cameras"]) parseCameras(r, c, sc);
  if (const YAML::Node s = root["scene"]) parseScene(r, s, sc);
  if (root["lever_arm_m"]) sc.leverArm = r.vec3(root["lever_arm_m"], "lever_arm_m", -100.0, 100.0);
  if (root["gnss"]) {
    const YAML::Node g = root["gnss"];
    if (g.IsScalar() && (g.Scalar() == "none" || g.Scalar() == "false" || g.Scalar() == "off")) {
      sc.gnss.reset();
    } else {
      sc.gnss = parseGnssSimConfig(g, r.file());
      // Without `navigation:` the bundled file (it covers the default date).
      if (sc.gnss->navigationFile.empty()) sc.gnss->navigationFile = bundledNavigationFile();
    }
  }
  // Consistency between sections.
  if (sc.trajectory == TrajectoryKind::Track && !sc.track.roverLog.empty() && sc.gnss)
    r.fail(root["trajectory"], "trajectory.rover_log", "a real rover log replaces the simulated GNSS: set gnss: none");
  if (sc.structure && sc.output == CameraOutput::Images && !sc.cameras.empty())
    r.fail(root["scene"], "scene.structure", "3-D structure gives feature tracks only: set cameras.output: features");
  if (sc.trajectory == TrajectoryKind::Flight &&
      (sc.flight.pattern == FlightPattern::Drive || sc.flight.pattern == FlightPattern::Walk) &&
      sc.flight.restHeight <= 0.0)
    r.fail(root["trajectory"], "trajectory.rest_height_m", "a ground vehicle or walker needs its IMU above the ground");
}

}  // namespace

Eigen::Matrix3d cameraMountRotation(bool lookDown, const Eigen::Vector3d& rpy) {
  Eigen::Matrix3d look;
  if (lookDown)
    look << 0, -1, 0, -1, 0, 0, 0, 0, -1;  // x_C = -y_B, y_C = -x_B, z_C = -z_B
  else
    look << 0, 0, 1, -1, 0, 0, 0, -1, 0;  // x_C = -y_B, y_C = -z_B, z_C = x_B
  return look * rotZ(rpy.z() * kDeg) * rotY(rpy.y() * kDeg) * rotX(rpy.x() * kDeg);
}

vio::CameraCalibration downwardCamera(const std::string& name, const Eigen::Vector3d& position,
                                      const Eigen::Vector3d& mountRpyDeg, bool cam1Intrinsics) {
  vio::CameraCalibration c;
  c.name = name;
  c.rate_hz = 20.0;
  // EuRoC MAV VI-sensor (MT9M034) calibration, mav0/cam0 and cam1 sensor.yaml (Burri et al. 2016).
  if (!cam1Intrinsics)
    c.intrinsics = {752, 480, 458.654, 457.296, 367.215, 248.375, vio::DistortionModel::RadialTangential,
                    {-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05}};
  else
    c.intrinsics = {752, 480, 457.587, 456.134, 379.999, 255.238, vio::DistortionModel::RadialTangential,
                    {-0.28368365, 0.07451284, -0.00010473, -3.55590700e-05}};
  c.T_BS.setIdentity();
  c.T_BS.topLeftCorner<3, 3>() = cameraMountRotation(true, mountRpyDeg);
  c.T_BS.topRightCorner<3, 1>() = position;
  return c;
}

std::string bundledDataDirectory() {
  if (const char* env = std::getenv("GVINS_DATA_DIR"); env != nullptr && *env != '\0') return env;
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  const std::filesystem::path base = ec ? std::filesystem::path(".") : exe.parent_path();
  return (base / GVINS_SIM_DATA_FROM_BIN / "data").lexically_normal().string();
}

std::string bundledNavigationFile() {
  return bundledDataDirectory() + "/gnss/nagoya_static_2024/base.nav.gz";
}

Scenario defaultScenario() {
  Scenario s;
  s.name = "default";
  s.description = "two-minute stereo UAV survey near Nagoya with a base station 3 km away";
  // Origin: the antenna of the Nagoya base receiver of tests/data/gnss/nagoya_static_2024
  // (base_position.txt); start: the first epoch of that recording, so base.nav covers it.
  s.frame.origin = geodeticFromDegrees(35.134707705, 136.977577939, 104.853);
  s.frame.startTime = GpsTime::fromCalendar({2024, 6, 24, 8, 20, 0.0});
  FlightSpec& f = s.flight;
  f.pattern = FlightPattern::Lawnmower;
  f.height = 40.0;
  f.length = 540.0;
  f.climbRate = 3.0;
  f.speed = 8.0;
  f.rows = 4;
  f.rowSpacing = 30.0;
  f.headingDeg = 30.0;
  f.wobbleDeg = 0.3;
  s.imu.rateHz = 200.0;
  // Stereo pair looking down, 12 cm baseline across the body, small mounting errors.
  s.cameras = {downwardCamera("cam0", {0.06, 0.06, -0.04}, {0.4, -0.3, 0.2}, false),
               downwardCamera("cam1", {0.06, -0.06, -0.04}, {-0.2, 0.3, -0.4}, true)};
  s.texture.board.enabled = true;
  s.texture.board.origin = {2.0, -3.0};
  s.texture.board.innerCols = 8;
  s.texture.board.innerRows = 6;
  s.texture.board.square = 0.5;
  GnssSimConfig g;
  g.navigationFile = bundledNavigationFile();
  s.gnss = g;
  return s;
}

Scenario parseScenario(const std::string& text, const std::string& file) {
  if (text.size() > kMaxScenarioBytes) throw ParseError(file, 0, "", "scenario larger than 1 MiB");
  if (text.find('\0') != std::string::npos) throw ParseError(file, 0, "", "binary data (NUL byte) in a scenario");
  Scenario sc = defaultScenario();
  sc.file = file;
  sc.text = text;
  const Reader r(file);
  try {
    const YAML::Node root = YamlReader::loadText(text, file);
    if (root.IsNull()) return sc;
    parseRoot(r, root, sc);
  } catch (const YAML::Exception& e) {
    throw ParseError(file, e.mark.is_null() || e.mark.line < 0 ? 0 : e.mark.line + 1, "YAML", e.msg);
  }
  return sc;
}

Scenario loadScenario(const std::string& path) {
  return parseScenario(YamlReader::readFile(path, kMaxScenarioBytes), path);
}

}  // namespace gvins::sim
