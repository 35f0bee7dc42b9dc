// runReplay (replay_pipeline.hpp) as a pipeline of named stages: the dataset and its frames
// (ReplayFrames), the GNSS inputs (GnssInputs), the output files (ReplayOutputs), the camera
// input (CameraInput), the frame loop (FrameLoop: IMU, estimator, GNSS epochs, timing), then the
// closing figures and the evaluations (replay_stages.hpp).
#include "gvins/fusion/replay_pipeline.hpp"

#include <algorithm>
#include <chrono>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>

#include <sys/resource.h>

#include "gvins/base/geodetic.hpp"
#include "gvins/base/parse_error.hpp"
#include "gvins/gnss/kml_writer.hpp"
#include "gvins/gnss/nmea_writer.hpp"
#include "gvins/gnss/pos_writer.hpp"
#include "gvins/vio/tum_trajectory.hpp"
#include "replay_stages.hpp"

namespace gvins::fusion {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

double msSince(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

GpsTime gpsFromNs(std::int64_t t_ns) {
  return GpsTime::fromSeconds(t_ns / 1'000'000'000, static_cast<double>(t_ns % 1'000'000'000) * 1e-9);
}

class OutFile {
 public:
  explicit OutFile(const fs::path& p) : path_(p.string()), f_(p, std::ios::binary) {
    if (!f_) throw std::runtime_error("cannot create output file " + path_);
  }
  std::ofstream& out() { return f_; }
  void close() {
    f_.close();
    if (!f_) throw std::runtime_error("error writing output file " + path_);
  }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::ofstream f_;
};

fs::path makeOutputFolder(const ReplayOptions& opt) {
  if (opt.outDir.empty()) throw std::invalid_argument("runReplay: no output folder");
  std::error_code ec;
  fs::create_directories(opt.outDir, ec);
  if (!fs::is_directory(opt.outDir)) throw std::runtime_error("cannot create output folder " + opt.outDir);
  return fs::path(opt.outDir);
}

/// The output files of a replay (docs/replay.md): the local trajectory, its covariances and the
/// timing always; the global solutions (.pos, ECEF, KML, per-epoch rows, NMEA) with GNSS.
class ReplayOutputs {
 public:
  ReplayOutputs(const fs::path& out, const std::string& dataset, const ReplayOptions& opt, bool gnss)
      : out_(out),
        tum((out / "trajectory.tum").string(),
            "t x y z qx qy qz qw  (IMU pose in the VIO world frame; gvins-replay " + opt.modeName + ")"),
        cov((out / "trajectory.cov.csv").string()),
        timing(out / "timing.csv") {
    timing.out() << "# t [ns],frame,features,frontend_ms,estimator_ms,gnss_ms,gnss_epochs,initialized,updated,msckf_features,slam_features,state_dim\n";
    if (gnss && !opt.nmeaPath.empty()) {
      nmeaFile_ = std::make_unique<OutFile>(opt.nmeaPath);
      nmeaWriter_ = std::make_unique<NmeaWriter>(nmeaFile_->out());
    }
    if (!gnss) return;
    posFile_ = std::make_unique<OutFile>(out / "global.pos");
    PosWriterOptions po;
    po.headerFields = {{"mode", opt.modeName}, {"dataset", dataset}};
    posWriter_ = std::make_unique<PosWriter>(posFile_->out(), po);
    ecefFile_ = std::make_unique<OutFile>(out / "global_ecef.csv");
    ecefFile_->out() << "# gps_week,tow [s],x [m],y [m],z [m],vx [m/s],vy [m/s],vz [m/s],rtk_fixed  (GNSS antenna, ECEF)\n";
    epochFile_ = std::make_unique<OutFile>(out / "gnss_epochs.csv");
    epochFile_->out() << "# gps_week,tow [s],stage,psr_used,psr_rejected,dopp_used,dopp_rejected,dpsr_used,dpsr_rejected,"
                         "ddcp_used,ddcp_rejected,vel_used,vel_rejected,updated,rtk_fixed,reset,chi2,dof,gnss_ms,"
                         "phase_used,phase_rejected,ambiguities\n";
  }

