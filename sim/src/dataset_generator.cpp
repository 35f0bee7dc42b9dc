#include "gvins/sim/dataset_generator.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <map>
#include <mutex>
#include <optional>
#include <ostream>
#include <sstream>
#include <stdexcept>
#include <thread>

#include <opencv2/imgcodecs.hpp>

#include "gvins/sim/dataset_writer.hpp"
#include "gvins/sim/gnss_simulator.hpp"
#include "gvins/sim/random.hpp"
#include "gvins/sim/urban_signal_path.hpp"
#include "gvins/sim/urban_structure.hpp"

namespace gvins::sim {
namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

/// Prints "<what> k/n (p %)" at most once a second (thread-safe).
class Progress {
 public:
  Progress(std::ostream* os, std::string what, std::size_t total) : os_(os), what_(std::move(what)), total_(total) {}
  void step() {
    const std::size_t k = ++done_;
    if (!os_) return;
    std::lock_guard<std::mutex> lock(m_);
    if (k != total_ && since(last_) < 1.0) return;
    last_ = Clock::now();
    *os_ << "[gvins-sim] " << what_ << " " << k << "/" << total_ << " (" << std::fixed << std::setprecision(0)
         << 100.0 * static_cast<double>(k) / static_cast<double>(std::max<std::size_t>(total_, 1)) << " %, "
         << std::setprecision(1) << static_cast<double>(k) / std::max(since(start_), 1e-9) << "/s)\n"
         << std::defaultfloat << std::flush;
  }

 private:
  std::ostream* os_;
  std::string what_;
  std::size_t total_;
  std::atomic<std::size_t> done_{0};
  std::mutex m_;
  Clock::time_point start_ = Clock::now(), last_ = Clock::now();
};

std::string gpstString(const GpsTime& t) { return t.toString(9); }

double medianCameraHeight(const Trajectory& tr, const vio::CameraCalibration& cam) {
  std::vector<double> z;
  for (double t = 0.0; t <= tr.duration(); t += std::max(tr.duration() / 200.0, 0.05)) {
    const TrajectoryState s = tr.evaluate(t);
    z.push_back((s.p_WB + s.R_WB * cam.T_BS.topRightCorner<3, 1>()).z());
  }
  std::nth_element(z.begin(), z.begin() + static_cast<long>(z.size() / 2), z.end());
  return std::max(z[z.size() / 2], 0.5);
}

void writeList(TextFile& f, const Eigen::Vector3d& v) {
  f << "[";
  f.num(v.x()) << ", ";
  f.num(v.y()) << ", ";
  f.num(v.z()) << "]";
}

std::string yamlQuoted(const std::string& s) {
  std::string o = "\"";
  for (const char c : s) {
    if (c == '"' || c == '\\') o += '\\';
    if (c == '\n') {
      o += "\\n";
      continue;
    }
    o += c;
  }
  return o + "\"";
}

/// The real rover (and navigation) files of a gnss_track scenario, copied as they are:
/// gnss/rover.<ext> and gnss/nav.<ext> (gvins-replay tells RINEX and UBX apart by content).
std::vector<fs::path> copyRealGnss(const TrackTrajectoryConfig& c, const fs::path& gdir) {
  fs::create_directories(gdir);
  std::vector<fs::path> out;
  const auto copy = [&](const std::string& from, const std::string& stem) {
    const fs::path to = gdir / (stem + fs::path(from).extension().string());
    fs::copy_file(from, to, fs::copy_options::overwrite_existing);
    out.push_back(to);
  };
  copy(c.roverLog, "rover");
  if (!c.navigationFile.empty()) copy(c.navigationFile, "nav");
  return out;
}

/// dataset.yaml keys of a gnss_track trajectory: its inputs and what the fit found.
void writeTrackSection(TextFile& f, const TrackTrajectoryConfig& c, const TrackFitReport& r) {
  f << "  pos_file: " << yamlQuoted(c.posFile) << "\n  imu_csv: " << yamlQuoted(c.imuCsv) << "\n  max_quality: ";
  f.integer(c.maxQuality) << "\n  rover_log: " << yamlQuoted(c.roverLog) << "\n  attitude: \"real gyro integrated, R0 and "
                             "biases fitted to the track's velocity increments (sim/track_trajectory.hpp)\"\n  track_epochs: ";
  f.integer(static_cast<std::int64_t>(r.trackEpochs)) << "\n  initial_yaw_deg: ";
  f.num(r.initialYawDeg) << "\n  fitted_gyro_bias_radps: ";
  writeList(f, r.gyroBias);
  f << "\n  fitted_accel_bias_mps2: ";
  writeList(f, r.accelBias);
  f << "\n  velocity_increment_residual_rms_mps: ";
  f.num(r.velocityResidualRms) << "\n  track_residual_rms_m: ";
  f.num(r.trackResidualRms) << "\n  track_residual_max_m: ";
  f.num(r.trackResidualMax) << "\n  accel_residual_rms_mps2: ";
  f.num(r.accelResidualRms) << "\n  forward_axis_body: ";
  writeList(f, r.forwardAxis);
  f << "  # mean direction of travel in B\n";
}

}  // namespace

