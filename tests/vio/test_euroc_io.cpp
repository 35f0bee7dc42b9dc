// EuRoC/ASL readers (IMU, camera lists, ground truth, sensor.yaml, images, whole dataset) and
// TUM trajectories: real files give the known contents; every kind of bad input gives a
// gvins::ParseError naming file, line and field.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <functional>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "gvins/base/parse_error.hpp"
#include "gvins/vio/euroc_csv.hpp"
#include "gvins/vio/euroc_dataset.hpp"
#include "gvins/vio/image_io.hpp"
#include "gvins/vio/sensor_yaml.hpp"
#include "gvins/vio/so3.hpp"
#include "gvins/vio/tum_trajectory.hpp"

using namespace gvins::vio;
using gvins::ParseError;
namespace fs = std::filesystem;

namespace {
const std::string kData = GVINS_TEST_DATA;
const std::string kV101 = kData + "/euroc/v101_static_stereo";
const std::string kV102 = kData + "/euroc/v102_imu_groundtruth";

// Runs fn, expects a ParseError and checks its line and field.
void expectParseError(const std::function<void()>& fn, std::int64_t line, const std::string& field,
                      const std::string& reasonPart = "") {
  try {
    fn();
    ADD_FAILURE() << "no ParseError";
  } catch (const ParseError& e) {
    EXPECT_EQ(e.line(), line) << e.what();
    EXPECT_EQ(e.field(), field) << e.what();
    if (!reasonPart.empty()) {
      EXPECT_NE(std::string(e.what()).find(reasonPart), std::string::npos) << e.what();
    }
  }
}

std::vector<ImuSample> parseImu(const std::string& text, double rate = 200.0, ImuGapReport* gaps = nullptr) {
  ImuCsvReader r(text, "imu.csv", rate);
  std::vector<ImuSample> out;
  ImuSample s;
  while (r.next(s)) out.push_back(s);
  if (gaps) *gaps = r.gaps();
  return out;
}

void writeFile(const fs::path& p, const std::string& text) {
  std::ofstream(p, std::ios::binary) << text;
}
std::string readFile(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// A scratch copy of the V1_01 test subset (text files copied, images symlinked).
struct DatasetCopy {
  fs::path root;
  explicit DatasetCopy(const std::string& tag) {
    root = fs::temp_directory_path() / ("gvins_vio_" + tag + "_" + std::to_string(::getpid()));
    fs::remove_all(root);
    fs::create_directories(root);
    for (const auto& e : fs::recursive_directory_iterator(kV101)) {
      const fs::path rel = fs::relative(e.path(), kV101);
      if (e.is_directory()) {
        fs::create_directories(root / rel);
      } else if (e.path().extension() == ".png") {
        fs::create_symlink(e.path(), root / rel);
      } else {
        fs::copy_file(e.path(), root / rel);
      }
    }
  }
  ~DatasetCopy() { fs::remove_all(root); }
  fs::path mav0() const { return root / "mav0"; }
};
}  // namespace

// ----------------------------------------------------------------------------------- IMU CSV

TEST(EurocImuCsv, RealFileGzip) {
  ImuGapReport gaps;
  const auto imu = readImuCsv(kV101 + "/mav0/imu0/data.csv.gz", 200.0, &gaps);
  ASSERT_EQ(imu.size(), 541u);
  EXPECT_EQ(imu.front().t_ns, 1403715273262142976LL);
  EXPECT_DOUBLE_EQ(imu.front().gyro.x(), -0.0020943951023931952);
  EXPECT_DOUBLE_EQ(imu.front().accel.z(), -3.6938381666666662);
  EXPECT_EQ(gaps.samples, 541u);
  EXPECT_EQ(gaps.gaps, 0u);
  EXPECT_EQ(gaps.nominalPeriod_ns, 5'000'000);
  // Static vehicle: the specific force is gravity.
  double meanNorm = 0.0;
  for (const auto& s : imu) meanNorm += s.accel.norm() / imu.size();
  EXPECT_NEAR(meanNorm, 9.81, 0.1);
}

TEST(EurocImuCsv, GapsAreCounted) {
  const std::string text =
      "#timestamp [ns],w_x,w_y,w_z,a_x,a_y,a_z\n"
      "1000000000,0,0,0,0,0,9.81\n"
      "1005000000,0,0,0,0,0,9.81\n"
      "1015000000,0,0,0,0,0,9.81\n"      // one sample missing
      "1020000000,0,0,0,0,0,9.81\r\n"    // CRLF
      "\n"
      "1045000000,0,0,0,0,0,9.81\n";     // four missing
  ImuGapReport gaps;
  const auto imu = parseImu(text, 200.0, &gaps);
  EXPECT_EQ(imu.size(), 5u);
  EXPECT_EQ(gaps.gaps, 2u);
  EXPECT_EQ(gaps.missingSamples, 5u);
  EXPECT_EQ(gaps.largestGap_ns, 25'000'000);
  EXPECT_EQ(gaps.largestGapStart_ns, 1020000000);
}

TEST(EurocImuCsv, MalformedInputNamesLineAndField) {
  const std::string h = "#timestamp,w_x,w_y,w_z,a_x,a_y,a_z\n1000000000,0,0,0,0,0,9.81\n";
  expectParseError([&] { parseImu(h + "1000000000,0,0,0,0,0,9.81\n"); }, 3, "timestamp", "duplicate");
  expectParseError([&] { parseImu(h + "999999999,0,0,0,0,0,9.81\n"); }, 3, "timestamp", "before");
  expectParseError([&] { parseImu(h + "1005000000,0,0,0,0,9.81\n"); }, 3, "a_z", "expected 7");
  expectParseError([&] { parseImu(h + "1005000000,0,0,0,0,0,9.81,1\n"); }, 3, "line");
  expectParseError([&] { parseImu(h + "1005000000,0,x,0,0,0,9.81\n"); }, 3, "w_y", "not a number");
  expectParseError([&] { parseImu(h + "1005000000,0,0,0,nan,0,9.81\n"); }, 3, "a_x");
  expectParseError([&] { parseImu(h + "1005000000,0,0,0,1e999,0,9.81\n"); }, 3, "a_x", "range");
  // Finite but physically impossible values (a corrupt file) are named here, not by the filter.
  expectParseError([&] { parseImu(h + "1005000000,0,0,0,1e30,0,9.81\n"); }, 3, "a_x", "beyond");
  expectParseError([&] { parseImu(h + "1005000000,0,-250,0,0,0,9.81\n"); }, 3, "w_y", "beyond");
  expectParseError([&] { parseImu(h + "1005000000,0,0,,0,0,9.81\n"); }, 3, "w_z", "missing");
  expectParseError([&] { parseImu(h + "-1005000000,0,0,0,0,0,9.81\n"); }, 3, "timestamp");
  expectParseError([&] { parseImu(h + "99999999999999999999,0,0,0,0,0,9.81\n"); }, 3, "timestamp", "range");
  expectParseError([&] { parseImu(h + "1.5e9,0,0,0,0,0,9.81\n"); }, 3, "timestamp");
  expectParseError([] { readImuCsv("/nonexistent/imu0/data.csv"); }, 0, "", "cannot open");
}

// -------------------------------------------------------------------------------- camera CSV

TEST(EurocCameraCsv, RealAndMalformed) {
  const auto cam = readCameraCsv(kV101 + "/mav0/cam1/data.csv");
  ASSERT_EQ(cam.size(), 24u);
  EXPECT_EQ(cam[0].t_ns, 1403715274312143104LL);
  EXPECT_EQ(cam[0].filename, "1403715274312143104.png");
  EXPECT_EQ(cam[0].line, 2);
  const std::string h = "#timestamp [ns],filename\n1,1.png\n";
  expectParseError([&] { parseCameraCsv(h + "2,../../etc/passwd\n", "c.csv"); }, 3, "filename", "path");
  expectParseError([&] { parseCameraCsv(h + "2\n", "c.csv"); }, 3, "filename");
  expectParseError([&] { parseCameraCsv(h + "2,a.png,b\n", "c.csv"); }, 3, "line");
  expectParseError([&] { parseCameraCsv(h + "1,b.png\n", "c.csv"); }, 3, "timestamp", "duplicate");
  expectParseError([&] { parseCameraCsv(h + "3,\n", "c.csv"); }, 3, "filename", "empty");
  // A fractional nanosecond part (as in some EuRoC ground-truth exports) is rounded.
  EXPECT_EQ(parseCameraCsv("5.6,a.png\n", "c.csv").at(0).t_ns, 6);
}

// ------------------------------------------------------------------------------ ground truth

TEST(EurocGroundTruthCsv, RealFile) {
  const auto gt = readGroundTruthCsv(kV102 + "/state_groundtruth_estimate0.csv.gz");
  ASSERT_EQ(gt.size(), 8001u);
  EXPECT_EQ(gt.front().state.t_ns, 1403715534907143168LL);
  EXPECT_TRUE(gt.front().hasVelocityAndBiases);
  for (const auto& g : gt) {
    EXPECT_LT((g.state.R_WI.transpose() * g.state.R_WI - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  }
  // Ground-truth velocity agrees with the central difference of the positions (5 ms apart).
  double worst = 0.0;
  for (std::size_t i = 1; i + 1 < gt.size(); i += 50) {
    const double dt = (gt[i + 1].state.t_ns - gt[i - 1].state.t_ns) * 1e-9;
    const Eigen::Vector3d v = (gt[i + 1].state.p_WI - gt[i - 1].state.p_WI) / dt;
    worst = std::max(worst, (v - gt[i].state.v_WI).norm());
  }
  EXPECT_LT(worst, 0.05);
}

TEST(EurocGroundTruthCsv, PoseOnlyFormAndErrors) {
  auto parse = [](const std::string& text) {
    GroundTruthCsvReader r(text, "gt.csv");
    std::vector<GroundTruthSample> out;
    GroundTruthSample s;
    while (r.next(s)) out.push_back(s);
    return out;
  };
  const auto gt = parse("#t,x,y,z,qw,qx,qy,qz\n10,1,2,3,0,1,0,0\n20,1,2,3,0.7071068,0,0,0.7071068\n");
  ASSERT_EQ(gt.size(), 2u);
  EXPECT_FALSE(gt[0].hasVelocityAndBiases);
  EXPECT_NEAR(gt[0].state.R_WI(1, 1), -1.0, 1e-12);  // 180 deg about x
  EXPECT_NEAR(gt[1].state.R_WI(1, 0), 1.0, 1e-6);    // 90 deg about z
  expectParseError([&] { parse("10,1,2,3,0,1,0,0\n20,1,2,3,0,1,0,0,1\n"); }, 2, "line");
  expectParseError([&] { parse("10,1,2,3,0,1,0\n"); }, 1, "line", "expected 17");
  expectParseError([&] { parse("10,1,2,3,0,0.5,0,0\n"); }, 1, "q_w", "norm");
  expectParseError([&] { parse("10,1,2,3,0,1,0,0\n10,1,2,3,0,1,0,0\n"); }, 2, "timestamp", "duplicate");
}

// ------------------------------------------------------------------------------- sensor.yaml

TEST(SensorYaml, RealEurocFiles) {
  const auto c0 = readCameraSensorYaml(kV101 + "/mav0/cam0/sensor.yaml");
  EXPECT_EQ(c0.intrinsics.width, 752);
  EXPECT_EQ(c0.intrinsics.height, 480);
  EXPECT_DOUBLE_EQ(c0.intrinsics.fx, 458.654);
  EXPECT_DOUBLE_EQ(c0.intrinsics.cy, 248.375);
  EXPECT_EQ(c0.intrinsics.model, DistortionModel::RadialTangential);
  EXPECT_DOUBLE_EQ(c0.intrinsics.distortion[0], -0.28340811);
  EXPECT_DOUBLE_EQ(c0.intrinsics.distortion[3], 1.76187114e-05);
  EXPECT_DOUBLE_EQ(c0.rate_hz, 20.0);
  EXPECT_NEAR(c0.T_BS(0, 3), -0.0216401454975, 1e-15);
  EXPECT_NEAR(c0.T_BS(1, 0), 0.999557249008, 1e-6);  // re-orthonormalised
  const auto c1 = readCameraSensorYaml(kV101 + "/mav0/cam1/sensor.yaml");
  // Stereo baseline from the two extrinsics: about 11 cm.
  const Eigen::Vector3d base = c1.T_BS.topRightCorner<3, 1>() - c0.T_BS.topRightCorner<3, 1>();
  EXPECT_NEAR(base.norm(), 0.1101, 0.0005);
  const auto imu = readImuSensorYaml(kV101 + "/mav0/imu0/sensor.yaml");
  EXPECT_DOUBLE_EQ(imu.noise.gyroscope_noise_density, 1.6968e-04);
  EXPECT_DOUBLE_EQ(imu.noise.gyroscope_random_walk, 1.9393e-05);
  EXPECT_DOUBLE_EQ(imu.noise.accelerometer_noise_density, 2.0e-3);
  EXPECT_DOUBLE_EQ(imu.noise.accelerometer_random_walk, 3.0e-3);
  EXPECT_DOUBLE_EQ(imu.noise.rate_hz, 200.0);
  EXPECT_TRUE(imu.T_BS.isIdentity());
}

TEST(SensorYaml, MalformedCameraFiles) {
  const std::string good = readFile(kV101 + "/mav0/cam0/sensor.yaml");
  auto with = [&](const std::string& from, const std::string& to) {
    std::string s = good;
    const auto pos = s.find(from);
    EXPECT_NE(pos, std::string::npos) << from;
    s.replace(pos, from.size(), to);
    return s;
  };
  auto parse = [](const std::string& text) { parseCameraSensorYaml(text, "cam0/sensor.yaml"); };
  // Lines as in the EuRoC file: T_BS values from line 8 (numbers from line 10), resolution
  // line 17, camera_model 18, intrinsics 19, distortion_model 20.
  expectParseError([&] { parse(with("intrinsics: [458.654, 457.296, 367.215, 248.375]", "intrinsics: [458.654, 457.296, 367.215]")); },
                   19, "intrinsics", "expected 4");
  expectParseError([&] { parse(with("458.654", "-458.654")); }, 19, "intrinsics", "positive");
  expectParseError([&] { parse(with("458.654", "4x8")); }, 19, "intrinsics", "not a number");
  expectParseError([&] { parse(with("radial-tangential", "kannala")); }, 20, "distortion_model", "unsupported");
  expectParseError([&] { parse(with("camera_model: pinhole", "camera_model: omni")); }, 18, "camera_model");
  expectParseError([&] { parse(with("resolution: [752, 480]", "resolution: [752.5, 480]")); }, 17, "resolution");
  expectParseError([&] { parse(with("rows: 4", "rows: 3")); }, 8, "T_BS", "rows");
  expectParseError([&] { parse(with("0.0148655429818", "0.5")); }, 10, "T_BS", "rotation");
  expectParseError([&] { parse(with("0.0, 0.0, 0.0, 1.0]", "0.0, 0.0, 0.1, 1.0]")); }, 10, "T_BS", "last row");
  expectParseError([&] { parse(with("intrinsics:", "intrinsic:")); }, 3, "intrinsics", "missing");
  expectParseError([&] { parse(with("sensor_type: camera", "sensor_type: imu")); }, 3, "sensor_type");
  // Broken YAML syntax: the parser's own line number.
  expectParseError([&] { parse(with("resolution: [752, 480]", "resolution: [752, 480")); }, 18, "YAML");
  expectParseError([] { parseCameraSensorYaml("", "e.yaml"); }, 0, "", "mapping");
  expectParseError([] { parseCameraSensorYaml("- a\n- b\n", "e.yaml"); }, 1, "", "mapping");
  expectParseError([] { parseCameraSensorYaml(std::string("a: \0b", 5), "e.yaml"); }, 0, "", "NUL");
  expectParseError([] { parseCameraSensorYaml(std::string(5000, '[') , "deep.yaml"); }, 1, "YAML");
  expectParseError([] { readCameraSensorYaml("/nonexistent/sensor.yaml"); }, 0, "", "cannot open");
}

TEST(SensorYaml, MalformedImuFiles) {
  const std::string good = readFile(kV101 + "/mav0/imu0/sensor.yaml");
  auto with = [&](const std::string& from, const std::string& to) {
    std::string s = good;
    s.replace(s.find(from), from.size(), to);
    return s;
  };
  auto parse = [](const std::string& text) { parseImuSensorYaml(text, "imu0/sensor.yaml"); };
  expectParseError([&] { parse(with("gyroscope_noise_density: 1.6968e-04", "gyroscope_noise_density: -1")); }, 17,
                   "gyroscope_noise_density", "positive");
  expectParseError([&] { parse(with("accelerometer_random_walk: 3.0000e-3", "accelerometer_random_walk: [1]")); }, 20,
                   "accelerometer_random_walk", "number");
  expectParseError([&] { parse(with("rate_hz: 200", "rate: 200")); }, 3, "update_rate", "missing");
}

TEST(SensorYaml, KalibrCamchainAndImuYaml) {
  // EuRoC cam0/cam1 written as a Kalibr camchain-imucam.yaml: T_cam_imu is the inverse of T_BS.
  const auto c0 = readCameraSensorYaml(kV101 + "/mav0/cam0/sensor.yaml");
  const auto c1 = readCameraSensorYaml(kV101 + "/mav0/cam1/sensor.yaml");
  auto inv = [](const Eigen::Matrix4d& T) {
    Eigen::Matrix4d I = Eigen::Matrix4d::Identity();
    I.topLeftCorner<3, 3>() = T.topLeftCorner<3, 3>().transpose();
    I.topRightCorner<3, 1>() = -T.topLeftCorner<3, 3>().transpose() * T.topRightCorner<3, 1>();
    return I;
  };
  auto rows = [](const Eigen::Matrix4d& T) {
    std::string s;
    char buf[200];
    for (int r = 0; r < 4; ++r) {
      std::snprintf(buf, sizeof buf, "  - [%.17g, %.17g, %.17g, %.17g]\n", T(r, 0), T(r, 1), T(r, 2), T(r, 3));
      s += buf;
    }
    return s;
  };
  const std::string text = "cam0:\n  T_cam_imu:\n" + rows(inv(c0.T_BS)) +
                           "  camera_model: pinhole\n  distortion_coeffs: [-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05]\n"
                           "  distortion_model: radtan\n  intrinsics: [458.654, 457.296, 367.215, 248.375]\n"
                           "  resolution: [752, 480]\n  rostopic: /cam0/image_raw\n"
                           "cam1:\n  T_cam_imu:\n" + rows(inv(c1.T_BS)) +
                           "  camera_model: pinhole\n  distortion_coeffs: [-0.28368365, 0.07451284, -0.00010473, -3.55590700e-05]\n"
                           "  distortion_model: radtan\n  intrinsics: [457.587, 456.134, 379.999, 255.238]\n"
                           "  resolution: [752, 480]\n  rostopic: /cam1/image_raw\n";
  const auto cams = parseKalibrCamchain(text, "camchain-imucam.yaml");
  ASSERT_EQ(cams.size(), 2u);
  EXPECT_EQ(cams[1].name, "cam1");
  EXPECT_LT((cams[0].T_BS - c0.T_BS).norm(), 1e-12);
  EXPECT_LT((cams[1].T_BS - c1.T_BS).norm(), 1e-12);
  EXPECT_DOUBLE_EQ(cams[1].intrinsics.cx, 379.999);
  EXPECT_EQ(cams[0].time_offset, 0.0);  // no timeshift_cam_imu
  // Kalibr's timeshift_cam_imu (t_imu = t_cam + shift) is the camera's time offset.
  const std::string shifted = text.substr(0, text.find("cam1:")) + "  timeshift_cam_imu: -0.0042\n";
  EXPECT_DOUBLE_EQ(parseKalibrCamchain(shifted, "cc.yaml")[0].time_offset, -0.0042);
  expectParseError([&] { parseKalibrCamchain(shifted.substr(0, shifted.size() - 8) + "x\n", "cc.yaml"); }, 13,
                   "cam0.timeshift_cam_imu");
  expectParseError([&] { parseKalibrCamchain(shifted.substr(0, shifted.size() - 8) + "3.0\n", "cc.yaml"); }, 13,
                   "cam0.timeshift_cam_imu", "within");
  expectParseError([] { parseKalibrCamchain("cam0:\n  camera_model: pinhole\n", "cc.yaml"); }, 2, "intrinsics", "missing");
  expectParseError([] { parseKalibrCamchain("foo: 1\n", "cc.yaml"); }, 0, "cam0");

  const auto imu = parseImuSensorYaml(
      "accelerometer_noise_density: 0.01\naccelerometer_random_walk: 0.0002\ngyroscope_noise_density: 0.005\n"
      "gyroscope_random_walk: 4.0e-06\nrostopic: /imu0\nupdate_rate: 400.0\n",
      "imu.yaml");
  EXPECT_DOUBLE_EQ(imu.noise.rate_hz, 400.0);
  EXPECT_DOUBLE_EQ(imu.noise.gyroscope_random_walk, 4.0e-6);
}

// ------------------------------------------------------------------------------------- images

TEST(ImageIo, RealPngAndBadFiles) {
  const std::string png = kV101 + "/mav0/cam0/data/1403715274312143104.png";
  const cv::Mat img = readGrayImage(png, 752, 480);
  EXPECT_EQ(img.type(), CV_8UC1);
  EXPECT_EQ(img.cols, 752);
  EXPECT_EQ(img.rows, 480);
  const double mean = cv::mean(img)[0];
  EXPECT_GT(mean, 20.0);
  EXPECT_LT(mean, 230.0);
  expectParseError([&] { readGrayImage(png, 640, 480); }, 0, "image", "calibration says");
  const std::string bytes = readFile(png);
  const fs::path dir = fs::temp_directory_path() / ("gvins_vio_img_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  writeFile(dir / "trunc.png", bytes.substr(0, bytes.size() / 2));
  writeFile(dir / "header.png", bytes.substr(0, 20));
  writeFile(dir / "text.png", "this is not an image\n");
  writeFile(dir / "empty.png", "");
  expectParseError([&] { readGrayImage((dir / "trunc.png").string()); }, 0, "image", "unreadable");
  expectParseError([&] { readGrayImage((dir / "header.png").string()); }, 0, "image", "truncated");
  expectParseError([&] { readGrayImage((dir / "text.png").string()); }, 0, "image", "not a PNG");
  expectParseError([&] { readGrayImage((dir / "empty.png").string()); }, 0, "image", "empty");
  expectParseError([&] { readGrayImage((dir / "missing.png").string()); }, 0, "image", "cannot open");
  // A PNG header claiming a gigantic image is refused before decoding.
  std::string huge = bytes.substr(0, 33);
  huge[16] = 0x7f;
  writeFile(dir / "huge.png", huge);
  expectParseError([&] { readGrayImage((dir / "huge.png").string()); }, 0, "image", "implausible");
  fs::remove_all(dir);
}

namespace {
// A PNG written by hand from the specification (PNG 2nd edition: chunks with CRC-32, a zlib
// stream of stored deflate blocks with Adler-32, row filter `filterOf(y)` computed from the
// definitions), independent of libpng and zlib.
std::uint32_t crc32Of(const std::string& bytes) {
  std::uint32_t c = 0xffffffffu;
  for (const unsigned char ch : bytes) {
    c ^= ch;
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
  }
  return c ^ 0xffffffffu;
}
std::string be32(std::uint32_t v) {
  return {static_cast<char>(v >> 24), static_cast<char>(v >> 16), static_cast<char>(v >> 8), static_cast<char>(v)};
}
std::string chunk(const std::string& type, const std::string& data) {
  return be32(static_cast<std::uint32_t>(data.size())) + type + data + be32(crc32Of(type + data));
}
int paethPredictor(int a, int b, int c) {
  const int p = a + b - c, pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
  return pa <= pb && pa <= pc ? a : (pb <= pc ? b : c);
}
// A zlib stream (RFC 1950) of stored deflate blocks (RFC 1951, section 3.2.4) holding `raw`.
std::string zlibStored(const std::string& raw) {
  std::string z = "\x78\x01";  // zlib header: deflate, 32 KiB window, no dictionary
  for (std::size_t o = 0; o < raw.size();) {
    const std::size_t n = std::min<std::size_t>(65535, raw.size() - o);
    const bool last = o + n == raw.size();
    z.push_back(last ? 1 : 0);  // stored block
    z.push_back(static_cast<char>(n & 0xff));
    z.push_back(static_cast<char>(n >> 8));
    z.push_back(static_cast<char>(~n & 0xff));
    z.push_back(static_cast<char>((~n >> 8) & 0xff));
    z += raw.substr(o, n);
    o += n;
  }
  std::uint32_t s1 = 1, s2 = 0;
  for (const unsigned char ch : raw) {
    s1 = (s1 + ch) % 65521;
    s2 = (s2 + s1) % 65521;
  }
  z += be32((s2 << 16) | s1);
  return z;
}
std::string handWrittenPng(const cv::Mat& img, const std::function<int(int)>& filterOf, std::size_t idatChunk) {
  std::string raw;
  for (int y = 0; y < img.rows; ++y) {
    const int f = filterOf(y);
    raw.push_back(static_cast<char>(f));
    for (int x = 0; x < img.cols; ++x) {
      const int v = img.at<std::uint8_t>(y, x);
      const int a = x > 0 ? img.at<std::uint8_t>(y, x - 1) : 0;
      const int b = y > 0 ? img.at<std::uint8_t>(y - 1, x) : 0;
      const int c = x > 0 && y > 0 ? img.at<std::uint8_t>(y - 1, x - 1) : 0;
      const int pred = f == 0 ? 0 : f == 1 ? a : f == 2 ? b : f == 3 ? (a + b) / 2 : paethPredictor(a, b, c);
      raw.push_back(static_cast<char>((v - pred) & 0xff));
    }
  }
  const std::string z = zlibStored(raw);
  std::string png = "\x89PNG\r\n\x1a\n";
  png += chunk("IHDR", be32(static_cast<std::uint32_t>(img.cols)) + be32(static_cast<std::uint32_t>(img.rows)) +
                           std::string("\x08\x00\x00\x00\x00", 5));
  for (std::size_t o = 0; o < z.size(); o += idatChunk) png += chunk("IDAT", z.substr(o, idatChunk));
  png += chunk("tEXt", std::string("Comment\0hand-written", 20));
  png += chunk("IEND", "");
  return png;
}
cv::Mat decode(const std::string& png, const std::string& name = "hand.png") {
  return decodeGrayImage(std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(png.data()), png.size()), name);
}
}  // namespace

TEST(ImageIo, GrayPngRowFiltersDecodeExactly) {
  // Real and random pixels, every row filter (one per row in turn, or all rows the same), the
  // image data split over several IDAT chunks: decoded exactly (and as cv::imdecode does).
  cv::Mat noise(97, 131, CV_8UC1);
  cv::RNG(5).fill(noise, cv::RNG::UNIFORM, 0, 256);
  const cv::Mat real = readGrayImage(kV101 + "/mav0/cam0/data/1403715274312143104.png", 752, 480);
  for (const cv::Mat& img : {noise, real}) {
    for (int mode = -1; mode < 5; ++mode) {
      const std::string png = handWrittenPng(img, [&](int y) { return mode < 0 ? y % 5 : mode; }, 8192);
      const cv::Mat ours = decode(png);
      ASSERT_EQ(ours.size(), img.size());
      EXPECT_EQ(cv::norm(ours, img, cv::NORM_INF), 0.0) << "filter mode " << mode;
      const cv::Mat ref = cv::imdecode(std::vector<std::uint8_t>(png.begin(), png.end()), cv::IMREAD_UNCHANGED);
      EXPECT_EQ(cv::norm(ref, img, cv::NORM_INF), 0.0) << "the hand-written PNG is not what libpng reads";
    }
  }
  // Compressed files: the bundled EuRoC PNGs (zlib level 9, adaptive filters) and OpenCV's own
  // encodings decode as libpng decodes them.
  const EurocDataset ds(kV101);
  for (int cam = 0; cam < 2; ++cam) {
    for (std::size_t i = 0; i < ds.cameraEntries(cam).size(); ++i) {
      const std::string bytes = readFile(ds.imagePath(cam, i));
      const cv::Mat ref = cv::imdecode(std::vector<std::uint8_t>(bytes.begin(), bytes.end()), cv::IMREAD_UNCHANGED);
      EXPECT_EQ(cv::norm(decode(bytes), ref, cv::NORM_INF), 0.0) << ds.imagePath(cam, i);
    }
  }
  for (const std::vector<int>& params : {std::vector<int>{}, std::vector<int>{cv::IMWRITE_PNG_COMPRESSION, 1}}) {
    std::vector<std::uint8_t> buf;
    cv::imencode(".png", real, buf, params);
    EXPECT_EQ(cv::norm(decode(std::string(buf.begin(), buf.end())), real, cv::NORM_INF), 0.0);
  }
  // Other PNG kinds still go through OpenCV: 16-bit grey scaled to 8 bits, colour to grey.
  cv::Mat wide;
  real.convertTo(wide, CV_16U, 257.0);
  std::vector<std::uint8_t> buf;
  cv::imencode(".png", wide, buf);
  EXPECT_EQ(cv::norm(decode(std::string(buf.begin(), buf.end())), real, cv::NORM_INF), 0.0);
  cv::Mat colour;
  cv::cvtColor(real, colour, cv::COLOR_GRAY2BGR);
  cv::imencode(".png", colour, buf);
  EXPECT_LE(cv::norm(decode(std::string(buf.begin(), buf.end())), real, cv::NORM_INF), 1.0);
}

TEST(ImageIo, DamagedGrayPngIsAParseError) {
  cv::Mat img(40, 60, CV_8UC1);
  cv::RNG(9).fill(img, cv::RNG::UNIFORM, 0, 256);
  const std::string good = handWrittenPng(img, [](int y) { return y % 5; }, 1000);
  ASSERT_EQ(cv::norm(decode(good), img, cv::NORM_INF), 0.0);
  const std::size_t idat = good.find("IDAT");
  ASSERT_NE(idat, std::string::npos);
  // A flipped bit in the image data: the chunk CRC.
  std::string bad = good;
  bad[idat + 100] = static_cast<char>(bad[idat + 100] ^ 0x10);
  expectParseError([&] { decode(bad, "flip.png"); }, 0, "image", "CRC");
  // Cut after the image data (no IEND), or inside a chunk.
  expectParseError([&] { decode(good.substr(0, good.find("tEXt") - 4), "cut.png"); }, 0, "image", "unreadable");
  expectParseError([&] { decode(good.substr(0, idat + 500), "cut.png"); }, 0, "image", "past the end");
  // A row filter type that does not exist (valid CRC and checksums).
  expectParseError([&] { decode(handWrittenPng(img, [](int y) { return y == 7 ? 5 : 0; }, 1000)); }, 0, "image",
                   "row filter");
  // Fewer rows of data than the header says: the stream does not inflate to the size.
  std::string shortData = handWrittenPng(img.rowRange(0, 30), [](int) { return 1; }, 1000);
  const std::string ihdr = be32(60) + be32(40) + std::string("\x08\x00\x00\x00\x00", 5);
  shortData.replace(8, 25, chunk("IHDR", ihdr));
  expectParseError([&] { decode(shortData); }, 0, "image", "inflate");
}

TEST(ImageIo, MalformedGrayPngsAreParseErrors) {
  // Every kind of damage the own decoder can meet is a ParseError naming the problem; none
  // crashes, hangs or allocates what the header promises before the data back it up.
  const std::string sig = "\x89PNG\r\n\x1a\n";
  const auto ihdr = [](std::uint32_t w, std::uint32_t h) {
    return chunk("IHDR", be32(w) + be32(h) + std::string("\x08\x00\x00\x00\x00", 5));
  };
  const auto rows = [](int w, int h) {  // filter byte 0 and mid-grey pixels
    std::string raw;
    for (int y = 0; y < h; ++y) raw += '\0' + std::string(static_cast<std::size_t>(w), '\x80');
    return raw;
  };
  const std::string iend = chunk("IEND", "");
  const std::string good = sig + ihdr(6, 4) + chunk("IDAT", zlibStored(rows(6, 4))) + iend;
  const cv::Mat ok = decode(good);
  ASSERT_EQ(ok.size(), cv::Size(6, 4));
  EXPECT_EQ(cv::norm(ok, cv::Mat(4, 6, CV_8UC1, cv::Scalar(128)), cv::NORM_INF), 0.0);
  // Zero-length IDAT chunks are legal (the stream is the concatenation of all IDAT data).
  EXPECT_EQ(decode(sig + ihdr(6, 4) + chunk("IDAT", "") + chunk("IDAT", zlibStored(rows(6, 4))) + iend).size(),
            cv::Size(6, 4));

  expectParseError([&] { decode(""); }, 0, "image", "empty");
  expectParseError([&] { decode(sig); }, 0, "image", "truncated PNG header");
  expectParseError([&] { decode(good.substr(0, 32)); }, 0, "image", "truncated PNG header");
  // Zero or huge dimensions, before anything is allocated.
  expectParseError([&] { decode(sig + ihdr(0, 4) + chunk("IDAT", zlibStored(rows(0, 4))) + iend); }, 0, "image",
                   "implausible image size 0x4");
  expectParseError([&] { decode(sig + ihdr(0xffffffffu, 0xffffffffu) + iend); }, 0, "image", "implausible");
  expectParseError([&] { decode(sig + ihdr(0x80000000u, 1) + iend); }, 0, "image", "implausible");
  // 10000 x 10000 is a plausible size, but 20 bytes of data cannot inflate to 100 MB.
  expectParseError([&] { decode(sig + ihdr(10000, 10000) + chunk("IDAT", zlibStored(rows(6, 1))) + iend); }, 0,
                   "image", "shorter than the header");
  // No image data at all, or only empty IDAT chunks.
  expectParseError([&] { decode(sig + ihdr(6, 4) + iend); }, 0, "image", "shorter than the header");
  expectParseError([&] { decode(sig + ihdr(6, 4) + chunk("IDAT", "") + iend); }, 0, "image", "shorter than the header");
  // IHDR CRC wrong.
  std::string badIhdr = good;
  badIhdr[32] = static_cast<char>(badIhdr[32] ^ 1);
  expectParseError([&] { decode(badIhdr); }, 0, "image", "IHDR CRC");
  // A chunk length that runs past the end of the file (0xffffffff and one byte too many).
  expectParseError([&] { decode(sig + ihdr(6, 4) + be32(0xffffffffu) + "IDAT" + std::string(40, 'x')); }, 0, "image",
                   "past the end");
  const std::string idat = chunk("IDAT", zlibStored(rows(6, 4)));
  std::string longer = sig + ihdr(6, 4) + be32(static_cast<std::uint32_t>(idat.size() - 11)) + idat.substr(4) + iend;
  expectParseError([&] { decode(longer.substr(0, longer.size() - iend.size())); }, 0, "image", "past the end");
  // More data than the header's rows, or fewer; a damaged Adler-32; a cut zlib stream; all with
  // valid chunk CRCs.
  expectParseError([&] { decode(sig + ihdr(6, 4) + chunk("IDAT", zlibStored(rows(6, 5))) + iend); }, 0, "image",
                   "inflate");
  expectParseError([&] { decode(sig + ihdr(6, 4) + chunk("IDAT", zlibStored(rows(6, 3))) + iend); }, 0, "image",
                   "inflate");
  std::string z = zlibStored(rows(6, 4));
  z.back() = static_cast<char>(z.back() ^ 1);
  expectParseError([&] { decode(sig + ihdr(6, 4) + chunk("IDAT", z) + iend); }, 0, "image", "inflate");
  z = zlibStored(rows(6, 4));
  expectParseError([&] { decode(sig + ihdr(6, 4) + chunk("IDAT", z.substr(0, z.size() - 9)) + iend); }, 0, "image",
                   "inflate");
  expectParseError([&] { decode(sig + ihdr(6, 4) + chunk("IDAT", "\x78\x01garbage") + iend); }, 0, "image", "inflate");
  // Filter byte 255 on the first row.
  std::string raw = rows(6, 4);
  raw[0] = '\xff';
  expectParseError([&] { decode(sig + ihdr(6, 4) + chunk("IDAT", zlibStored(raw)) + iend); }, 0, "image", "row filter");
  // A critical chunk a grey image must not have (PLTE), or an unknown one.
  expectParseError([&] { decode(sig + ihdr(6, 4) + chunk("PLTE", "abc") + idat + iend); }, 0, "image",
                   "unexpected critical chunk");
  expectParseError([&] { decode(sig + ihdr(6, 4) + idat + chunk("ABCD", "") + iend); }, 0, "image",
                   "unexpected critical chunk");

  // Every prefix and every single-bit flip of the good file: a 6x4 8-bit image or a ParseError.
  int decoded = 0, errors = 0;
  auto tryDecode = [&](const std::string& bytes) {
    try {
      const cv::Mat m = decode(bytes);
      EXPECT_EQ(m.type(), CV_8UC1);
      EXPECT_EQ(m.size(), cv::Size(6, 4));
      ++decoded;
    } catch (const ParseError&) {
      ++errors;
    }
  };
  for (std::size_t n = 0; n < good.size(); ++n) tryDecode(good.substr(0, n));
  EXPECT_EQ(decoded, 0);  // no prefix is a whole PNG (IEND missing)
  for (std::size_t i = 0; i < good.size(); ++i) {
    for (int bit = 0; bit < 8; ++bit) {
      std::string b = good;
      b[i] = static_cast<char>(b[i] ^ (1 << bit));
      tryDecode(b);
    }
  }
  std::printf("%zu prefixes and %zu bit flips of a %zu-byte PNG: %d decoded, %d ParseErrors\n", good.size(),
              good.size() * 8, good.size(), decoded, errors);
  EXPECT_EQ(decoded, 0);  // every flip hits a CRC, a length, a chunk type or the signature
  EXPECT_EQ(errors, static_cast<int>(good.size() * 9));
}

// ------------------------------------------------------------------------------------ dataset

TEST(EurocDataset, OpensTheStaticStereoClip) {
  const EurocDataset ds(kV101);
  EXPECT_EQ(ds.cameraCount(), 2);
  EXPECT_EQ(ds.frames().size(), 24u);
  EXPECT_EQ(ds.report().stereoPairs, 24u);
  EXPECT_EQ(ds.report().unpairedCam1, 0u);
  EXPECT_EQ(ds.imu().size(), 541u);
  EXPECT_EQ(ds.report().imuGaps.gaps, 0u);
  EXPECT_FALSE(ds.hasGroundTruth());
  EXPECT_DOUBLE_EQ(ds.cameraCalibration(1).intrinsics.fx, 457.587);
  for (const auto& f : ds.frames()) {
    ASSERT_TRUE(f.cam1.has_value());
    EXPECT_EQ(ds.cameraEntries(1)[*f.cam1].t_ns, f.t_ns);
  }
  const cv::Mat a = ds.loadImage(0, 0), b = ds.loadImage(1, 0);
  EXPECT_EQ(a.size(), b.size());
  const auto span = ds.imuCovering(ds.frames()[0].t_ns + 1, ds.frames()[1].t_ns + 1);
  ASSERT_GE(span.size(), 2u);
  EXPECT_LE(span.front().t_ns, ds.frames()[0].t_ns + 1);
  EXPECT_GE(span.back().t_ns, ds.frames()[1].t_ns + 1);
  EXPECT_LE(span.size(), 13u);
  EXPECT_NE(ds.report().summary().find("24 stereo pairs"), std::string::npos);
  // Opening the mav0 folder directly works too.
  EXPECT_EQ(EurocDataset(kV101 + "/mav0").frames().size(), 24u);
}

TEST(EurocDataset, BrokenDatasetsGiveClearErrors) {
  {
    DatasetCopy d("noimuyaml");
    fs::remove(d.mav0() / "imu0/sensor.yaml");
    expectParseError([&] { EurocDataset ds(d.root.string()); }, 0, "", "missing IMU calibration");
  }
  {
    DatasetCopy d("noimu");
    fs::remove(d.mav0() / "imu0/data.csv.gz");
    expectParseError([&] { EurocDataset ds(d.root.string()); }, 0, "", "missing file");
  }
  {
    DatasetCopy d("missingimage");
    fs::remove(d.mav0() / "cam1/data/1403715274812143104.png");  // line 12 of cam1/data.csv
    expectParseError([&] { EurocDataset ds(d.root.string()); }, 12, "filename", "image file missing");
    EurocOptions opt;
    opt.skipMissingImages = true;
    const EurocDataset ds(d.root.string(), opt);
    EXPECT_EQ(ds.report().missingImages[1], 1u);
    EXPECT_EQ(ds.report().stereoPairs, 23u);
    EXPECT_EQ(ds.report().unpairedCam0, 1u);
    EXPECT_FALSE(ds.frames()[10].cam1.has_value());
  }
  {
    DatasetCopy d("unsorted");
    std::string csv = readFile(d.mav0() / "cam0/data.csv");
    const std::string a = "1403715274362142976,1403715274362142976.png\n";
    const std::string b = "1403715274412143104,1403715274412143104.png\n";
    const auto pa = csv.find(a);
    csv.replace(pa, a.size() + b.size(), b + a);
    writeFile(d.mav0() / "cam0/data.csv", csv);
    expectParseError([&] { EurocDataset ds(d.root.string()); }, 4, "timestamp", "before the previous");
  }
  {
    DatasetCopy d("extracam1");
    std::ofstream(d.mav0() / "cam1/data.csv", std::ios::app) << "1403715275512143104,1403715275462142976.png\n";
    const EurocDataset ds(d.root.string());
    EXPECT_EQ(ds.report().unpairedCam1, 1u);
    EXPECT_EQ(ds.report().stereoPairs, 24u);
  }
  {
    DatasetCopy d("imugap");
    // Replace the gzip IMU by a plain data.csv with 30 samples removed.
    std::vector<std::string> lines;
    {
      gvins::LineReader r(kV101 + "/mav0/imu0/data.csv.gz");
      std::string l;
      while (r.next(l)) lines.push_back(l);
    }
    fs::remove(d.mav0() / "imu0/data.csv.gz");
    std::ofstream out(d.mav0() / "imu0/data.csv");
    for (std::size_t i = 0; i < lines.size(); ++i) {
      if (i < 300 || i >= 330) out << lines[i] << "\n";
    }
    out.close();
    const EurocDataset ds(d.root.string());
    EXPECT_EQ(ds.report().imuGaps.gaps, 1u);
    EXPECT_EQ(ds.report().imuGaps.missingSamples, 30u);
    EXPECT_NEAR(ds.report().imuGaps.largestGap_ns, 155'000'000, 1000);  // real stamps jitter by ns
    EXPECT_NE(ds.report().summary().find("1 gaps"), std::string::npos);
  }
  {
    DatasetCopy d("corruptimage");
    const fs::path img = d.mav0() / "cam0/data/1403715274312143104.png";
    fs::remove(img);
    writeFile(img, "garbage");
    const EurocDataset ds(d.root.string());  // exists: opening succeeds
    expectParseError([&] { ds.loadImage(0, 0); }, 0, "image", "not a PNG");
  }
  {
    DatasetCopy d("nocam0");
    fs::remove_all(d.mav0() / "cam0");
    expectParseError([&] { EurocDataset ds(d.root.string()); }, 0, "", "missing camera folder");
  }
  {
    DatasetCopy d("mono");
    fs::remove_all(d.mav0() / "cam1");
    const EurocDataset ds(d.root.string());
    EXPECT_EQ(ds.cameraCount(), 1);
    EXPECT_FALSE(ds.frames()[0].cam1.has_value());
    EurocOptions opt;
    opt.requireStereo = true;
    expectParseError([&] { EurocDataset s(d.root.string(), opt); }, 0, "", "stereo required");
  }
  {
    DatasetCopy d("gt");
    fs::create_directories(d.mav0() / "state_groundtruth_estimate0");
    fs::copy_file(kV102 + "/state_groundtruth_estimate0.csv.gz", d.mav0() / "state_groundtruth_estimate0/data.csv.gz");
    EXPECT_EQ(EurocDataset(d.root.string()).groundTruth().size(), 8001u);
  }
  expectParseError([] { EurocDataset ds("/nonexistent/dataset"); }, 0, "", "missing dataset folder");
}

// --------------------------------------------------------------------------------------- TUM

TEST(TumTrajectory, RoundTripKeepsNanosecondsAndRotation) {
  const fs::path p = fs::temp_directory_path() / ("gvins_vio_tum_" + std::to_string(::getpid()) + ".txt");
  std::vector<TumPose> poses;
  for (int i = 0; i < 50; ++i) {
    TumPose t;
    t.t_ns = 1403715274312143104LL + i * 50'000'001LL;
    t.p = {0.1 * i, -2.0 + i, 1e-6 * i};
    t.R = so3::exp(Eigen::Vector3d(0.1 * i, -0.05 * i, 3.0 - 0.1 * i));
    poses.push_back(t);
  }
  writeTumTrajectory(p.string(), poses);
  const auto back = readTumTrajectory(p.string());
  ASSERT_EQ(back.size(), poses.size());
  for (std::size_t i = 0; i < poses.size(); ++i) {
    EXPECT_EQ(back[i].t_ns, poses[i].t_ns);
    EXPECT_LT((back[i].p - poses[i].p).norm(), 1e-9);
    EXPECT_LT((back[i].R - poses[i].R).norm(), 1e-8);
  }
  fs::remove(p);
}

TEST(TumTrajectory, ReaderFormatsAndErrors) {
  // Whitespace or commas, comments, seconds or nanoseconds.
  const auto a = parseTumTrajectory("# comment\n1.5 1 2 3 0 0 0 1\n1.500000001\t1 2 3 0 0 1 0\n", "a.txt");
  ASSERT_EQ(a.size(), 2u);
  EXPECT_EQ(a[0].t_ns, 1'500'000'000);
  EXPECT_EQ(a[1].t_ns, 1'500'000'001);
  EXPECT_NEAR(a[1].R(0, 0), -1.0, 1e-12);  // 180 deg about z
  const auto b = parseTumTrajectory("10,1,2,3,0,0,0,1\n", "b.txt", TumTimeUnit::Nanoseconds);
  EXPECT_EQ(b.at(0).t_ns, 10);
  expectParseError([] { parseTumTrajectory("1 1 2 3 0 0 0\n", "t.txt"); }, 1, "qw", "expected 8");
  expectParseError([] { parseTumTrajectory("1 1 2 3 0 0 0 2\n", "t.txt"); }, 1, "qw", "norm");
  expectParseError([] { parseTumTrajectory("1 1 2 3 0 0 0 1\n1 1 2 3 0 0 0 1\n", "t.txt"); }, 2, "timestamp", "duplicate");
  expectParseError([] { parseTumTrajectory("2 1 2 3 0 0 0 1\n1 1 2 3 0 0 0 1\n", "t.txt"); }, 2, "timestamp");
  expectParseError([] { parseTumTrajectory("x 1 2 3 0 0 0 1\n", "t.txt"); }, 1, "timestamp");
  expectParseError([] { parseTumTrajectory("1e3 1 2 3 0 0 0 1\n", "t.txt"); }, 1, "timestamp");
  EXPECT_THROW(TumTrajectoryWriter("/nonexistent/dir/t.txt"), std::runtime_error);
}

TEST(TumTrajectory, CommentsBetweenPosesAreSkipped) {
  const fs::path p = fs::temp_directory_path() / "gvins_tum_comment_test.txt";
  {
    TumTrajectoryWriter w(p.string());
    w.write(1'000'000'000, Eigen::Matrix3d::Identity(), Eigen::Vector3d(1, 2, 3));
    w.comment("VIO reset: new frame below");
    w.write(2'000'000'000, Eigen::Matrix3d::Identity(), Eigen::Vector3d(4, 5, 6));
    EXPECT_THROW(w.comment("two\nlines"), std::invalid_argument);
    w.close();
  }
  std::ifstream in(p);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("\n# VIO reset: new frame below\n"), std::string::npos) << text;
  std::vector<std::size_t> fileMarks;
  const auto back = readTumTrajectory(p.string(), TumTimeUnit::Seconds, &fileMarks);
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(back[1].p, Eigen::Vector3d(4, 5, 6));
  // The reset mark sits before pose 1 (gvins-replay's "# VIO reset" comments only).
  EXPECT_EQ(fileMarks, std::vector<std::size_t>{1});
  fs::remove(p);
  std::vector<std::size_t> marks;
  const auto poses = parseTumTrajectory("# t x\n1 0 0 0 0 0 0 1\n# VIO reset a\n# VIO reset b\n2 0 0 0 0 0 0 1\n"
                                        "# other\n3 0 0 0 0 0 0 1\n# VIO reset c\n",
                                        "m.tum", TumTimeUnit::Seconds, &marks);
  EXPECT_EQ(poses.size(), 3u);
  EXPECT_EQ(marks, (std::vector<std::size_t>{1, 3}));
}
