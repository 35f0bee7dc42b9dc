// The replay pipeline behind gvins-replay: dataset → front end (own thread) → estimator → GNSS
// fusion → output files, with timing, progress and a summary.
//
// Inputs: a dataset folder in the EuRoC/ASL layout (vio/euroc_dataset.hpp) as recorded by EuRoC
// or written by gvins-sim; with camN/features.csv (feature-only simulated datasets) the tracks
// replace the image front end. GNSS (gnss/rover.obs, gnss/base.obs, the navigation file) is read
// when a GNSS client is given.
//
// Order of work, one consumer thread: for each camera frame (in time order) every IMU sample up to
// the frame time (plus the estimator's imuLeadNs, for a camera-IMU time offset) is added, the frame is processed, the pose and its covariance are written, then
// every rover epoch whose time tag is <= the newest state time is handed to the GNSS client with
// the base epoch at or before it. Images are decoded on a loader thread and tracked on the front
// end thread (FrontendThread), so loading, tracking and estimation overlap.
//
// The estimator and the GNSS fusion are reached through the small interfaces below, so that the
// pipeline is tested with test doubles and gvins-replay binds the SRI-SWF estimator and
// GnssFusion (replay_sri_swf.hpp).
//
// Outputs in the output folder: trajectory.tum (IMU pose in the VIO frame at every frame once
// initialised), trajectory.cov.csv (pose_covariance_csv.hpp), timing.csv (per frame: front-end,
// estimator and GNSS ms); with GNSS: global.pos (RTKLIB layout), global_ecef.csv, track.kml,
// gnss_epochs.csv (satellite use per epoch). docs/replay.md describes the columns.
#pragma once

#include <cstdint>
#include <functional>
#include <iosfwd>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "gvins/base/enum_names.hpp"
#include "gvins/base/gnss_time.hpp"
#include "gvins/base/observation.hpp"
#include "gvins/fusion/gnss_epoch_report.hpp"
#include "gvins/gnss/pos_reader.hpp"
#include "gvins/vio/feature_frame.hpp"
#include "gvins/vio/frontend.hpp"
#include "gvins/vio/imu_sample.hpp"
#include "gvins/vio/imu_state.hpp"
#include "gvins/vio/init_status.hpp"
#include "gvins/vio/pose_covariance_csv.hpp"
#include "gvins/vio/world_frame_change.hpp"

namespace gvins {
class EphemerisStore;
}