std::unique_ptr<Trajectory> buildTrajectory(const Scenario& sc, std::uint64_t seed) {
  if (sc.trajectory == TrajectoryKind::Recorded) return std::make_unique<RecordedTrajectory>(sc.recorded);
  if (sc.trajectory == TrajectoryKind::Track)
    return std::make_unique<TrackTrajectory>(sc.track, sc.frame, sc.leverArm, flatGravity(sc.imu, sc.frame));
  FlightSpec f = sc.flight;
  f.gravity = flatGravity(sc.imu, sc.frame);
  return buildFlight(f, seed);
}

void GenerationSummary::print(std::ostream& os) const {
  const auto flags = os.flags();
  os << "gvins-sim summary\n";
  os << "  scenario            " << scenario << " (seed " << seed << ")\n";
  os << "  start (GPST)        " << startGpst << "\n";
  os << std::fixed << std::setprecision(1);
  os << "  duration            " << duration << " s, path " << pathLength << " m, max speed " << std::setprecision(2)
     << maxSpeed << " m/s, max height " << std::setprecision(1) << maxHeight << " m\n";
  os << "  IMU                 " << imuSamples << " samples at " << std::setprecision(0) << imuRate << " Hz\n";
  if (cameras > 0) {
    os << "  cameras             " << cameras << " x " << framesPerCamera << " frames, "
       << (images ? "rendered images" : "feature tracks") << "\n";
    os << std::setprecision(2);
    if (images)
      os << "  rendering           " << meanBlurSamples << " sub-exposures per image, " << textureTiles
         << " texture tiles\n";
    else
      os << "  features            " << featureObservations << " observations of " << landmarks << " landmarks, "
         << meanFeaturesPerImage << " per image\n";
  }
  if (buildings > 0) os << "  structure           " << buildings << " buildings along the route\n";
  os << std::setprecision(1);
  os << "  time                trajectory+IMU " << secondsTrajectoryImu << " s, cameras " << secondsCameras
     << " s, GNSS " << secondsGnss << " s, total " << secondsTotal << " s\n";
  os << "  written             " << std::setprecision(1) << static_cast<double>(bytes) / 1e6 << " MB\n";
  os.flags(flags);
  if (!gnssSummary.empty()) os << gnssSummary;
}

namespace {
/// A lower bound of a flight's duration from its spec alone (path at cruise speed, hovers): the
/// route is built as a polyline of 0.5 m steps, so a spec of legs 1000 km long must be refused
/// before it is built.
double nominalFlightDuration(const FlightSpec& f) {
  double path = f.length;
  if (f.pattern == FlightPattern::Waypoints) {
    path = 0.0;
    Eigen::Vector3d prev = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& w : f.waypoints) {
      path += (w - prev).norm();
      prev = w;
    }
  }
  return path / f.speed + f.hoverStart + f.hoverEnd;
}

void checkResourceLimits(const Scenario& sc, double duration, const GenerationOptions& opt) {
  const GenerationLimits lim;
  const auto fail = [&](const std::string& what) {
    throw std::invalid_argument("scenario '" + sc.name + "' asks for " + what + " (trajectory " + std::to_string(duration) +
                                " s); shorten the trajectory or lower the rates");
  };
  if (!(duration <= lim.maxDuration))
    fail("a trajectory longer than the limit of " + std::to_string(lim.maxDuration) + " s");
  const double imuSamples = duration * sc.imu.rateHz;
  if (imuSamples > lim.maxImuSamples)
    fail(std::to_string(static_cast<long long>(imuSamples)) + " IMU samples, more than the limit of " +
         std::to_string(static_cast<long long>(lim.maxImuSamples)));
  const bool images = !(opt.featuresOnly || sc.output == CameraOutput::Features);
  double pixels = 0.0;
  for (const auto& c : sc.cameras) pixels += static_cast<double>(c.intrinsics.width) * c.intrinsics.height;
  const double imageBytes = images ? duration * sc.cameraRate * pixels : 0.0;  // 8-bit, before PNG compression
  if (imageBytes > lim.maxImageBytes)
    fail(std::to_string(static_cast<long long>(imageBytes / 1e6)) + " MB of images, more than the limit of " +
         std::to_string(static_cast<long long>(lim.maxImageBytes / 1e6)) + " MB");
}
/// What the stages of generateDataset share: the inputs, the summary they fill in, and what
/// each stage hands on to the later ones.
struct Generation {
  Generation(const Scenario& scenario, const fs::path& folder, const GenerationOptions& options, GenerationSummary& summary)
      : sc(scenario), dir(folder), opt(options), sum(summary), seed(options.seed), log(options.progress) {}

