// Dataset and camera input of the replay (replay_stages.hpp): the frames of the requested range,
// from feature tracks, from images through the loader and front end threads, or camera-less.
#include <cmath>
#include <limits>
#include <stdexcept>

#include "gvins/base/parse_error.hpp"
#include "replay_stages.hpp"

namespace gvins::fusion::detail {

namespace fs = std::filesystem;

namespace {

fs::path mav0Of(const std::string& dataset) {
  const fs::path mav0 = fs::path(dataset) / "mav0";
  return fs::is_directory(mav0) ? mav0 : fs::path(dataset);
}

vio::EurocOptions datasetOptions(bool tracks, const ReplayOptions& opt) {
  vio::EurocOptions eo;
  eo.checkImageFiles = !tracks;
  eo.skipMissingImages = opt.skipMissingImages;
  eo.requireCamera = false;
  return eo;
}

}  // namespace

ReplayFrames::ReplayFrames(const std::string& dataset, const ReplayOptions& opt, ReplaySummary& sum)
    : mav0(mav0Of(dataset)),
      tracks(opt.useFeatureTracks && fs::exists(mav0 / "cam0" / "features.csv")),
      ds(dataset, datasetOptions(tracks, opt)) {
  sum.featureTracks = tracks;
  sum.skippedMissingImages = ds.report().missingImages[0] + ds.report().missingImages[1];
  const auto& imu = ds.imu();
  if (imu.size() < 2) throw ParseError((mav0 / "imu0" / "data.csv").string(), 0, "imu0", "fewer than 2 IMU samples");

  // A camera-less rig (no cam0 folder) gets frames without features at cameraLessRate_hz over
  // the IMU log: the estimator's clones, IMU propagation and GNSS rows run as with a camera that
  // sees nothing.
  cameraLess_ = ds.cameraCount() == 0;
  sum.cameraLess = cameraLess_;
  if (cameraLess_) {
    if (!(opt.cameraLessRate_hz > 0.0)) throw std::invalid_argument("runReplay: camera-less frame rate must be positive");
    const auto period = static_cast<std::int64_t>(std::llround(1e9 / opt.cameraLessRate_hz));
    for (std::int64_t t = imu.front().t_ns + period; t <= imu.back().t_ns; t += period) cameraLessFrames_.push_back({t, 0, {}});
  }
  const auto& all = frames();
  sum.frames = all.size();
  if (all.empty()) throw ParseError((mav0 / "cam0" / "data.csv").string(), 0, "cam0", "no camera frames");
  tFirst = all.front().t_ns + static_cast<std::int64_t>(opt.start_s * 1e9);
  tLast = opt.duration_s > 0.0 ? tFirst + static_cast<std::int64_t>(opt.duration_s * 1e9)
                               : std::numeric_limits<std::int64_t>::max();
  for (std::size_t i = 0; i < all.size(); ++i)
    if (all[i].t_ns >= tFirst && all[i].t_ns <= tLast) selected.push_back(i);
  if (selected.empty()) throw std::invalid_argument("no frames in the requested time range");
}

CameraInput::CameraInput(const std::string& dataset, const ReplayFrames& frames, const ReplayOptions& opt)
    : frames_(frames) {
  const fs::path& mav0 = frames.mav0;
  const vio::EurocDataset& ds = frames.ds;
  if (frames.tracks && !opt.saveTracksDir.empty())
    throw std::invalid_argument("--save-tracks needs the image front end; this dataset is replayed from its feature tracks (add --images)");
  if (frames.tracks) {
    model0_ = std::make_unique<vio::CameraModel>(ds.cameraCalibration(0).intrinsics);
    std::vector<TrackStamp> c1;
    if (ds.cameraCount() > 1 && fs::exists(mav0 / "cam1" / "features.csv")) {
      model1_ = std::make_unique<vio::CameraModel>(ds.cameraCalibration(1).intrinsics);
      c1 = readFeatureTracksCsv((mav0 / "cam1" / "features.csv").string());
    }
    std::vector<std::int64_t> imageStamps;
    for (const vio::EurocFrame& fr : frames.frames()) imageStamps.push_back(fr.t_ns);
    trackFrames_ = std::make_unique<FeatureTrackFrames>(
        withImageStamps(readFeatureTracksCsv((mav0 / "cam0" / "features.csv").string()), imageStamps), *model0_,
        std::move(c1), model1_.get());
    for (std::size_t i = 0; i < trackFrames_->size(); ++i)
      if (trackFrames_->stamp(i) >= frames.tFirst && trackFrames_->stamp(i) <= frames.tLast) trackIndex_.push_back(i);
  } else if (!frames.cameraLess()) {
    startImages(dataset, opt);
  }
}

void CameraInput::startImages(const std::string& dataset, const ReplayOptions& opt) {
  const vio::EurocDataset& ds = frames_.ds;
  const bool stereo = ds.cameraCount() > 1 && opt.frontend.useStereo;
  if (!opt.saveTracksDir.empty())
    trackWriter_ = std::make_unique<FeatureTrackDatasetWriter>(dataset, opt.saveTracksDir, stereo ? 2 : 1);
  fe_ = std::make_unique<vio::FrontendThread>(
      vio::StereoFrontend(opt.frontend, ds.cameraCalibration(0), stereo ? &ds.cameraCalibration(1) : nullptr));
  const bool skipBad = opt.skipBadImages;
  loader_ = std::thread([this, stereo, skipBad] {
    const vio::EurocDataset& data = frames_.ds;
    try {
      for (std::size_t k : frames_.selected) {
        const vio::EurocFrame& fr = frames_.frames()[k];
        vio::StereoImages im;
        im.t_ns = fr.t_ns;
        try {
          im.left = data.loadImage(0, fr.cam0);
          if (stereo && fr.cam1) im.right = data.loadImage(1, *fr.cam1);
        } catch (const ParseError&) {
          if (!skipBad) throw;
          ++badImages_;
          continue;
        }
        if (!fe_->push(std::move(im))) return;
      }
      fe_->finish();
    } catch (...) {
      std::lock_guard<std::mutex> lock(loaderMutex_);
      loaderError_ = std::current_exception();
      fe_->stop();
    }
  });
}

CameraInput::~CameraInput() {
  if (fe_) fe_->stop();
  if (loader_.joinable()) loader_.join();
}

std::size_t CameraInput::total() const { return frames_.tracks ? trackIndex_.size() : frames_.selected.size(); }

std::optional<vio::FeatureFrame> CameraInput::next() {
  if (frames_.tracks) {
    if (cursor_ >= trackIndex_.size()) return std::nullopt;
    return trackFrames_->frame(trackIndex_[cursor_++]);
  }
  if (frames_.cameraLess()) {
    if (cursor_ >= frames_.selected.size()) return std::nullopt;
    vio::FeatureFrame f{frames_.frames()[frames_.selected[cursor_]].t_ns, cursor_, {}, {}};
    ++cursor_;
    return f;
  }
  std::optional<vio::FeatureFrame> frame = fe_->pop();
  if (frame && trackWriter_) trackWriter_->write(*frame);
  return frame;
}

void CameraInput::finish() {
  if (loader_.joinable()) loader_.join();
  {
    std::lock_guard<std::mutex> lock(loaderMutex_);
    if (loaderError_) std::rethrow_exception(loaderError_);
  }
  if (trackWriter_) trackWriter_->close();
}

}  // namespace gvins::fusion::detail