  /// gnss_epochs.csv: one row per processed epoch.
  void writeEpoch(const GpsTime& t, const GnssEpochReport& r, double ms) {
    char b[400];
    std::snprintf(b, sizeof b, "%d,%.3f,%s,%d,%d,%d,%d,%d,%d,%d,%d,%d,%d,%d,%d,%d,%.3f,%d,%.3f,%d,%d,%d\n", t.week(), t.tow(),
                  toString(r.stage), r.psr.used, r.psr.rejected, r.dopp.used, r.dopp.rejected, r.dpsr.used,
                  r.dpsr.rejected, r.ddcp.used, r.ddcp.rejected, r.vel.used, r.vel.rejected, r.updated ? 1 : 0,
                  r.rtkFixed ? 1 : 0, r.reset ? 1 : 0, r.chi2, r.dof, ms, r.phase.used, r.phase.rejected, r.ambiguities);
    epochFile_->out() << b;
  }

  /// The antenna solution of an epoch to global.pos, NMEA, global_ecef.csv and the KML track.
  PositionSolution writeSolution(const GpsTime& t, const ReplayGnssOutcome& o) {
    const GnssEpochReport& r = o.report;
    PositionSolution ps;
    ps.time = t;
    ps.position = *r.antennaEcef;
    ps.positionCovariance = o.antennaCovarianceEcef;
    ps.quality = r.rtkFixed ? SolutionQuality::Fix
                            : ((r.dpsr.used + r.ddcp.used) > 0 ? SolutionQuality::Float : SolutionQuality::Single);
    ps.numSatellites = std::max({r.psr.used, r.dopp.used, r.dpsr.used, r.ddcp.used, r.phase.used});
    ps.velocity = r.antennaVelocityEcef;
    ps.velocityCovariance = o.antennaVelocityCovarianceEcef;
    posWriter_->write(ps);
    if (nmeaWriter_) nmeaWriter_->write(ps);
    const Eigen::Vector3d v = r.antennaVelocityEcef ? *r.antennaVelocityEcef : Eigen::Vector3d::Zero();
    char b[400];
    std::snprintf(b, sizeof b, "%d,%.3f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%d\n", t.week(), t.tow(), ps.position.x(),
                  ps.position.y(), ps.position.z(), v.x(), v.y(), v.z(), r.rtkFixed ? 1 : 0);
    ecefFile_->out() << b;
    kml_.push_back(ecefToGeodetic(ps.position));
    return ps;
  }

  /// Closes trajectory.tum, trajectory.cov.csv and timing.csv; their names to sum.files.
  void closeLocal(ReplaySummary& sum) {
    tum.close();
    cov.close();
    timing.close();
    sum.files = {(out_ / "trajectory.tum").string(), (out_ / "trajectory.cov.csv").string(), timing.path()};
  }

  /// Closes the GNSS outputs and writes track.kml; their names to sum.files.
  void closeGnss(const ReplayOptions& opt, ReplaySummary& sum) {
    posWriter_->finish();
    posFile_->close();
    ecefFile_->close();
    epochFile_->close();
    OutFile kml(out_ / "track.kml");
    writeKmlTrack(kml.out(), kml_, "gvins-replay " + opt.modeName);
    kml.close();
    sum.files.insert(sum.files.end(), {posFile_->path(), ecefFile_->path(), (out_ / "track.kml").string(), epochFile_->path()});
    if (nmeaFile_) {
      nmeaFile_->close();
      sum.files.push_back(nmeaFile_->path());
    }
  }

 private:
  fs::path out_;

 public:
  vio::TumTrajectoryWriter tum;
  vio::PoseCovarianceWriter cov;
  OutFile timing;

 private:
  std::unique_ptr<OutFile> posFile_, ecefFile_, epochFile_, nmeaFile_;
  std::unique_ptr<PosWriter> posWriter_;
  std::unique_ptr<NmeaWriter> nmeaWriter_;
  std::vector<Geodetic> kml_;
};

/// The frame loop: for each frame the IMU up to it, the estimator, the local outputs, the GNSS
/// epochs up to the newest state, the timing row and the progress line; the figures it gathers.
class FrameLoop {
 public:
  FrameLoop(ReplayEstimator& est, ReplayGnss* gnss, const ReplayOptions& opt, const detail::ReplayFrames& frames,
            detail::GnssInputs& g, ReplayOutputs& outputs, ReplaySummary& sum, Clock::time_point wall0)
      : est_(est), gnss_(gnss), opt_(opt), frames_(frames), g_(g), out_(outputs), sum_(sum), wall0_(wall0),
        imuLead_(est.imuLeadNs()), imuFile_(frames.imuFile()) {
    const auto& imu = frames.ds.imu();
    const std::int64_t imuStart = opt.start_s > 0.0 ? frames.tFirst - 2'000'000'000 : imu.front().t_ns;
    while (imuNext_ < imu.size() && imu[imuNext_].t_ns < imuStart) ++imuNext_;
    lastProgress_ = Clock::now();
  }

