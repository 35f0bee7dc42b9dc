// The named stages of runReplay (replay_pipeline.hpp), private to gvins_fusion:
//
//   ReplayFrames     the dataset, its frames (camera or camera-less) and the requested time range
//   GnssInputs       rover, base, navigation data, precise products and SSR corrections
//   CameraInput      the frames in time order: feature tracks, images through the loader and front
//                    end threads, or empty camera-less frames
//   (replay_pipeline.cpp: outputs, the per-frame loop: IMU, estimator, GNSS epochs, timing)
//   evaluateLocal / evaluateGlobal   accuracy against the dataset's truth at the end
#pragma once

#include <atomic>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "gvins/base/observation.hpp"
#include "gvins/ephemeris/ephemeris_store.hpp"
#include "gvins/fusion/replay_feature_tracks.hpp"
#include "gvins/fusion/replay_pipeline.hpp"
#include "gvins/gnss/base_reader.hpp"
#include "gvins/vio/camera_model.hpp"
#include "gvins/vio/euroc_dataset.hpp"
#include "gvins/vio/frontend_thread.hpp"
#include "gvins/vio/trajectory_metrics.hpp"

namespace gvins::fusion::detail {

/// The dataset and the frames to replay. Throws ParseError for an IMU log of fewer than two
/// samples or a dataset without frames, std::invalid_argument for an empty time range.
class ReplayFrames {
 public:
  ReplayFrames(const std::string& dataset, const ReplayOptions& opt, ReplaySummary& sum);
  ReplayFrames(const ReplayFrames&) = delete;
  ReplayFrames& operator=(const ReplayFrames&) = delete;

  const std::filesystem::path mav0;     ///< DATASET/mav0, or DATASET itself
  const bool tracks;                    ///< replayed from camN/features.csv
  const vio::EurocDataset ds;
  const std::vector<vio::EurocFrame>& frames() const { return cameraLess_ ? cameraLessFrames_ : ds.frames(); }
  bool cameraLess() const { return cameraLess_; }
  std::int64_t tFirst = 0, tLast = 0;   ///< requested range (ns, sensor clock)
  std::vector<std::size_t> selected;    ///< indices into frames() inside the range
  std::string imuFile() const { return (mav0 / "imu0" / "data.csv").string(); }

 private:
  bool cameraLess_ = false;
  std::vector<vio::EurocFrame> cameraLessFrames_;
};

/// The GNSS files of a replay and the epochs read ahead of the estimator.
struct GnssInputs {
  std::unique_ptr<BaseReader> rover;  // RINEX or a u-blox UBX log
  std::unique_ptr<BaseReader> base;   // RINEX, an RTCM 3 log or a UBX log
  bool basePositionSet = false;
  EphemerisStore nav;
  ObsEpoch nextRover, nextBase, currentBase;
  bool haveRover = false, haveBase = false, haveCurrentBase = false;

  /// Opens the inputs of ReplayOptions (defaults: the dataset's gnss folder), reads the
  /// navigation data and products into `nav`, sets the base position of `gnss`, and reads the
  /// first rover and base epochs.
  void open(const std::string& dataset, const ReplayOptions& opt, ReplayGnss& gnss, ReplaySummary& sum);
  /// Makes currentBase the last base epoch at or before the next rover epoch.
  void advanceBase();
  /// An RTCM base whose station message arrived after the start: its position to `gnss`, once.
  void updateBasePosition(ReplayGnss& gnss);
  /// Warnings about rover epochs or messages skipped while reading (stderr).
  void reportSkipped() const;

 private:
  void loadNavigation(const std::filesystem::path& gnssDir, const std::string& roverPath, const std::string& basePath,
                      const ReplayOptions& opt);
  void loadPreciseProducts(const std::filesystem::path& gnssDir, const ReplayOptions& opt, ReplaySummary& sum);
  void loadSsr(const ReplayOptions& opt, ReplaySummary& sum);
  void openBase(const std::string& basePath, const ReplayOptions& opt, ReplayGnss& gnss);
};

/// The camera frames of the selected range in time order. Images are decoded on a loader thread
/// and tracked on the front end thread; the destructor stops and joins both.
class CameraInput {
 public:
  CameraInput(const std::string& dataset, const ReplayFrames& frames, const ReplayOptions& opt);
  ~CameraInput();
  CameraInput(const CameraInput&) = delete;
  CameraInput& operator=(const CameraInput&) = delete;

  /// Number of frames next() delivers at most.
  std::size_t total() const;
  /// The next frame; nullopt at the end.
  std::optional<vio::FeatureFrame> next();
  /// Waits for the loader thread, rethrows its error, closes the --save-tracks dataset.
  void finish();
  std::size_t badImages() const { return badImages_.load(); }

 private:
  void startImages(const std::string& dataset, const ReplayOptions& opt);

  const ReplayFrames& frames_;
  std::size_t cursor_ = 0;
  std::unique_ptr<FeatureTrackFrames> trackFrames_;
  std::vector<std::size_t> trackIndex_;  // tracks: the selected stamp indices
  std::unique_ptr<vio::CameraModel> model0_, model1_;
  std::unique_ptr<vio::FrontendThread> fe_;
  std::unique_ptr<FeatureTrackDatasetWriter> trackWriter_;
  std::thread loader_;
  std::exception_ptr loaderError_;
  std::mutex loaderMutex_;
  std::atomic<std::size_t> badImages_{0};
};

/// Key figures of an evaluation (metrics.csv).
ReplaySummary::Accuracy accuracyOf(const vio::EvaluationResult& r);

/// The local trajectory (VIO world frame) against the dataset's ground truth, 4-DoF aligned:
/// the table, the figures and the SVG plots (eval_*) in `out`.
void evaluateLocal(const vio::EurocDataset& ds, const std::vector<vio::TrajectorySample>& localTrack,
                   const std::vector<vio::PoseCovariance>& covs, const std::filesystem::path& out, ReplaySummary& sum);

/// The GNSS antenna solutions against the true antenna track (--truth-pos, or
/// DATASET/truth/groundtruth_ecef.csv when it exists), ENU, no alignment; `fromTight`: the track
/// starts at the first tightly coupled update.
void evaluateGlobal(const std::string& dataset, const ReplayOptions& opt, const std::vector<EcefTruthSample>& track,
                    bool fromTight, const std::filesystem::path& out, ReplaySummary& sum);

}  // namespace gvins::fusion::detail