namespace gvins::fusion {

/// What the pipeline needs from a VIO estimator (SriSwfEstimator's driver API).
class ReplayEstimator {
 public:
  struct FrameOutcome {
    bool initialized = false;
    bool updated = false;
    double estimator_ms = 0.0;
    int msckf_features = 0;
    int slam_features = 0;
    bool reset = false;  ///< the estimator dropped its state after this frame and initialises again
    int state_dim = 0;   ///< error-state dimension after the frame (columns of the square-root factor)
    vio::InitStatus init_status = vio::InitStatus::kCollecting;  ///< not initialised: why
  };
  virtual ~ReplayEstimator() = default;
  virtual void addImu(const vio::ImuSample& s) = 0;
  virtual FrameOutcome processFrame(const vio::FeatureFrame& f) = 0;
  virtual bool initialized() const = 0;
  virtual vio::ImuState newestImuState() const = 0;
  virtual vio::Matrix6d poseCovariance() const = 0;
  /// How far past a frame's stamp (ns) the IMU must be added before processFrame: a camera-IMU
  /// time offset puts the frame at IMU time stamp + t_d.
  virtual std::int64_t imuLeadNs() const { return 0; }
  /// Camera-IMU time offset estimate and its 1-σ (s), when the estimator calibrates one.
  struct TimeOffset {
    double value = 0.0, sigma = 0.0;
  };
  virtual std::optional<TimeOffset> timeOffset() const { return std::nullopt; }
};

/// Result of one GNSS epoch as the outputs need it: the fusion's report and the antenna's covariance.
struct ReplayGnssOutcome {
  GnssEpochReport report;
  Eigen::Matrix3d antennaCovarianceEcef = Eigen::Matrix3d::Zero();          ///< position, zero if unknown
  Eigen::Matrix3d antennaVelocityCovarianceEcef = Eigen::Matrix3d::Zero();  ///< velocity, zero if unknown
};

/// What the pipeline needs from the GNSS fusion.
class ReplayGnss {
 public:
  virtual ~ReplayGnss() = default;
  virtual void setBasePosition(const Eigen::Vector3d& ecef) = 0;
  virtual ReplayGnssOutcome processEpoch(const ObsEpoch& rover, const ObsEpoch* base, const EphemerisStore& nav) = 0;
  /// The current GNSS-IMU lever-arm estimate (^I p_r, m), when the client has one.
  virtual std::optional<Eigen::Vector3d> leverArm() const { return std::nullopt; }
  /// The change the client made to the estimator's world frame (GnssFusion::worldChange): the
  /// local outputs (trajectory.tum, covariances, the local evaluation) undo it, so that they stay
  /// in the VIO world frame of the start.
  virtual std::optional<vio::WorldFrameChange> worldChange() const { return std::nullopt; }
  /// Whether the client may start the estimator itself (GnssFusionConfig::insStart): then it gets
  /// the epochs before the estimator is initialised too.
  virtual bool startsEstimator() const { return false; }
};

enum class ImuGapPolicy { Error, Warn };
/// Names of the IMU gap policies (replay: imu_gaps, --imu-gaps).
inline constexpr EnumName<ImuGapPolicy> kImuGapPolicyNames[] = {{ImuGapPolicy::Error, "error"}, {ImuGapPolicy::Warn, "warn"}};

struct ReplayOptions {
  std::string outDir;
  /// Also NMEA 0183 GGA+RMC sentences of the global (GNSS) solutions to this file (empty: none).
  std::string nmeaPath;
  vio::FrontendConfig frontend;
  /// Images that cannot be decoded: error (default) or skip the frame and count it.
  bool skipBadImages = false;
  /// Listed images whose file is missing: error at open (default) or drop and count.
  bool skipMissingImages = false;
  /// Gaps in the IMU log longer than this (s) between two processed frames are an error, or
  /// (Warn) counted and reported.
  double maxImuGap_s = 0.05;
  ImuGapPolicy imuGapPolicy = ImuGapPolicy::Error;
  /// Replay only [start, start + duration] s after the first frame (duration <= 0: to the end).
  double start_s = 0.0, duration_s = 0.0;
  /// Use camN/features.csv when present instead of images (auto), or force images.
  bool useFeatureTracks = true;
  /// A dataset without a cam0 folder runs camera-less (IMU and GNSS): the estimator gets frames
  /// without features at this rate (Hz), each a pose clone for the GNSS rows.
  double cameraLessRate_hz = 10.0;
  /// Reference track of the antenna for the global evaluation from a .pos file (RTKLIB layout,
  /// e.g. an RTK solution of the same receiver), its epochs of quality <= truthPosMaxQuality only
  /// (1: fixed); empty: the dataset's truth/groundtruth_ecef.csv.
  std::string truthPos;
  int truthPosMaxQuality = 1;
  /// Simulated GNSS outages: [start, end) in s after the first frame. Rover epochs inside reach
  /// the GNSS client without satellites (and without a base epoch), so the antenna track goes on
  /// from the IMU alone and the error at the end of each window is the outage drift.
  std::vector<std::pair<double, double>> gnssOutages;
  /// Images mode: also write the front end's tracks as a feature-only dataset in this folder
  /// (FeatureTrackDatasetWriter; empty: no). Replaying that folder runs the estimator on the
  /// same tracks without the front end.
  std::string saveTracksDir;
  /// GNSS inputs; empty: <dataset>/gnss/rover.obs, base.obs and the navigation file found there.
  std::string roverObs, baseObs, navFile;
  /// Precise orbit (SP3) and clock (RINEX clock) files; empty: the *.sp3 / *.clk files (also
  /// gzipped) in <dataset>/gnss. Where they cover a satellite they replace its broadcast orbit and
  /// clock (EphemerisStore::setPrecise). broadcastOnly: use none.
  std::vector<std::string> sp3Files, clockFiles;
  /// ANTEX files for the products' satellite antenna offsets (default: *.atx in DATASET/gnss when
  /// the products come from there too).
  std::vector<std::string> antennaFiles;
  /// Bias-SINEX code biases for the products (default: *.bia / *.bsx in DATASET/gnss, as above).
  std::vector<std::string> biasFiles;
  bool broadcastOnly = false;
  /// Read the *.sp3 / *.clk (and *.atx, *.bia) of <dataset>/gnss when no --sp3/--clk were given.
  /// gvins-replay turns it off for the differential modes (vio+dopp+dpsr, vio+dopp+ddcp): their
  /// code and phase rows difference the satellite orbit and clock errors away (3 km baseline:
  /// orbit error × 1.5·10⁻⁴), the ten simulated flights give the same RMSE to ±1 mm either way,
  /// and the products' interpolation costs ~17 % of their GNSS time (docs/gnss_fusion.md).
  bool folderProducts = true;
  /// Recorded RTCM 3 streams of SSR corrections (gvins/rtcm/ssr_file.hpp; e.g. a gvins-sim
  /// dataset's gnss/ssr.rtcm3): they correct the broadcast records where no precise products
  /// cover a satellite (with broadcastOnly: everywhere). Not read from the folder by default.
  std::vector<std::string> ssrFiles;
  std::optional<Eigen::Vector3d> basePosition;  ///< default: base.obs header position
  /// GPST (ns since the GPS epoch) = sensor stamp + this. 0 for gvins-sim datasets, whose sensor
  /// stamps are GPST; set it to replay GNSS files against a recording stamped on another clock.
  std::int64_t sensorToGpst_ns = 0;
  std::string modeName = "vio";  ///< for the summary and output headers
  /// The true GNSS lever arm (gvins-sim dataset.yaml), for the lever-arm error in metrics.csv.
  std::optional<Eigen::Vector3d> leverArmTruth;
  /// The true camera-IMU time offset (gvins-sim dataset.yaml cameras.time_offset_s), s.
  std::optional<double> timeOffsetTruth;
  bool progress = true;
  /// Evaluate against the dataset's ground truth at the end (table + SVG plots in outDir).
  bool evaluate = true;
};

struct ReplaySummary {
  std::size_t frames = 0, framesProcessed = 0, framesInitialized = 0, framesUpdated = 0;
  std::size_t estimatorResets = 0;  ///< VIO lock-outs: the estimator started again (vio_resets)
  std::size_t imuSamples = 0;
  std::size_t skippedBadImages = 0, skippedMissingImages = 0;
  std::size_t imuGaps = 0;
  double largestImuGap_s = 0.0;
  bool featureTracks = false;
  bool cameraLess = false;  ///< no camera: frames without features (ReplayOptions::cameraLessRate_hz)
  double datasetSeconds = 0.0, wallSeconds = 0.0;
  double frontendMsMean = 0.0, frontendMsMax = 0.0, estimatorMsMean = 0.0, estimatorMsMax = 0.0;
  double gnssMsMean = 0.0;  ///< per epoch
  std::size_t gnssEpochs = 0, gnssEpochsUpdated = 0, gnssEpochsFixed = 0, gnssEpochsSkipped = 0;
  std::size_t gnssEpochsInOutage = 0;  ///< handed over without satellites (ReplayOptions::gnssOutages)
  /// Satellites with precise products loaded (0: broadcast orbits and clocks only).
  std::size_t preciseSatellites = 0;
  std::size_t antexAntennas = 0;  ///< satellite antenna entries of the ANTEX files used with the products
  bool folderProductsSkipped = false;  ///< the dataset folder has precise products that were not read (folderProducts off)
  std::size_t codeBiases = 0;     ///< entries of the Bias-SINEX files used with the products
  std::size_t ssrMessages = 0;    ///< SSR messages read from the ReplayOptions::ssrFiles
  /// vio+dopp+ppp: carrier-phase rows used / gated out over the run, most ambiguity states at once.
  std::size_t phaseRowsUsed = 0, phaseRowsRejected = 0, ambiguityStatesMax = 0;
  std::size_t recordChanges = 0;  ///< broadcast record changes carried over to ambiguities
  std::size_t codeRowsMasked = 0;  ///< psr/dpsr rows dropped below cn0_mask_dbhz
  /// GNSS re-acquisitions (gnss_gate_recovery.hpp): started, rows admitted and excluded by their
  /// widened gate and consensus, and the excluded rows per satellite.
  std::size_t reacquisitions = 0, reacquisitionRowsAdmitted = 0, reacquisitionRowsExcluded = 0;
  std::map<SatId, std::size_t> reacquisitionExcluded;
  /// Frame initialisations that dropped the estimator's state (a start that was not linear).
  std::size_t frameRestarts = 0;
  double realTimeFactor() const { return wallSeconds > 0.0 ? datasetSeconds / wallSeconds : 0.0; }
  double estimatorMsMedian = 0.0;
  /// First processed frame to the first initialised one (s; NaN: never), the estimator's mean time
  /// per frame before and after that, and the frames not initialised by their InitStatus.
  double initSeconds = std::numeric_limits<double>::quiet_NaN();
  double estimatorMsBeforeInit = std::numeric_limits<double>::quiet_NaN();
  double estimatorMsAfterInit = std::numeric_limits<double>::quiet_NaN();
  std::map<vio::InitStatus, std::size_t> framesWaitingBy;
  /// GNSS modes with the GNSS/INS start: GNSS epochs before the initialisation by what the
  /// alignment still missed (GnssFusion's GnssInsStatus text).
  std::map<std::string, std::size_t> gnssEpochsWaitingBy;
  double gnssMsPerFrame = 0.0;   ///< GNSS time summed over the run / processed frames
  double cpuSeconds = 0.0;       ///< process CPU time (user + system), all threads
  std::vector<std::string> files;
  std::string evaluationTable;  ///< printEvaluation output, empty without ground truth
  /// Key figures of the evaluations for scripts (metrics.csv): NaN where not evaluated.
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  struct Accuracy {
    double positionRmse = kNaN, rotationRmseDeg = kNaN, velocityRmse = kNaN, bodyVelocityRmse = kNaN;
    /// Local only: 4-DoF alignment on the poses of the first 10 % of the path (VIO as a navigator started
    /// in a known frame: its drift is not aligned away).
    double startAlignedPositionRmse = kNaN;
    double horizontalRmse = kNaN, verticalRmse = kNaN;
    double pathLength = kNaN, driftPercent = kNaN;  ///< drift: longest segment length evaluated
    double positionNees = kNaN, orientationNees = kNaN;
    /// Local only: NEES under the first-pose alignment (the estimator's gauge, under which its
    /// covariances describe its errors; the whole-flight fit moves the first poses, whose
    /// covariance is the tight initial prior).
    double positionNeesFirstPose = kNaN, orientationNeesFirstPose = kNaN;
    std::size_t poses = 0;
  };
  Accuracy local;   ///< trajectory.tum vs ground truth, 4-DoF aligned
  Accuracy global;  ///< GNSS antenna solutions after the frame initialisation, ENU, no alignment
  double frameInitSeconds = kNaN;  ///< from the first processed frame to the first tight GNSS epoch
  /// From the first processed frame to the frame after which the estimator was in ENU
  /// (GnssFusionConfig::frameReanchor; NaN if it never moved, or with frame_reanchor off).
  double enuMoveSeconds = kNaN;
  std::optional<Eigen::Vector3d> leverArm, leverArmTruth;  ///< final estimate; options' truth
  /// Camera-IMU time offset (s): final estimate and 1-σ when calibrated; options' truth.
  std::optional<double> timeOffset, timeOffsetSigma, timeOffsetTruth;
  /// GNSS modes with DATASET/truth/groundtruth_ecef.csv: accuracy of the GNSS antenna solutions
  /// (global_ecef.csv) against the true antenna track, in ENU at the first truth point, no
  /// alignment (rotation rows are meaningless there: the antenna has no orientation).
  std::string globalEvaluationTable;
  void print(std::ostream& os) const;
  /// `key,value` lines of the figures above (metrics.csv; NaN where not evaluated).
  void writeMetrics(std::ostream& os) const;
};

/// Antenna track of a gvins-sim ECEF truth file (truth/groundtruth_ecef.csv: t [ns], IMU
/// position/velocity/orientation, then antenna_E_x/y/z in columns 12-14 and, when present, the
/// antenna velocity in columns 15-17). Throws ParseError
/// (file, line, field) on malformed rows or stamps that do not increase.
struct EcefTruthSample {
  std::int64_t t_ns = 0;
  Eigen::Vector3d antenna = Eigen::Vector3d::Zero();
  std::optional<Eigen::Vector3d> antennaVelocity;  ///< columns 15-17 when present
};
std::vector<EcefTruthSample> readEcefTruthCsv(const std::string& path);
/// The solutions of a .pos file with quality 1..maxQuality (1 fixed, 2 float, 5 single) as
/// antenna truth on the sensor clock (GPST ns minus sensorToGpst_ns).
std::vector<EcefTruthSample> ecefTruthFromPos(const PosFile& pos, int maxQuality, std::int64_t sensorToGpst_ns = 0);
std::vector<EcefTruthSample> parseEcefTruthCsv(std::string_view text, const std::string& name);

/// Runs the whole replay. Throws gvins::ParseError for dataset problems (file, line, field),
/// std::runtime_error for output problems. `gnss` may be null (VIO only).
ReplaySummary runReplay(const std::string& dataset, ReplayEstimator& estimator, ReplayGnss* gnss,
                        const ReplayOptions& options);

}  // namespace gvins::fusion