  const Scenario& sc;
  const fs::path& dir;
  const GenerationOptions& opt;
  GenerationSummary& sum;
  std::uint64_t seed;
  std::ostream* log;
  fs::path mav0, truthDir;
  std::unique_ptr<Trajectory> traj;
  double duration = 0.0;
  // trajectory and IMU
  std::vector<vio::ImuSample> imu;
  std::vector<TruthRow> truth;
  double gravity = 9.81;
  std::string imuSource = "simulated";
  vio::ImuNoise noise;
  // structure and cameras
  bool features = false;  ///< feature tracks instead of rendered images
  std::unique_ptr<UrbanStructure> urban;
  std::vector<std::int64_t> stamps;  ///< camera stamps (sensor time, ns)
  std::vector<double> times;         ///< their true times (s of the trajectory)
  // GNSS
  std::vector<fs::path> gnssFiles;
};

/// The trajectory, its duration checked against the resource limits, and the dataset folders.
void buildTrajectoryStage(Generation& g) {
  const Scenario& sc = g.sc;
  if (g.log) *g.log << "[gvins-sim] scenario '" << sc.name << "', seed " << g.seed << " -> " << g.dir.string() << "\n";
  if (sc.trajectory == TrajectoryKind::Flight) checkResourceLimits(sc, nominalFlightDuration(sc.flight), g.opt);
  g.traj = buildTrajectory(sc, g.seed);
  g.duration = g.traj->duration();
  g.sum.duration = g.duration;
  checkResourceLimits(sc, g.duration, g.opt);
  g.mav0 = g.dir / "mav0";
  g.truthDir = g.dir / "truth";
  fs::create_directories(g.mav0 / "imu0");
  fs::create_directories(g.mav0 / "state_groundtruth_estimate0");
  fs::create_directories(g.truthDir);
}

/// A flight's IMU samples (simulated) and the truth at each.
void simulatedImuStage(Generation& g) {
  const Scenario& sc = g.sc;
  const SimulatedImu sim = simulateImu(*g.traj, sc.frame, sc.imu, g.seed);
  g.gravity = sim.gravity;
  g.imu = sim.samples;
  g.truth.resize(g.imu.size());
  for (std::size_t i = 0; i < g.imu.size(); ++i) {
    g.truth[i].t_ns = g.imu[i].t_ns;
    g.truth[i].state = g.traj->evaluate(sc.frame.flightTimeOfStamp(g.imu[i].t_ns));
    g.truth[i].bg = sim.gyroBias[i];
    g.truth[i].ba = sim.accelBias[i];
  }
  g.sum.imuRate = sc.imu.rateHz;
}

/// A recorded or track trajectory's real IMU samples within the duration, restamped to the
/// scenario's start, and the truth at each.
void recordedImuStage(Generation& g) {
  const Scenario& sc = g.sc;
  const auto& rec = static_cast<const RecordedTrajectory&>(*g.traj);
  const bool track = sc.trajectory == TrajectoryKind::Track;
  g.imuSource = "recorded: " + (track ? sc.track.imuCsv : sc.recorded.imuCsv);
  // EuRoC's processing convention; a track fit uses the scenario's flat gravity.
  g.gravity = track ? flatGravity(sc.imu, sc.frame) : 9.81;
  for (const vio::ImuSample& m : rec.imuSamples()) {
    const std::int64_t off = m.t_ns - rec.startStamp();
    if (off < 0 || static_cast<double>(off) * 1e-9 > g.duration) continue;
    vio::ImuSample s = m;
    s.t_ns = sc.frame.startStampNs() + off;
    g.imu.push_back(s);
    TruthRow row;
    row.t_ns = s.t_ns;
    row.state = g.traj->evaluate(static_cast<double>(off) * 1e-9);
    rec.biases(row.state.t, row.bg, row.ba);
    g.truth.push_back(row);
  }
  g.sum.imuRate = g.imu.size() > 1 ? 1e9 * static_cast<double>(g.imu.size() - 1) /
                                         static_cast<double>(g.imu.back().t_ns - g.imu.front().t_ns)
                                   : 0.0;
}

/// The path statistics and the IMU and ground-truth files.
void writeImuStage(Generation& g) {
  const Scenario& sc = g.sc;
  GenerationSummary& sum = g.sum;
  sum.imuSamples = g.imu.size();
  for (std::size_t i = 0; i < g.truth.size(); ++i) {
    if (i > 0) sum.pathLength += (g.truth[i].state.p_WB - g.truth[i - 1].state.p_WB).norm();
    sum.maxSpeed = std::max(sum.maxSpeed, g.truth[i].state.v_WB.norm());
    sum.maxHeight = std::max(sum.maxHeight, g.truth[i].state.p_WB.z());
  }
  g.noise = sc.imu.noise;
  g.noise.rate_hz = sum.imuRate;
  writeImuCsv(g.mav0 / "imu0" / "data.csv", g.imu);
  writeImuSensorYaml(g.mav0 / "imu0" / "sensor.yaml", g.noise, std::round(sum.imuRate),
                     sc.trajectory == TrajectoryKind::Flight ? "gvins-sim IMU (noise model of this file)"
                                                            : "recorded IMU driving gvins-sim");
  writeGroundTruthCsv(g.mav0 / "state_groundtruth_estimate0" / "data.csv", g.truth);
  writeEcefTruthCsv(g.truthDir / "groundtruth_ecef.csv", g.truth, sc.frame, sc.leverArm);
}

