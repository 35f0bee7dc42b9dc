// Sensor calibration YAML files.
//
// Parser choice: yaml-cpp rather than cv::FileStorage. Kalibr files are plain YAML 1.1 (block
// sequences of flow sequences for T_cam_imu, no "%YAML:1.0" header) which FileStorage does not
// read reliably, while yaml-cpp reads both those and the EuRoC files; yaml-cpp reports a line and
// column for every syntax error and every node (needed for ParseError), and bounds its recursion
// depth (DeepRecursion), whereas FileStorage signals errors through cv::Exception without a usable
// position. Values are converted with gvins' strict number parser, not yaml-cpp's as<double>().
#include "gvins/vio/sensor_yaml.hpp"

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

#include <yaml-cpp/yaml.h>
#include <Eigen/Geometry>

#include "gvins/base/parse_error.hpp"
#include "gvins/base/yaml_reader.hpp"
#include "gvins/base/text_fields.hpp"

namespace gvins::vio {
namespace {

constexpr std::size_t kMaxYamlBytes = 1 << 20;

struct Ctx {
  const std::string& file;
};

std::int64_t lineOf(const YAML::Node& n) {
  const YAML::Mark m = n.Mark();
  return m.is_null() ? 0 : m.line + 1;
}

[[noreturn]] void fail(const Ctx& c, std::int64_t line, const std::string& field, const std::string& what) {
  throw ParseError(c.file, line, field, what);
}

YAML::Node loadYaml(std::string_view text, const Ctx& c) {
  if (text.size() > kMaxYamlBytes) fail(c, 0, "", "file larger than 1 MiB: not a sensor calibration file");
  for (const char ch : text) {
    if (ch == '\0') fail(c, 0, "", "binary data (NUL byte) in a YAML file");
  }
  std::string s(text);
  // OpenCV writes a non-standard "%YAML:1.0" directive; blank it (keeping line numbers).
  if (s.rfind("%YAML:", 0) == 0) {
    const std::size_t eol = s.find('\n');
    s.replace(0, eol == std::string::npos ? s.size() : eol, "");
  }
  try {
    YAML::Node root = YamlReader::loadText(s, c.file);
    if (!root.IsMap()) fail(c, lineOf(root), "", "expected a YAML mapping of keys at the top level");
    return root;
  } catch (const YAML::Exception& e) {
    fail(c, e.mark.is_null() ? 0 : e.mark.line + 1, "YAML", e.msg);
  }
}

std::string readFileText(const std::string& path) { return YamlReader::readFile(path, kMaxYamlBytes); }

YAML::Node child(const YAML::Node& map, const char* key, const Ctx& c, bool required = true) {
  if (!map.IsMap()) fail(c, lineOf(map), key, "expected a mapping containing this key");
  YAML::Node n = map[key];
  if (!n.IsDefined() || n.IsNull()) {
    if (required) fail(c, lineOf(map), key, "missing");
    return YAML::Node(YAML::NodeType::Undefined);
  }
  return n;
}

double scalarDouble(const YAML::Node& n, const Ctx& c, const std::string& field) {
  if (!n.IsScalar()) fail(c, lineOf(n), field, "expected a number");
  const TextLocation where{c.file, lineOf(n)};
  return parseDouble(n.Scalar(), where, field);
}

std::string scalarString(const YAML::Node& n, const Ctx& c, const std::string& field) {
  if (!n.IsScalar()) fail(c, lineOf(n), field, "expected a string");
  return n.Scalar();
}

std::vector<double> doubleList(const YAML::Node& n, const Ctx& c, const std::string& field,
                               std::size_t minCount, std::size_t maxCount) {
  if (!n.IsSequence()) fail(c, lineOf(n), field, "expected a list of numbers");
  if (n.size() < minCount || n.size() > maxCount) {
    fail(c, lineOf(n), field,
         "expected " + (minCount == maxCount ? std::to_string(minCount)
                                             : std::to_string(minCount) + " to " + std::to_string(maxCount)) +
             " numbers, found " + std::to_string(n.size()));
  }
  std::vector<double> v;
  for (std::size_t i = 0; i < n.size(); ++i) v.push_back(scalarDouble(n[i], c, field));
  return v;
}

// A 4x4 rigid transform: EuRoC {rows: 4, cols: 4, data: [16]} or Kalibr nested 4x4 list.
Eigen::Matrix4d transform(const YAML::Node& n, const Ctx& c, const std::string& field) {
  Eigen::Matrix4d T;
  std::int64_t line = lineOf(n);  // where the numbers are, for value errors
  if (n.IsMap()) {
    const double rows = scalarDouble(child(n, "rows", c), c, field + ".rows");
    const double cols = scalarDouble(child(n, "cols", c), c, field + ".cols");
    if (rows != 4.0 || cols != 4.0) fail(c, lineOf(n), field, "expected rows: 4 and cols: 4");
    const YAML::Node dn = child(n, "data", c);
    line = lineOf(dn);
    const auto d = doubleList(dn, c, field + ".data", 16, 16);
    for (int r = 0; r < 4; ++r) {
      for (int k = 0; k < 4; ++k) T(r, k) = d[static_cast<std::size_t>(4 * r + k)];
    }
  } else if (n.IsSequence()) {
    if (n.size() != 4) fail(c, lineOf(n), field, "expected 4 rows of 4 numbers");
    for (std::size_t r = 0; r < 4; ++r) {
      const auto row = doubleList(n[r], c, field, 4, 4);
      for (int k = 0; k < 4; ++k) T(static_cast<int>(r), k) = row[static_cast<std::size_t>(k)];
    }
  } else {
    fail(c, lineOf(n), field, "expected a 4x4 matrix");
  }
  if (std::abs(T(3, 0)) > 1e-9 || std::abs(T(3, 1)) > 1e-9 || std::abs(T(3, 2)) > 1e-9 ||
      std::abs(T(3, 3) - 1.0) > 1e-9) {
    fail(c, line, field, "last row must be 0 0 0 1");
  }
  const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
  const double orthoErr = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (!(orthoErr < 1e-3) || !(R.determinant() > 0.0)) {
    fail(c, line, field, "rotation part is not a rotation matrix (orthonormality error " +
                                  std::to_string(orthoErr) + ")");
  }
  // Remove the rounding of the printed coefficients.
  T.topLeftCorner<3, 3>() = Eigen::Quaterniond(R).normalized().toRotationMatrix();
  return T;
}

DistortionModel distortionModel(const YAML::Node& n, const Ctx& c, const std::string& field) {
  const std::string m = scalarString(n, c, field);
  if (m == "radial-tangential" || m == "radtan" || m == "plumb_bob") return DistortionModel::RadialTangential;
  if (m == "equidistant" || m == "fisheye") return DistortionModel::Equidistant;
  if (m == "none") return DistortionModel::None;
  fail(c, lineOf(n), field, "unsupported distortion model '" + m + "' (radial-tangential, equidistant)");
}

void fillIntrinsics(CameraIntrinsics& k, const YAML::Node& map, const Ctx& c, const char* coeffKey) {
  const YAML::Node modelNode = child(map, "camera_model", c);
  const std::string model = scalarString(modelNode, c, "camera_model");
  if (model != "pinhole") {
    fail(c, lineOf(modelNode), "camera_model", "unsupported camera model '" + model + "' (pinhole)");
  }
  const YAML::Node in = child(map, "intrinsics", c);
  const auto f = doubleList(in, c, "intrinsics", 4, 4);
  if (!(f[0] > 0.0) || !(f[1] > 0.0)) fail(c, lineOf(in), "intrinsics", "focal lengths must be positive");
  k.fx = f[0];
  k.fy = f[1];
  k.cx = f[2];
  k.cy = f[3];
  const YAML::Node res = child(map, "resolution", c);
  const auto r = doubleList(res, c, "resolution", 2, 2);
  for (const double v : r) {
    if (!(v >= 1.0 && v <= 100000.0) || v != std::floor(v)) {
      fail(c, lineOf(res), "resolution", "expected two positive integers (width height)");
    }
  }
  k.width = static_cast<int>(r[0]);
  k.height = static_cast<int>(r[1]);
  k.model = distortionModel(child(map, "distortion_model", c), c, "distortion_model");
  const YAML::Node dn = child(map, coeffKey, c);
  const auto d = doubleList(dn, c, coeffKey, k.model == DistortionModel::None ? 0 : 4,
                            k.model == DistortionModel::RadialTangential ? 5 : 4);
  if (d.size() == 5 && d[4] != 0.0) fail(c, lineOf(dn), coeffKey, "k3 (5th coefficient) is not supported; it must be 0");
  for (std::size_t i = 0; i < 4 && i < d.size(); ++i) k.distortion[i] = d[i];
}

template <class Fn>
auto guarded(const std::string& name, Fn&& fn) {
  const Ctx c{name};
  try {
    return fn(c);
  } catch (const YAML::Exception& e) {
    fail(c, e.mark.is_null() ? 0 : e.mark.line + 1, "YAML", e.msg);
  }
}

}  // namespace

CameraCalibration parseCameraSensorYaml(std::string_view text, const std::string& name) {
  return guarded(name, [&](const Ctx& c) {
    const YAML::Node root = loadYaml(text, c);
    CameraCalibration cal;
    if (const YAML::Node t = child(root, "sensor_type", c, false); t.IsDefined()) {
      const std::string type = scalarString(t, c, "sensor_type");
      if (type != "camera") fail(c, lineOf(t), "sensor_type", "expected 'camera', found '" + type + "'");
    }
    fillIntrinsics(cal.intrinsics, root, c, "distortion_coefficients");
    cal.T_BS = transform(child(root, "T_BS", c), c, "T_BS");
    if (const YAML::Node r = child(root, "rate_hz", c, false); r.IsDefined()) {
      cal.rate_hz = scalarDouble(r, c, "rate_hz");
      if (!(cal.rate_hz > 0.0 && cal.rate_hz < 1e5)) fail(c, lineOf(r), "rate_hz", "must be positive");
    }
    return cal;
  });
}

CameraCalibration readCameraSensorYaml(const std::string& path) {
  return parseCameraSensorYaml(readFileText(path), path);
}

ImuCalibration parseImuSensorYaml(std::string_view text, const std::string& name) {
  return guarded(name, [&](const Ctx& c) {
    const YAML::Node root = loadYaml(text, c);
    ImuCalibration cal;
    if (const YAML::Node t = child(root, "sensor_type", c, false); t.IsDefined()) {
      const std::string type = scalarString(t, c, "sensor_type");
      if (type != "imu") fail(c, lineOf(t), "sensor_type", "expected 'imu', found '" + type + "'");
    }
    auto positive = [&](const char* key, double& out) {
      const YAML::Node n = child(root, key, c);
      out = scalarDouble(n, c, key);
      if (!(out > 0.0)) fail(c, lineOf(n), key, "must be positive");
    };
    positive("gyroscope_noise_density", cal.noise.gyroscope_noise_density);
    positive("gyroscope_random_walk", cal.noise.gyroscope_random_walk);
    positive("accelerometer_noise_density", cal.noise.accelerometer_noise_density);
    positive("accelerometer_random_walk", cal.noise.accelerometer_random_walk);
    if (child(root, "rate_hz", c, false).IsDefined()) {
      positive("rate_hz", cal.noise.rate_hz);
    } else {
      positive("update_rate", cal.noise.rate_hz);  // Kalibr imu.yaml
    }
    if (const YAML::Node t = child(root, "T_BS", c, false); t.IsDefined()) cal.T_BS = transform(t, c, "T_BS");
    return cal;
  });
}

ImuCalibration readImuSensorYaml(const std::string& path) { return parseImuSensorYaml(readFileText(path), path); }

std::vector<CameraCalibration> parseKalibrCamchain(std::string_view text, const std::string& name) {
  return guarded(name, [&](const Ctx& c) {
    const YAML::Node root = loadYaml(text, c);
    std::vector<CameraCalibration> cams;
    for (int i = 0; i < 16; ++i) {
      const std::string key = "cam" + std::to_string(i);
      const YAML::Node cn = child(root, key.c_str(), c, false);
      if (!cn.IsDefined()) break;
      if (!cn.IsMap()) fail(c, lineOf(cn), key, "expected a mapping");
      CameraCalibration cal;
      cal.name = key;
      fillIntrinsics(cal.intrinsics, cn, c, "distortion_coeffs");
      const YAML::Node tn = child(cn, "T_cam_imu", c, false);
      if (!tn.IsDefined()) {
        fail(c, lineOf(cn), key + ".T_cam_imu",
             "missing (use the camchain-imucam.yaml written by kalibr_calibrate_imu_camera)");
      }
      const Eigen::Matrix4d T_ci = transform(tn, c, key + ".T_cam_imu");
      cal.T_BS.setIdentity();
      cal.T_BS.topLeftCorner<3, 3>() = T_ci.topLeftCorner<3, 3>().transpose();
      cal.T_BS.topRightCorner<3, 1>() = -T_ci.topLeftCorner<3, 3>().transpose() * T_ci.topRightCorner<3, 1>();
      if (const YAML::Node ts = child(cn, "timeshift_cam_imu", c, false); ts.IsDefined()) {
        cal.time_offset = scalarDouble(ts, c, key + ".timeshift_cam_imu");
        if (!(std::abs(cal.time_offset) <= 1.0)) {
          fail(c, lineOf(ts), key + ".timeshift_cam_imu", "must be within [-1, 1] s");
        }
      }
      cams.push_back(cal);
    }
    if (cams.empty()) fail(c, 0, "cam0", "no cameras (cam0, cam1, ...) in the camchain file");
    return cams;
  });
}

std::vector<CameraCalibration> readKalibrCamchain(const std::string& path) {
  return parseKalibrCamchain(readFileText(path), path);
}

}  // namespace gvins::vio
