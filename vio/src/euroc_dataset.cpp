#include "gvins/vio/euroc_dataset.hpp"

#include <algorithm>
#include <filesystem>
#include <sstream>

#include "gvins/base/parse_error.hpp"
#include "gvins/vio/image_io.hpp"

namespace gvins::vio {

namespace fs = std::filesystem;

namespace {
bool isDir(const fs::path& p) {
  std::error_code ec;
  return fs::is_directory(p, ec);
}
bool isFile(const fs::path& p) {
  std::error_code ec;
  return fs::is_regular_file(p, ec);
}
[[noreturn]] void missing(const fs::path& p, const std::string& what) {
  throw ParseError(p.string(), 0, "", "missing " + what);
}
// data.csv or data.csv.gz.
fs::path csvIn(const fs::path& dir, const std::string& base, bool required) {
  const fs::path plain = dir / base, gz = dir / (base + ".gz");
  if (isFile(plain)) return plain;
  if (isFile(gz)) return gz;
  if (required) missing(plain, "file (also looked for " + gz.filename().string() + ")");
  return {};
}
}  // namespace

EurocDataset::EurocDataset(const std::string& root, const EurocOptions& opt) {
  fs::path mav0 = fs::path(root) / "mav0";
  if (!isDir(mav0)) {
    if (isDir(fs::path(root) / "imu0") || isDir(fs::path(root) / "cam0")) {
      mav0 = fs::path(root);
    } else if (!isDir(root)) {
      missing(root, "dataset folder");
    } else {
      missing(mav0, "folder (EuRoC/ASL layout: <root>/mav0/{imu0,cam0,...})");
    }
  }
  mav0_ = mav0.string();

  // IMU.
  const fs::path imuDir = mav0 / "imu0";
  if (!isDir(imuDir)) missing(imuDir, "IMU folder");
  const fs::path imuYaml = imuDir / "sensor.yaml";
  if (!isFile(imuYaml)) missing(imuYaml, "IMU calibration file");
  imuCalib_ = readImuSensorYaml(imuYaml.string());
  imu_ = readImuCsv(csvIn(imuDir, "data.csv", true).string(), imuCalib_.noise.rate_hz, &report_.imuGaps);
  if (imu_.size() < 2) throw ParseError(csvIn(imuDir, "data.csv", true).string(), 0, "", "fewer than 2 IMU samples");

  // Cameras.
  for (int i = 0; i < 2; ++i) {
    const fs::path dir = mav0 / ("cam" + std::to_string(i));
    if (!isDir(dir)) {
      if (i == 0 && !opt.requireCamera) break;
      if (i == 0) missing(dir, "camera folder");
      if (opt.requireStereo) missing(dir, "second camera folder (stereo required)");
      break;
    }
    Camera cam;
    cam.dir = dir.string();
    const fs::path yaml = dir / "sensor.yaml";
    if (!isFile(yaml)) missing(yaml, "camera calibration file");
    cam.calib = readCameraSensorYaml(yaml.string());
    cam.calib.name = "cam" + std::to_string(i);
    const fs::path csv = csvIn(dir, "data.csv", true);
    cam.entries = readCameraCsv(csv.string());
    if (cam.entries.empty()) throw ParseError(csv.string(), 0, "", "no images listed");
    if (opt.checkImageFiles) {
      std::vector<CameraCsvEntry> kept;
      kept.reserve(cam.entries.size());
      for (auto& e : cam.entries) {
        const fs::path img = dir / "data" / e.filename;
        if (isFile(img)) {
          kept.push_back(std::move(e));
        } else if (opt.skipMissingImages) {
          ++report_.missingImages[i];
        } else {
          throw ParseError(csv.string(), e.line, "filename", "image file missing: " + img.string());
        }
      }
      cam.entries = std::move(kept);
      if (cam.entries.empty()) throw ParseError(csv.string(), 0, "", "none of the listed images exists");
    }
    cams_.push_back(std::move(cam));
  }

  // Stereo pairing by time stamp (both lists are strictly increasing).
  static const std::vector<CameraCsvEntry> kNoImages;
  const auto& c0 = cams_.empty() ? kNoImages : cams_[0].entries;
  report_.cam0Images = c0.size();
  std::size_t j = 0;
  for (std::size_t i = 0; i < c0.size(); ++i) {
    EurocFrame f;
    f.t_ns = c0[i].t_ns;
    f.cam0 = i;
    if (cams_.size() > 1) {
      const auto& c1 = cams_[1].entries;
      while (j < c1.size() && c1[j].t_ns < f.t_ns - opt.stereoTolerance_ns) ++j;
      if (j < c1.size() && c1[j].t_ns <= f.t_ns + opt.stereoTolerance_ns) {
        f.cam1 = j++;
        ++report_.stereoPairs;
      }
    }
    frames_.push_back(f);
  }
  if (cams_.size() > 1) {
    report_.cam1Images = cams_[1].entries.size();
    report_.unpairedCam1 = report_.cam1Images - report_.stereoPairs;
    report_.unpairedCam0 = report_.cam0Images - report_.stereoPairs;
  }

  // Optional files.
  const fs::path body = mav0 / "body.yaml";
  (void)body;  // body.yaml only carries a comment in EuRoC; nothing to read.
  const fs::path gtDir = mav0 / "state_groundtruth_estimate0";
  if (isDir(gtDir)) {
    const fs::path gt = csvIn(gtDir, "data.csv", false);
    if (!gt.empty()) gt_ = readGroundTruthCsv(gt.string());
  }
  report_.groundTruthSamples = gt_.size();
}

std::span<const ImuSample> EurocDataset::imuCovering(std::int64_t t0, std::int64_t t1) const {
  auto lo = std::upper_bound(imu_.begin(), imu_.end(), t0,
                             [](std::int64_t t, const ImuSample& s) { return t < s.t_ns; });
  if (lo != imu_.begin()) --lo;
  auto hi = std::lower_bound(imu_.begin(), imu_.end(), t1,
                             [](const ImuSample& s, std::int64_t t) { return s.t_ns < t; });
  if (hi != imu_.end()) ++hi;
  if (hi <= lo) return {};
  return {&*lo, static_cast<std::size_t>(hi - lo)};
}

std::string EurocDataset::imagePath(int cam, std::size_t entry) const {
  const Camera& c = cams_.at(static_cast<std::size_t>(cam));
  return (fs::path(c.dir) / "data" / c.entries.at(entry).filename).string();
}

cv::Mat EurocDataset::loadImage(int cam, std::size_t entry) const {
  const auto& k = cams_.at(static_cast<std::size_t>(cam)).calib.intrinsics;
  return readGrayImage(imagePath(cam, entry), k.width, k.height);
}

std::string EurocReport::summary() const {
  std::ostringstream s;
  s << "IMU: " << imuGaps.samples << " samples, " << imuGaps.gaps << " gaps";
  if (imuGaps.gaps > 0) {
    s << " (~" << imuGaps.missingSamples << " samples missing, largest " << imuGaps.largestGap_ns * 1e-6
      << " ms after t=" << imuGaps.largestGapStart_ns << ")";
  }
  s << "\ncam0: " << cam0Images << " images";
  if (cam1Images > 0) {
    s << "\ncam1: " << cam1Images << " images; " << stereoPairs << " stereo pairs, " << unpairedCam0
      << " unpaired cam0, " << unpairedCam1 << " unpaired cam1";
  }
  if (missingImages[0] + missingImages[1] > 0) {
    s << "\nskipped missing images: cam0 " << missingImages[0] << ", cam1 " << missingImages[1];
  }
  s << "\nground truth: " << groundTruthSamples << " samples\n";
  return s.str();
}

}  // namespace gvins::vio