/// 3-D structure along the route (features and GNSS).
void buildStructureStage(Generation& g) {
  const Scenario& sc = g.sc;
  g.features = g.opt.featuresOnly || sc.output == CameraOutput::Features;
  if (!sc.structure) return;
  if (!g.features && !sc.cameras.empty())
    throw std::invalid_argument("scenario '" + sc.name + "': 3-D structure gives feature tracks only (cameras.output: features)");
  g.urban = std::make_unique<UrbanStructure>(*sc.structure, horizontalRoute(*g.traj), hashCombine(g.seed, nameHash("structure")));
  g.sum.buildings = g.urban->buildings().size();
  if (g.log) *g.log << "[gvins-sim] structure: " << g.urban->buildings().size() << " buildings, " << g.urban->poles().size()
                    << " poles and trees along the route\n";
}

/// Camera stamps and times, and per camera its sensor.yaml, data.csv and true poses.
void cameraFilesStage(Generation& g) {
  const Scenario& sc = g.sc;
  if (!sc.cameras.empty()) {
    // Images at true (IMU) times t_k, stamped t_k − t_d (Scenario::cameraTimeOffset); the first
    // image is taken at the start or t_d later, so that no stamp precedes the IMU.
    const std::int64_t td = std::llround(sc.cameraTimeOffset * 1e9);
    const std::int64_t first = std::max<std::int64_t>(td, 0);
    const auto nFrames =
        static_cast<std::size_t>(std::floor((g.duration - static_cast<double>(first) * 1e-9) * sc.cameraRate + 1e-9)) + 1;
    for (std::size_t k = 0; k < nFrames; ++k) {
      const std::int64_t off = first + std::llround(static_cast<double>(k) * 1e9 / sc.cameraRate);
      g.stamps.push_back(sc.frame.startStampNs() + off - td);
      g.times.push_back(static_cast<double>(off) * 1e-9);
    }
  }
  g.sum.framesPerCamera = g.stamps.size();
  for (std::size_t c = 0; c < sc.cameras.size(); ++c) {
    const fs::path camDir = g.mav0 / ("cam" + std::to_string(c));
    fs::create_directories(camDir);
    vio::CameraCalibration cal = sc.cameras[c];
    cal.rate_hz = sc.cameraRate;
    writeCameraSensorYaml(camDir / "sensor.yaml", cal, sc.cameraRate,
                          g.features ? "gvins-sim camera (feature tracks in features.csv, no images)"
                                     : "gvins-sim rendered camera");
    writeCameraCsv(camDir / "data.csv", g.stamps);
    // True camera poses at the stamps.
    std::vector<Eigen::Matrix3d> R(g.stamps.size());
    std::vector<Eigen::Vector3d> p(g.stamps.size());
    const Eigen::Matrix3d R_BC = cal.T_BS.topLeftCorner<3, 3>();
    const Eigen::Vector3d p_BC = cal.T_BS.topRightCorner<3, 1>();
    for (std::size_t k = 0; k < g.stamps.size(); ++k) {
      const TrajectoryState s = g.traj->evaluate(g.times[k]);
      R[k] = s.R_WB * R_BC;
      p[k] = s.p_WB + s.R_WB * p_BC;
    }
    writeCameraPosesCsv(g.truthDir / ("cam" + std::to_string(c) + "_poses.csv"), g.stamps, R, p);
  }
}