  void run(detail::CameraInput& camera) {
    const std::size_t total = camera.total();
    while (std::optional<vio::FeatureFrame> frame = camera.next()) {
      feedImu(*frame);
      const ReplayEstimator::FrameOutcome r = estimate(*frame);
      const bool init = est_.initialized();
      if (init) writeState();
      double gnssMs = 0.0;
      int gnssCount = 0;
      if (gnss_) processGnss(*frame, init, gnssMs, gnssCount);
      char b[256];
      std::snprintf(b, sizeof b, "%" PRId64 ",%" PRIu64 ",%zu,%.3f,%.3f,%.3f,%d,%d,%d,%d,%d,%d\n", frame->t_ns, frame->index,
                    frame->features.size(), frame->timing.total, r.estimator_ms, gnssMs, gnssCount, init ? 1 : 0,
                    r.updated ? 1 : 0, r.msckf_features, r.slam_features, r.state_dim);
      out_.timing.out() << b;
      progress(r, init, total);
    }
    if (opt_.progress) std::fputc('\n', stderr);
  }

  /// Timing figures of the run into the summary.
  void summarise() {
    ReplaySummary& sum = sum_;
    const double n = static_cast<double>(std::max<std::size_t>(sum.framesProcessed, 1));
    sum.frontendMsMean = feSum_ / n;
    sum.estimatorMsMean = estSum_ / n;
    auto mean = [](const std::vector<double>& v) {
      double t = 0.0;
      for (double x : v) t += x;
      return v.empty() ? std::numeric_limits<double>::quiet_NaN() : t / static_cast<double>(v.size());
    };
    sum.estimatorMsBeforeInit = mean(estBefore_);
    sum.estimatorMsAfterInit = mean(estAfter_);
    sum.gnssMsMean = sum.gnssEpochs ? gnssSum_ / static_cast<double>(sum.gnssEpochs) : 0.0;
    sum.datasetSeconds = firstT_ >= 0 ? static_cast<double>(lastT_ - firstT_) * 1e-9 : 0.0;
    sum.wallSeconds = msSince(wall0_) * 1e-3;
    if (!estimatorMs_.empty()) {
      auto mid = estimatorMs_.begin() + static_cast<std::ptrdiff_t>(estimatorMs_.size() / 2);
      std::nth_element(estimatorMs_.begin(), mid, estimatorMs_.end());
      sum.estimatorMsMedian = *mid;
    }
    sum.gnssMsPerFrame = gnssSum_ / n;
    rusage ru{};
    if (getrusage(RUSAGE_SELF, &ru) == 0)
      sum.cpuSeconds = static_cast<double>(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) +
                       1e-6 * static_cast<double>(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
    if (firstTight_ >= 0 && firstT_ >= 0) sum.frameInitSeconds = static_cast<double>(firstTight_ - firstT_) * 1e-9;
  }

  /// Poses with the estimated velocity, in the VIO world frame of the start.
  const std::vector<vio::TrajectorySample>& localTrack() const { return localTrack_; }
  const std::vector<vio::PoseCovariance>& covariances() const { return covs_; }
  /// GNSS solutions on the sensor clock from the first tightly coupled update on (all if the
  /// frame never converged); `fromTight` tells which.
  const std::vector<EcefTruthSample>& antennaTrack(bool& fromTight) const {
    fromTight = antennaTight_.size() >= 2;
    return fromTight ? antennaTight_ : antennaTrack_;
  }

 private:
  // IMU up to the first sample at or after the frame time.
  void feedImu(const vio::FeatureFrame& frame) {
    const auto& imu = frames_.ds.imu();
    while (imuNext_ < imu.size()) {
      const vio::ImuSample& s = imu[imuNext_];
      if (lastImu_ >= 0) {
        const double gap = static_cast<double>(s.t_ns - lastImu_) * 1e-9;
        if (gap > opt_.maxImuGap_s) {
          ++sum_.imuGaps;
          sum_.largestImuGap_s = std::max(sum_.largestImuGap_s, gap);
          if (opt_.imuGapPolicy == ImuGapPolicy::Error) {
            char b[160];
            std::snprintf(b, sizeof b, "IMU gap of %.3f s before the sample at %" PRId64 " ns (limit %.3f s; --imu-gaps warn to continue)",
                          gap, s.t_ns, opt_.maxImuGap_s);
            throw ParseError(imuFile_, 0, "timestamp", b);
          }
        }
      }
      est_.addImu(s);
      lastImu_ = s.t_ns;
      ++sum_.imuSamples;
      ++imuNext_;
      if (s.t_ns >= frame.t_ns + imuLead_) break;
    }
  }

  ReplayEstimator::FrameOutcome estimate(const vio::FeatureFrame& frame) {
    ReplaySummary& sum = sum_;
    const ReplayEstimator::FrameOutcome r = est_.processFrame(frame);
    ++sum.framesProcessed;
    if (firstT_ < 0) firstT_ = frame.t_ns;
    lastT_ = frame.t_ns;
    feSum_ += frame.timing.total;
    sum.frontendMsMax = std::max(sum.frontendMsMax, frame.timing.total);
    estSum_ += r.estimator_ms;
    estimatorMs_.push_back(r.estimator_ms);
    sum.estimatorMsMax = std::max(sum.estimatorMsMax, r.estimator_ms);
    if (r.updated) ++sum.framesUpdated;
    (r.initialized ? estAfter_ : estBefore_).push_back(r.estimator_ms);
    if (!r.initialized) ++sum.framesWaitingBy[r.init_status];
    if (r.initialized && std::isnan(sum.initSeconds)) sum.initSeconds = static_cast<double>(frame.t_ns - firstT_) * 1e-9;
    if (r.reset) {
      ++sum.estimatorResets;
      // The next poses are in the new state's VIO frame: the local evaluation covers the last
      // state only, and trajectory.tum marks the jump.
      out_.tum.markReset("after a visual lock-out: the poses below are in a new VIO world frame");
      localTrack_.clear();
      covs_.clear();
      localMap_.reset();
      if (opt_.progress) {
        std::fprintf(stderr, "\n[gvins-replay] warning: visual lock-out at frame %zu (t %.2f s): the estimator "
                             "starts again (lockout_reset_s; check the camera-IMU time offset and calibration)\n",
                     sum.framesProcessed, static_cast<double>(frame.t_ns - firstT_) * 1e-9);
      }
    }
    return r;
  }

  // The newest pose and its covariance to trajectory.tum and trajectory.cov.csv.
  void writeState() {
    ++sum_.framesInitialized;
    vio::ImuState s = est_.newestImuState();
    vio::Matrix6d P = est_.poseCovariance();
    if (localMap_) {  // the estimator is in ENU: to the local frame (δθ is in the body, δp rotates)
      s.R_WI = localMap_->attitude(s.R_WI);
      s.p_WI = localMap_->point(s.p_WI);
      s.v_WI = localMap_->direction(s.v_WI);
      vio::Matrix6d T = vio::Matrix6d::Identity();
      T.bottomRightCorner<3, 3>() = localMap_->rotation();
      P = T * P * T.transpose();
    }
    const vio::TumPose p{s.t_ns, s.p_WI, s.R_WI};
    if (lastPose_ < 0 || p.t_ns > lastPose_) {
      out_.tum.write(p);
      out_.cov.write(s.t_ns, P);
      lastPose_ = p.t_ns;
      localTrack_.push_back({s.t_ns, s.R_WI, s.p_WI, s.v_WI});
      covs_.push_back({s.t_ns, 0.5 * (P + P.transpose())});
    }
  }

  // GNSS epochs up to the newest state.
  void processGnss(const vio::FeatureFrame& frame, bool init, double& gnssMs, int& gnssCount) {
    const std::int64_t tState = init ? est_.newestImuState().t_ns : frame.t_ns;
    const GpsTime limit = gpsFromNs(tState + opt_.sensorToGpst_ns);
    while (g_.haveRover && g_.nextRover.time <= limit) {
      if (!init && !gnss_->startsEstimator()) {
        ++sum_.gnssEpochsSkipped;
      } else {
        g_.advanceBase();
        g_.updateBasePosition(*gnss_);  // an RTCM station message arrived
        gnssMs += processGnssEpoch();
        ++gnssCount;
      }
      g_.haveRover = g_.rover->next(g_.nextRover);
    }
    gnssSum_ += gnssMs;
    if (init && !localMap_) {
      if (const auto c = gnss_->worldChange()) {
        localMap_ = c->inverse();
        if (!std::isfinite(sum_.enuMoveSeconds)) sum_.enuMoveSeconds = static_cast<double>(frame.t_ns - firstT_) * 1e-9;
      }
    }
  }

  // One rover epoch through the fusion and to the outputs; returns its time (ms).
  double processGnssEpoch() {
    ReplaySummary& sum = sum_;
    // A simulated outage (opt.gnssOutages): the epoch without satellites and no base.
    const double since = static_cast<double>(gnssStamp(g_.nextRover.time) - firstT_) * 1e-9;
    const bool outage = std::any_of(opt_.gnssOutages.begin(), opt_.gnssOutages.end(),
                                    [&](const auto& w) { return since >= w.first && since < w.second; });
    ObsEpoch empty;
    if (outage) {
      empty.time = g_.nextRover.time;
      ++sum.gnssEpochsInOutage;
    }
    const bool before = !est_.initialized();  // the GNSS/INS start may start it with this epoch
    const auto t0 = Clock::now();
    const ReplayGnssOutcome o = gnss_->processEpoch(outage ? empty : g_.nextRover,
                                                    g_.haveCurrentBase && !outage ? &g_.currentBase : nullptr, g_.nav);
    const double ms = msSince(t0);
    const GnssEpochReport& r = o.report;
    for (const std::string& w : r.warnings) std::fprintf(stderr, "\n[gvins-replay] warning: %s\n", w.c_str());
    const bool tight = r.stage == GnssFusionStage::kTight;
    if (before && !tight) {  // the GNSS/INS start has not started the estimator yet
      ++sum.gnssEpochsSkipped;
      if (r.insStart) ++sum.gnssEpochsWaitingBy[std::string(gnssInsStatusText(*r.insStart))];
    } else {
      ++sum.gnssEpochs;
    }
    if (r.updated) ++sum.gnssEpochsUpdated;
    sum.phaseRowsUsed += static_cast<std::size_t>(r.phase.used);
    sum.phaseRowsRejected += static_cast<std::size_t>(r.phase.rejected);
    sum.codeRowsMasked += static_cast<std::size_t>(r.psr.masked + r.dpsr.masked);
    sum.ambiguityStatesMax = std::max(sum.ambiguityStatesMax, static_cast<std::size_t>(r.ambiguities));
    sum.recordChanges += static_cast<std::size_t>(r.recordChanges);
    if (r.rtkFixed) ++sum.gnssEpochsFixed;
    if (r.reacquisition.started) ++sum.reacquisitions;
    sum.reacquisitionRowsAdmitted += static_cast<std::size_t>(r.reacquisition.admitted);
    sum.reacquisitionRowsExcluded += static_cast<std::size_t>(r.reacquisition.excluded);
    for (const SatId& sat : r.reacquisition.excludedSats) ++sum.reacquisitionExcluded[sat];
    if (r.frameRestart) ++sum.frameRestarts;
    const GpsTime& t = g_.nextRover.time;
    out_.writeEpoch(t, r, ms);
    if (r.antennaEcef) {
      const PositionSolution ps = out_.writeSolution(t, o);
      const EcefTruthSample a{gnssStamp(t), ps.position, r.antennaVelocityEcef};
      antennaTrack_.push_back(a);
      if (tight) {
        if (firstTight_ < 0) firstTight_ = a.t_ns;
        if (r.updated && r.psr.used + r.dopp.used + r.dpsr.used + r.ddcp.used + r.vel.used > 0) tightRowsApplied_ = true;
        if (tightRowsApplied_) antennaTight_.push_back(a);
      }
    }
    return ms;
  }

  std::int64_t gnssStamp(const GpsTime& t) const {
    return t.wholeSeconds() * 1'000'000'000 + static_cast<std::int64_t>(std::llround(t.fraction() * 1e9)) - opt_.sensorToGpst_ns;
  }

  void progress(const ReplayEstimator::FrameOutcome& r, bool init, std::size_t total) {
    if (!opt_.progress || (Clock::now() - lastProgress_ <= std::chrono::seconds(1) && sum_.framesProcessed != total)) return;
    lastProgress_ = Clock::now();
    const double wall = msSince(wall0_) * 1e-3;
    const double data = static_cast<double>(lastT_ - firstT_) * 1e-9;
    std::fprintf(stderr, "\r[gvins-replay] frame %zu/%zu  t %.1f s  %s  %.1fx real time   ", sum_.framesProcessed, total,
                 data, init ? "initialised" : ("initialising: " + std::string(vio::initStatusText(r.init_status))).c_str(),
                 wall > 0 ? data / wall : 0.0);
    std::fflush(stderr);
  }

  ReplayEstimator& est_;
  ReplayGnss* gnss_;
  const ReplayOptions& opt_;
  const detail::ReplayFrames& frames_;
  detail::GnssInputs& g_;
  ReplayOutputs& out_;
  ReplaySummary& sum_;
  const Clock::time_point wall0_;
  const std::int64_t imuLead_;
  const std::string imuFile_;
  std::size_t imuNext_ = 0;
  std::int64_t lastImu_ = -1;
  std::int64_t lastPose_ = -1;  // stamp of the last pose written
  double feSum_ = 0.0, estSum_ = 0.0, gnssSum_ = 0.0;
  std::int64_t firstT_ = -1, lastT_ = -1;
  Clock::time_point lastProgress_;
  std::vector<vio::TrajectorySample> localTrack_;
  std::vector<vio::PoseCovariance> covs_;
  std::vector<double> estimatorMs_, estBefore_, estAfter_;  // per frame; before and after the initialisation
  // Local outputs (trajectory.tum, covariances, the local evaluation) stay in the VIO world frame
  // of the start: once the GNSS fusion has moved the estimator into ENU (ReplayGnss::worldChange),
  // `localMap_` takes ENU back to it, fixed at the move.
  std::optional<vio::WorldFrameChange> localMap_;
  // GNSS solutions, stamped on the sensor clock: all, and those after the frame initialisation.
  std::vector<EcefTruthSample> antennaTrack_, antennaTight_;
  std::int64_t firstTight_ = -1;
  // Set at the first epoch whose tightly coupled GNSS rows were applied. The epoch at which the
  // frame initialisation converges carries the frame-initialisation estimate (SPP-level, metres)
  // and no GNSS rows yet; the global accuracy is evaluated from the next update on.
  bool tightRowsApplied_ = false;
};

}  // namespace

ReplaySummary runReplay(const std::string& dataset, ReplayEstimator& est, ReplayGnss* gnss, const ReplayOptions& opt) {
  const auto wall0 = Clock::now();
  ReplaySummary sum;
  const fs::path out = makeOutputFolder(opt);
  const detail::ReplayFrames frames(dataset, opt, sum);
  detail::GnssInputs g;
  if (gnss) g.open(dataset, opt, *gnss, sum);
  ReplayOutputs outputs(out, dataset, opt, gnss != nullptr);
  detail::CameraInput camera(dataset, frames, opt);

  FrameLoop loop(est, gnss, opt, frames, g, outputs, sum, wall0);
  loop.run(camera);
  camera.finish();
  sum.skippedBadImages = camera.badImages();
  outputs.closeLocal(sum);
  if (gnss) {
    g.reportSkipped();
    outputs.closeGnss(opt, sum);
  }
  loop.summarise();
  if (gnss) sum.leverArm = gnss->leverArm();
  sum.leverArmTruth = opt.leverArmTruth;
  if (const auto td = est.timeOffset()) {
    sum.timeOffset = td->value;
    sum.timeOffsetSigma = td->sigma;
  }
  sum.timeOffsetTruth = opt.timeOffsetTruth;

  if (opt.evaluate && frames.ds.hasGroundTruth() && loop.localTrack().size() >= 2)
    detail::evaluateLocal(frames.ds, loop.localTrack(), loop.covariances(), out, sum);
  bool fromTight = false;
  const std::vector<EcefTruthSample>& track = loop.antennaTrack(fromTight);
  if (opt.evaluate && gnss) detail::evaluateGlobal(dataset, opt, track, fromTight, out, sum);
  OutFile mf(out / "metrics.csv");
  sum.writeMetrics(mf.out());
  mf.close();
  sum.files.push_back(mf.path());
  return sum;
}

}  // namespace gvins::fusion
