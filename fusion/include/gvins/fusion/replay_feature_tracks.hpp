// Simulated feature tracks of a feature-only dataset (gvins-sim with cameras.output: features):
// mav0/camN/features.csv, one observation per line
//   #timestamp [ns],landmark_id,u [px],v [px]
// (distorted pixel coordinates). gvins-replay turns them into FeatureFrames (the landmark id is
// the track id; cam1 observations of the same landmark at the same stamp are the stereo match)
// instead of running the image front end.
// Errors: gvins::ParseError naming file, line and field (malformed numbers, wrong column count,
// decreasing stamps, a landmark listed twice at one stamp).
//
// FeatureTrackDatasetWriter is the inverse: it records the tracks of the image front end as a
// feature-only dataset (gvins-replay --save-tracks DIR), so that the estimator can be replayed,
// compared or tuned on exactly the same tracks without running the front end again.
#pragma once

#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "gvins/vio/camera_model.hpp"
#include "gvins/vio/feature_frame.hpp"

namespace gvins::fusion {

struct TrackObservation {
  std::uint64_t id = 0;
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();
};

/// All observations of one stamp.
struct TrackStamp {
  std::int64_t t_ns = 0;
  std::vector<TrackObservation> obs;
};

std::vector<TrackStamp> readFeatureTracksCsv(const std::string& path);
std::vector<TrackStamp> parseFeatureTracksCsv(std::string_view text, const std::string& name);
/// `tracks` with an empty stamp added for every image stamp in `images` (sorted) that has no
/// track row: a camera too close to the ground, or over a featureless surface, still delivers
/// frames, and the estimator sees them (standstill initialisation from the IMU, docs/replay.md).
std::vector<TrackStamp> withImageStamps(std::vector<TrackStamp> tracks, const std::vector<std::int64_t>& images);

/// Builds FeatureFrames from cam0 (and optionally cam1) tracks: normalised coordinates through
/// the camera models, track lengths counted over consecutive cam0 stamps, stereo where cam1 has
/// the landmark at the same stamp. `cam1`/`model1` may be null.
class FeatureTrackFrames {
 public:
  FeatureTrackFrames(std::vector<TrackStamp> cam0, const vio::CameraModel& model0,
                     std::vector<TrackStamp> cam1 = {}, const vio::CameraModel* model1 = nullptr);
  std::size_t size() const { return cam0_.size(); }
  std::int64_t stamp(std::size_t i) const { return cam0_.at(i).t_ns; }
  /// Frames must be requested in order (track lengths depend on the previous frame).
  vio::FeatureFrame frame(std::size_t i);

 private:
  std::vector<TrackStamp> cam0_, cam1_;
  const vio::CameraModel* model0_;
  const vio::CameraModel* model1_;
  std::size_t cam1Next_ = 0;
  std::vector<std::pair<std::uint64_t, int>> lengths_;  ///< sorted by id: track length so far
};

/// Writes a feature-only dataset folder `dir` next to an image dataset: mav0/camN/features.csv
/// from FeatureFrames (pixel0 → cam0, pixel1 of stereo observations → cam1; pixels with 6
/// decimals, rows of a stamp by increasing id) and symbolic links to everything else of the
/// source dataset (IMU, camN/data.csv and sensor.yaml, ground truth, gnss/, dataset.yaml), not
/// to the images. A frame without features leaves no row (its stamp is then skipped by a replay
/// of the tracks). Throws std::runtime_error naming the path if `dir` exists and is not empty or
/// a file cannot be created.
class FeatureTrackDatasetWriter {
 public:
  FeatureTrackDatasetWriter(const std::string& sourceDataset, const std::string& dir, int cameras);
  ~FeatureTrackDatasetWriter();
  FeatureTrackDatasetWriter(const FeatureTrackDatasetWriter&) = delete;
  FeatureTrackDatasetWriter& operator=(const FeatureTrackDatasetWriter&) = delete;
  void write(const vio::FeatureFrame& frame);
  /// Flushes and closes the files; throws std::runtime_error on a write error.
  void close();

 private:
  struct File;
  std::vector<std::unique_ptr<File>> files_;  // one per camera
  std::vector<std::pair<std::uint64_t, std::size_t>> order_;
};

}  // namespace gvins::fusion