/// Feature tracks of every camera (of the structure, else of a ground-plane landmark field) and
/// the landmarks seen.
void featuresStage(Generation& g) {
  const Scenario& sc = g.sc;
  const std::size_t nCams = sc.cameras.size();
  std::optional<LandmarkField> field;
  if (!g.urban) {
    double density = sc.features.densityPerM2;
    if (!(density > 0.0))
      density = autoLandmarkDensity(sc.cameras[0].intrinsics, medianCameraHeight(*g.traj, sc.cameras[0]),
                                    sc.features.landmarksPerImage);
    field.emplace(density, sc.features.heightSigma, hashCombine(g.seed, nameHash("landmarks")));
  }
  std::map<std::uint64_t, Eigen::Vector3d> seen;
  Progress prog(g.log, "feature frames", g.stamps.size() * nCams);
  for (std::size_t c = 0; c < nCams; ++c) {
    const FeatureSimulator fsim = g.urban ? FeatureSimulator(sc.cameras[c], sc.features, *g.urban, sc.imaging.lineTime)
                                          : FeatureSimulator(sc.cameras[c], sc.features, *field, sc.imaging.lineTime);
    const std::string cam = "cam" + std::to_string(c);
    TextFile obs(g.mav0 / cam / "features.csv");
    TextFile tru(g.truthDir / (cam + "_features.csv"));
    obs << "#timestamp [ns],landmark_id,u [px],v [px]\n";
    tru << "#timestamp [ns],landmark_id,u_true [px],v_true [px],outlier\n";
    for (std::size_t k = 0; k < g.stamps.size(); ++k) {
      std::vector<FeatureObservation> o;
      try {
        o = fsim.observe(*g.traj, g.times[k], hash4(g.seed, 0xFEA7, static_cast<std::int64_t>(c), static_cast<std::int64_t>(k)));
      } catch (const std::invalid_argument& e) {
        if (g.urban) throw;
        // A camera seeing far over the ground plane (looking forward from a vehicle).
        throw std::invalid_argument(std::string(e.what()) + " for " + cam + " at t = " + std::to_string(g.times[k]) +
                                    " s: the ground-plane landmarks suit downward cameras; give a forward-looking "
                                    "camera 3-D structure (scene.structure, docs/dataset_format.md)");
      }
      for (const FeatureObservation& f : o) {
        obs.integer(g.stamps[k]).put(',').unsignedInteger(f.landmark).put(',').fixed(f.pixel.x(), 4).put(',').fixed(f.pixel.y(), 4).put('\n');
        tru.integer(g.stamps[k]).put(',').unsignedInteger(f.landmark).put(',').fixed(f.truePixel.x(), 6).put(',').fixed(f.truePixel.y(), 6).put(',').integer(f.outlier ? 1 : 0).put('\n');
        seen.emplace(f.landmark, f.p_W);
      }
      g.sum.featureObservations += o.size();
      prog.step();
    }
    obs.close();
    tru.close();
  }
  TextFile lm(g.truthDir / "landmarks.csv");
  lm << "#landmark_id,p_W_x [m],p_W_y [m],p_W_z [m]\n";
  for (const auto& [id, pw] : seen) {
    lm.unsignedInteger(id).put(',').num(pw.x()).put(',').num(pw.y()).put(',').num(pw.z()).put('\n');
  }
  lm.close();
  g.sum.landmarks = seen.size();
  g.sum.meanFeaturesPerImage = static_cast<double>(g.sum.featureObservations) / static_cast<double>(std::max<std::size_t>(g.stamps.size() * nCams, 1));
}

