// A dataset folder in the EuRoC/ASL layout (Burri et al., IJRR 2016), as recorded by EuRoC and
// written by gvins-sim:
//   <root>/mav0/imu0/{data.csv[.gz], sensor.yaml}
//   <root>/mav0/cam0/{data.csv, sensor.yaml, data/<t>.png}   cam1/ likewise for stereo
//   <root>/mav0/body.yaml                                    (optional)
//   <root>/mav0/state_groundtruth_estimate0/data.csv[.gz]    (optional)
// `root` may also be the mav0 folder itself. Opening reads the calibration, the IMU log (kept in
// memory: 56 bytes per sample), the image lists and the ground truth, and checks that every
// listed image exists; images are decoded only on request (never all in memory).
// Every problem is a gvins::ParseError naming the file, line and field: missing files or
// folders, malformed lines, repeated or decreasing time stamps, missing or unreadable images,
// an image size that differs from sensor.yaml. IMU gaps and unpaired stereo images are counted
// in report() instead.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "gvins/vio/euroc_csv.hpp"
#include "gvins/vio/sensor_yaml.hpp"

namespace gvins::vio {

struct EurocOptions {
  /// cam0/cam1 images whose stamps differ by at most this are a stereo pair.
  std::int64_t stereoTolerance_ns = 1'000'000;
  /// Stat every listed image at open time (a missing image is then an error at open, naming
  /// the data.csv line, rather than later during replay).
  bool checkImageFiles = true;
  /// With checkImageFiles: drop (and count in report()) listed images whose file is missing
  /// instead of failing.
  bool skipMissingImages = false;
  /// Refuse a dataset without a cam1 folder.
  bool requireStereo = false;
  /// Refuse a dataset without a cam0 folder; false accepts an IMU-only (camera-less) rig:
  /// cameraCount() 0, no frames.
  bool requireCamera = true;
};

/// One camera time step: the cam0 image and, if paired, the cam1 image (indices into
/// cameraEntries()).
struct EurocFrame {
  std::int64_t t_ns = 0;
  std::size_t cam0 = 0;
  std::optional<std::size_t> cam1;
};

struct EurocReport {
  ImuGapReport imuGaps;
  std::size_t cam0Images = 0, cam1Images = 0;
  std::size_t stereoPairs = 0;
  std::size_t unpairedCam0 = 0, unpairedCam1 = 0;
  std::size_t missingImages[2] = {0, 0};  ///< dropped with EurocOptions::skipMissingImages
  std::size_t groundTruthSamples = 0;
  /// Multi-line human-readable summary.
  std::string summary() const;
};

class EurocDataset {
 public:
  explicit EurocDataset(const std::string& root, const EurocOptions& options = {});

  /// The mav0 folder.
  const std::string& mav0() const { return mav0_; }
  int cameraCount() const { return static_cast<int>(cams_.size()); }
  const CameraCalibration& cameraCalibration(int cam) const { return cams_.at(static_cast<std::size_t>(cam)).calib; }
  const std::vector<CameraCsvEntry>& cameraEntries(int cam) const {
    return cams_.at(static_cast<std::size_t>(cam)).entries;
  }
  const ImuCalibration& imuCalibration() const { return imuCalib_; }
  const std::vector<ImuSample>& imu() const { return imu_; }
  /// Smallest run of samples with first stamp <= t0 and last >= t1 (clipped to the log: check
  /// the ends before propagating).
  std::span<const ImuSample> imuCovering(std::int64_t t0_ns, std::int64_t t1_ns) const;
  /// cam0 time steps in time order, with the cam1 partner when there is one.
  const std::vector<EurocFrame>& frames() const { return frames_; }

  std::string imagePath(int cam, std::size_t entry) const;
  /// Decodes one image as 8-bit gray (ParseError if unreadable or of the wrong size).
  cv::Mat loadImage(int cam, std::size_t entry) const;

  bool hasGroundTruth() const { return !gt_.empty(); }
  const std::vector<GroundTruthSample>& groundTruth() const { return gt_; }
  const EurocReport& report() const { return report_; }

 private:
  struct Camera {
    CameraCalibration calib;
    std::vector<CameraCsvEntry> entries;
    std::string dir;
  };
  std::string mav0_;
  std::vector<Camera> cams_;
  ImuCalibration imuCalib_;
  std::vector<ImuSample> imu_;
  std::vector<EurocFrame> frames_;
  std::vector<GroundTruthSample> gt_;
  EurocReport report_;
};

}  // namespace gvins::vio