/// Rendered images of every camera (PNG), on `opt.threads` threads.
void renderStage(Generation& g) {
  const Scenario& sc = g.sc;
  const std::size_t nCams = sc.cameras.size();
  const std::uint64_t seed = g.seed;
  GroundTextureConfig tc = sc.texture;
  tc.seed = hashCombine(seed, nameHash("texture"));
  const GroundTexture texture(tc);
  std::vector<std::unique_ptr<CameraRenderer>> renderers;
  std::vector<std::vector<double>> gains;
  for (std::size_t c = 0; c < nCams; ++c) {
    renderers.push_back(std::make_unique<CameraRenderer>(sc.cameras[c], sc.imaging, texture));
    gains.push_back(exposureGains(g.stamps.size(), sc.imaging, hashCombine(seed, 0x6A1 + c)));
    fs::create_directories(g.mav0 / ("cam" + std::to_string(c)) / "data");
  }
  const std::size_t total = g.stamps.size() * nCams;
  int threads = g.opt.threads > 0 ? g.opt.threads : static_cast<int>(std::thread::hardware_concurrency());
  threads = std::clamp(threads, 1, 64);
  std::atomic<std::size_t> next{0};
  std::atomic<std::size_t> blurSum{0};
  std::exception_ptr error;
  std::mutex errorMutex;
  Progress prog(g.log, "images", total);
  // Level 1 (the default) is written with OpenCV's parameter-less settings: zlib level 1, RLE
  // strategy and the "Sub" row filter on every row (lossless like any PNG: the same pixels).
  // Against an explicit level 1 (libpng then picks Average/Paeth rows), on 60 rendered 752x480
  // images of the default flight (2026-12-01, OpenCV 4.6): 211 vs 220 kB, encode 4.6 vs
  // 12.8 ms CPU, cv::imdecode 3.0 vs 4.5 ms CPU per image.
  std::vector<int> pngParams;
  if (sc.pngCompression != 1) pngParams = {cv::IMWRITE_PNG_COMPRESSION, sc.pngCompression};
  auto worker = [&] {
    std::vector<std::uint8_t> buf;
    for (;;) {
      const std::size_t i = next++;
      if (i >= total) return;
      {
        std::lock_guard<std::mutex> lock(errorMutex);
        if (error) return;
      }
      try {
        const std::size_t k = i / nCams, c = i % nCams;
        const CameraRenderer& r = *renderers[c];
        blurSum += static_cast<std::size_t>(r.blurSamples(*g.traj, g.times[k]));
        const cv::Mat img = r.render(*g.traj, g.times[k], gains[c][k],
                                     hash4(seed, 0x1A6E, static_cast<std::int64_t>(c), static_cast<std::int64_t>(k)));
        if (!cv::imencode(".png", img, buf, pngParams)) throw std::runtime_error("PNG encoding failed");
        const fs::path file = g.mav0 / ("cam" + std::to_string(c)) / "data" / (std::to_string(g.stamps[k]) + ".png");
        std::FILE* f = std::fopen(file.string().c_str(), "wb");
        if (!f) throw std::runtime_error("cannot create " + file.string());
        const bool ok = std::fwrite(buf.data(), 1, buf.size(), f) == buf.size();
        if (std::fclose(f) != 0 || !ok) throw std::runtime_error("write error on " + file.string());
        prog.step();
      } catch (...) {
        std::lock_guard<std::mutex> lock(errorMutex);
        if (!error) error = std::current_exception();
        return;
      }
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
  if (error) std::rethrow_exception(error);
  g.sum.meanBlurSamples = static_cast<double>(blurSum.load()) / static_cast<double>(std::max<std::size_t>(total, 1));
  g.sum.textureTiles = texture.tilesGenerated();
}

/// The GNSS part: simulated (through the structure when there is one), or a track scenario's
/// real rover files copied.
void gnssStage(Generation& g) {
  const Scenario& sc = g.sc;
  if (sc.gnss && g.opt.gnss) {
    GnssSimulator gsim(*sc.gnss);
    gsim.setProgressStream(g.log);
    if (g.urban) {
      // The rover's signals through the same buildings (W coordinates of the ECEF antenna and
      // direction); the buildings near the antenna are gathered again after 20 m of travel.
      struct Near {
        Eigen::Vector3d at = Eigen::Vector3d::Constant(1e300);
        std::vector<int> buildings;
      };
      auto near = std::make_shared<Near>();
      const UrbanStructure* world = g.urban.get();
      const LocalFrame frame = sc.frame;
      const Eigen::Matrix3d R_WE = frame.rotationEcefFromW().transpose();
      gsim.setRoverPathModel([world, frame, R_WE, near](const Eigen::Vector3d& antenna, const Eigen::Vector3d& toSat) {
        const Eigen::Vector3d p = frame.fromEcef(antenna);
        if ((p - near->at).norm() > 20.0) {
          near->at = p;
          near->buildings = buildingsNear(*world, p, 320.0);
        }
        return urbanSignalPath(*world, p, R_WE * toSat, near->buildings);
      });
    }
    const GnssSimSummary s = gsim.run(*g.traj, sc.frame, sc.leverArm, g.seed, g.dir);
    std::ostringstream os;
    s.print(os);
    g.sum.gnssSummary = os.str();
    g.gnssFiles = s.files;
  } else if (sc.trajectory == TrajectoryKind::Track && !sc.track.roverLog.empty() && g.opt.gnss) {
    g.gnssFiles = copyRealGnss(sc.track, g.dir / "gnss");
    g.sum.gnssSummary = "  GNSS                the real rover's files (" + std::to_string(g.gnssFiles.size()) + ") copied into gnss/\n";
  }
}

/// dataset.yaml: time, local frame, gravity, body frame and lever arm.
void writeYamlFrame(TextFile& f, const Generation& g) {
  const Scenario& sc = g.sc;
  const GpsTime t0 = sc.frame.startTime;
  const Eigen::Vector3d oe = sc.frame.originEcef();
  const Eigen::Matrix3d R = sc.frame.rotationEcefFromW();
  f << "# SRI-GVINS simulated dataset written by gvins-sim; layout and conventions: docs/dataset_format.md\n";
  f << "format: gvins-sim-dataset\nformat_version: 1\n";
  f << "scenario: " << yamlQuoted(sc.name) << "\ndescription: " << yamlQuoted(sc.description) << "\nseed: " << std::to_string(g.seed);
  f << "\ntime:\n  convention: \"sensor stamps (imu0, cam*, features, ground truth) are GPST nanoseconds since "
       "1980-01-06 00:00:00 GPST; GNSS epochs are GPST receiver time tags (see gnss/)\"\n";
  f << "  start_gpst: \"" << gpstString(t0) << "\"\n  start_ns: ";
  f.integer(sc.frame.startStampNs()) << "\n  gps_week: ";
  f.integer(t0.week()) << "\n  gps_tow_s: ";
  f.num(t0.tow()) << "\n  duration_s: ";
  f.num(g.duration) << "\n";
  f << "local_frame:\n  type: ENU\n  origin_latitude_deg: ";
  f.num(sc.frame.origin.lat * 180.0 / 3.14159265358979323846) << "\n  origin_longitude_deg: ";
  f.num(sc.frame.origin.lon * 180.0 / 3.14159265358979323846) << "\n  origin_height_m: ";
  f.num(sc.frame.origin.height) << "\n  origin_ecef_m: ";
  writeList(f, oe);
  f << "\n  R_ecef_local: [";
  for (int i = 0; i < 9; ++i) {
    f.num(R(i / 3, i % 3));
    if (i < 8) f << ", ";
  }
  f << "]  # row-major; p_ecef = origin_ecef + R p_local\n  ground_plane_z_m: 0\n";
  f << "gravity:\n  model: " << (sc.imu.earth == EarthModel::Rotating && sc.trajectory == TrajectoryKind::Flight ? "rotating" : "flat")
    << "  # flat: the IMU measures R^T (a + g e_z); rotating: Earth rate and normal gravity included\n  magnitude_mps2: ";
  f.num(g.gravity) << "\n";
  f << "body_frame: \"IMU frame (x forward, y left, z up); ground truth is the pose of this frame in the local frame\"\n";
  f << "lever_arm_m: ";
  writeList(f, sc.leverArm);
  f << "  # GNSS antenna phase centre in the body (IMU) frame\n";
}

/// dataset.yaml: trajectory and IMU.
void writeYamlTrajectory(TextFile& f, const Generation& g) {
  const Scenario& sc = g.sc;
  f << "trajectory:\n  type: "
    << (sc.trajectory == TrajectoryKind::Flight ? "flight" : sc.trajectory == TrajectoryKind::Track ? "gnss_track" : "recorded")
    << "\n";
  if (sc.trajectory == TrajectoryKind::Flight) {
    f << "  pattern: " << toString(sc.flight.pattern) << "\n  height_m: ";
    f.num(sc.flight.height) << "\n  length_m: ";
    f.num(sc.flight.length) << "\n  speed_mps: ";
    f.num(sc.flight.speed) << "\n";
  } else if (sc.trajectory == TrajectoryKind::Track) {
    writeTrackSection(f, sc.track, static_cast<const TrackTrajectory&>(*g.traj).report());
  } else {
    f << "  imu_csv: " << yamlQuoted(sc.recorded.imuCsv) << "\n  groundtruth_csv: " << yamlQuoted(sc.recorded.groundTruthCsv) << "\n";
  }
  f << "  path_length_m: ";
  f.num(g.sum.pathLength) << "\n  max_speed_mps: ";
  f.num(g.sum.maxSpeed) << "\n";
  f << "imu:\n  folder: mav0/imu0\n  source: " << yamlQuoted(g.imuSource) << "\n  rate_hz: ";
  f.num(g.sum.imuRate) << "\n  samples: ";
  f.integer(static_cast<std::int64_t>(g.imu.size())) << "\n  gyroscope_noise_density: ";
  f.num(g.noise.gyroscope_noise_density) << "\n  gyroscope_random_walk: ";
  f.num(g.noise.gyroscope_random_walk) << "\n  accelerometer_noise_density: ";
  f.num(g.noise.accelerometer_noise_density) << "\n  accelerometer_random_walk: ";
  f.num(g.noise.accelerometer_random_walk) << "\n";
  if (sc.trajectory == TrajectoryKind::Flight) {
    f << "  white_noise: " << (sc.imu.whiteNoise ? "true" : "false") << "\n  bias_random_walk: "
      << (sc.imu.biasRandomWalk ? "true" : "false") << "\n";
  }
  if (!g.truth.empty()) {
    f << "  initial_gyro_bias_radps: ";
    writeList(f, g.truth.front().bg);
    f << "\n  initial_accel_bias_mps2: ";
    writeList(f, g.truth.front().ba);
    f << "\n";
  }
}

/// dataset.yaml: cameras (output, timing, and per camera its files and calibration).
void writeYamlCameras(TextFile& f, const Generation& g) {
  const Scenario& sc = g.sc;
  const std::size_t nCams = sc.cameras.size();
  f << "cameras:\n  output: " << (g.features ? "features" : "images") << "\n  rate_hz: ";
  f.num(sc.cameraRate) << "\n  time_offset_s: ";
  f.num(sc.cameraTimeOffset) << "  # t_imu = t_cam + time_offset_s\n  frames: ";
  f.integer(static_cast<std::int64_t>(g.stamps.size()))
      << "\n  stamp: \"mid-exposure of the centre row\"\n  exposure_s: ";
  f.num(sc.imaging.exposure) << "\n  line_time_s: ";
  f.num(sc.imaging.lineTime) << "\n";
  if (g.features) {
    f << "  pixel_noise_px: ";
    f.num(sc.features.pixelNoise) << "\n  outlier_rate: ";
    f.num(sc.features.outlierRate) << "\n";
  }
  f << "  list:";
  if (nCams == 0) f << " []";
  f << "\n";
  for (std::size_t c = 0; c < nCams; ++c) {
    const std::string cam = "cam" + std::to_string(c);
    f << "    - name: " << cam << "\n      folder: mav0/" << cam << "\n      sensor_yaml: mav0/" << cam
      << "/sensor.yaml\n      " << (g.features ? "features: mav0/" + cam + "/features.csv" : "images: mav0/" + cam + "/data")
      << "\n      poses: truth/" << cam << "_poses.csv\n";
    // The calibration once more (the same numbers as sensor.yaml), so dataset.yaml alone
    // describes the rig.
    const vio::CameraIntrinsics& k = sc.cameras[c].intrinsics;
    f << "      resolution: [";
    f.integer(k.width) << ", ";
    f.integer(k.height) << "]\n      intrinsics: [";
    f.num(k.fx) << ", ";
    f.num(k.fy) << ", ";
    f.num(k.cx) << ", ";
    f.num(k.cy) << "]  # fu, fv, cu, cv\n      distortion_model: "
                << (k.model == vio::DistortionModel::Equidistant ? "equidistant" : "radial-tangential")
                << "\n      distortion_coefficients: [";
    for (int i = 0; i < 4; ++i) {
      f.num(k.model == vio::DistortionModel::None ? 0.0 : k.distortion[static_cast<std::size_t>(i)]);
      f << (i < 3 ? ", " : "]\n");
    }
    f << "      T_BS: [";
    for (int i = 0; i < 16; ++i) {
      f.num(sc.cameras[c].T_BS(i / 4, i % 4));
      f << (i < 15 ? ", " : "]  # row-major 4x4, camera in the body (IMU) frame: p_B = T_BS p_C\n");
    }
  }
}

/// dataset.yaml: the description of the whole dataset (docs/dataset_format.md).
void writeDatasetYaml(const Generation& g) {
  TextFile f(g.dir / "dataset.yaml");
  writeYamlFrame(f, g);
  writeYamlTrajectory(f, g);
  writeYamlCameras(f, g);
  f << "groundtruth:\n  local: mav0/state_groundtruth_estimate0/data.csv\n  ecef: truth/groundtruth_ecef.csv\n";
  if (g.features && !g.sc.cameras.empty()) f << "  landmarks: truth/landmarks.csv\n";
  f << "gnss:";
  if (g.gnssFiles.empty()) {
    f << " null\n";
  } else {
    f << "\n  folder: gnss\n  files:\n";
    for (const fs::path& p : g.gnssFiles) f << "    - " << yamlQuoted(fs::relative(p, g.dir).generic_string()) << "\n";
  }
  f.close();
}

}  // namespace

GenerationSummary generateDataset(const Scenario& sc, const fs::path& dir, const GenerationOptions& opt) {
  const auto tStart = Clock::now();
  GenerationSummary sum;
  sum.scenario = sc.name;
  sum.seed = opt.seed;
  sum.startGpst = gpstString(sc.frame.startTime);
  if (std::abs(sc.frame.startTime.fraction() * 1e9 - std::round(sc.frame.startTime.fraction() * 1e9)) > 1e-3)
    throw std::invalid_argument("the start time must be a whole nanosecond");
  Generation g(sc, dir, opt, sum);

  // ---- trajectory and IMU
  buildTrajectoryStage(g);
  if (sc.trajectory == TrajectoryKind::Flight) simulatedImuStage(g);
  else recordedImuStage(g);
  writeImuStage(g);
  sum.secondsTrajectoryImu = since(tStart);
  if (g.log) *g.log << "[gvins-sim] trajectory " << std::fixed << std::setprecision(1) << g.duration << " s, "
                    << g.imu.size() << " IMU samples\n" << std::defaultfloat;

  // ---- 3-D structure, cameras
  buildStructureStage(g);
  const auto tCam = Clock::now();
  sum.images = !g.features;
  sum.cameras = static_cast<int>(sc.cameras.size());
  cameraFilesStage(g);
  if (!sc.cameras.empty() && g.features) featuresStage(g);
  else if (!sc.cameras.empty()) renderStage(g);
  sum.secondsCameras = since(tCam);

  // ---- GNSS
  const auto tGnss = Clock::now();
  gnssStage(g);
  sum.secondsGnss = since(tGnss);

  writeDatasetYaml(g);
  if (!sc.text.empty()) {
    TextFile s(dir / "scenario.yaml");
    s << sc.text;
    s.close();
  }
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(dir, ec); !ec && it != fs::recursive_directory_iterator(); it.increment(ec))
    if (it->is_regular_file(ec)) sum.bytes += it->file_size(ec);
  sum.secondsTotal = since(tStart);
  return sum;
}

}  // namespace gvins::sim
