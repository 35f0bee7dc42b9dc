// SRI-SWF visual-inertial estimator (see sri_swf_estimator.hpp and docs/vio_estimator.md).
#include "gvins/vio/sri_swf_estimator.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <type_traits>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "gvins/sri/chi_square.hpp"
#include "gvins/sri/qr_update.hpp"
#include "gvins/vio/imu_propagation.hpp"
#include "gvins/vio/so3.hpp"
#include "gvins/vio/visual_inertial_initializer.hpp"
#include "gvins/vio/visual_jacobians.hpp"

namespace gvins::vio {
namespace {

using sri::BlockEstimate;
using sri::BlockId;
using sri::BlockSpec;
using sri::Placement;

template <typename S>
PoseEstimate poseOf(const BlockEstimate<S>& e) {
  PoseEstimate p;
  p.R_WI = e.rotation.template cast<double>().normalized().toRotationMatrix();
  p.p_WI = e.vector.template cast<double>().head(3);
  return p;
}

template <typename S>
BlockEstimate<S> poseEstimate(const Eigen::Matrix3d& R, const Eigen::Vector3d& p) {
  return BlockEstimate<S>::fromPose(Eigen::Quaterniond(R).normalized().cast<S>(), p.cast<S>());
}

}  // namespace

void applyFirstEstimates(Eigen::Matrix<double, 15, 15>& Phi, const Eigen::Matrix3d& R0, const Eigen::Vector3d& p0,
                         const Eigen::Vector3d& v0, const Eigen::Matrix3d& R1, const Eigen::Vector3d& p1,
                         const Eigen::Vector3d& v1, double dt, double gravity) {
  const Eigen::Vector3d g(0.0, 0.0, -gravity);
  // Attitude: Φ_θθ = ΔRᵀ maps the yaw direction R₀ᵀe_z to (R₀ΔR)ᵀe_z, not to R₁ᵀe_z when the
  // first estimate R₀ differs from the estimate R₁ was propagated from (a tilt correction since):
  // the smallest change that makes it so (rank one along w = R₀ᵀe_z, as the observability-
  // constrained transition of Hesch et al. 2014, eq. (35)); zero at Φ's own linearization point.
  const Eigen::Vector3d w = R0.transpose() * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d u = R1.transpose() * Eigen::Vector3d::UnitZ();
  Phi.block<3, 3>(ImuErr::kTheta, ImuErr::kTheta) += (u - Phi.block<3, 3>(ImuErr::kTheta, ImuErr::kTheta) * w) * w.transpose();
  Phi.block<3, 3>(ImuErr::kVel, ImuErr::kTheta) = -so3::skew(v1 - v0 - g * dt) * R0;
  Phi.block<3, 3>(ImuErr::kPos, ImuErr::kTheta) = -so3::skew(p1 - p0 - v0 * dt - 0.5 * dt * dt * g) * R0;
}

// ======================================================================================= Impl
template <typename Scalar>
struct SriSwfEstimator<Scalar>::Impl {
  using Filter = sri::SriFilter<Scalar>;
  using Meas = sri::Measurement<Scalar>;
  using MatrixS = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>;
  using VectorS = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>;

  struct Obs {
    BlockId clone;
    int cam = 0;
    Eigen::Vector2d z = Eigen::Vector2d::Zero();
  };
  struct Track {
    std::vector<Obs> obs;  // in time order, clones in the window only
    int frames = 0;        // frames with a cam0 observation in `obs`
  };
  struct Clone {
    BlockId id;
    std::int64_t t_ns = 0;
  };
  struct Slam {
    BlockId block;
    BlockId anchor;
    bool seen = false;  // observed in the current frame
  };

  const SriSwfConfig& cfg;
  Filter f;
  // Speculative joint SLAM update: update() only changes R and r, so only they are saved (a
  // copy of the whole filter also copied its capacity-sized buffers and workspaces).
  Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> backup_R;
  VectorS backup_r;
  ImuPropagator prop;
  std::vector<ImuSample> imu;
  bool initialized = false;
  std::int64_t t_newest = 0;
  ImuBlocks newest;
  std::int64_t t_bias = 0;  // when the bias block was last renewed (SriSwfConfig::imu_bias_renewal)
  std::deque<Clone> clones;
  std::vector<CameraExtrinsic> ext_fixed;  // configured (or carried over a reset) camera extrinsics
  double td_start = 0.0;  // t_d before the time-offset block exists: configured, or carried over a reset
  std::vector<BlockId> ext_ids;  // calibrate_extrinsics
  BlockId td_id;                 // calibrate_time_offset: t_d (1-dim)
  // Motion of each clone at its IMU time τ = t_cam + td (time-offset calibration): body angular
  // rate (bias-corrected), world velocity and the t_d estimate τ was made with.
  struct CloneMotion {
    Eigen::Vector3d w = Eigen::Vector3d::Zero();
    Eigen::Vector3d v = Eigen::Vector3d::Zero();
    double td = 0.0;
  };
  std::unordered_map<std::uint64_t, CloneMotion> clone_motion;
  std::vector<double> sigma_n;   // per camera: pixel noise in normalised units
  std::unordered_map<std::uint64_t, Track> tracks;
  std::unordered_map<std::uint64_t, Slam> slam;
  VisualInertialInitializer initializer;
  std::deque<FeatureFrame> recent;  // frames of the last init_window (zero-velocity detection)
  std::unordered_map<std::uint64_t, PoseEstimate> pose_cache;
  std::unordered_map<std::uint64_t, PoseEstimate> obs_pose_cache;  // poses at the image times
  void clearCaches() {
    pose_cache.clear();
    obs_pose_cache.clear();
  }
  // First estimates (first_estimate_jacobians): of every clone (its propagated pose) and of the
  // newest velocity.
  std::unordered_map<std::uint64_t, PoseEstimate> fe_pose;
  Eigen::Vector3d fe_v = Eigen::Vector3d::Zero();
  std::int64_t t_init = 0;
  mutable sri::ChiSquareQuantiles chi2_thr;  // visual gates (cfg.chi2_probability)
  sri::ChiSquareQuantiles client_gate;        // client gates (update(m, p))
  std::function<void(const char*)> observer;  // setStepObserver (diagnostics)
  void notify(const char* step) {
    if (observer) observer(step);
  }

  // Visual lock-out (SriSwfConfig::lockout_reset_s): features gated and rejected per frame over
  // the last lockout_reset_s, and whether they were ≥ 20 with ≥ 90 % rejected.
  struct GateCount {
    std::int64_t t_ns;
    int gated;
    int rejected;
  };
  std::deque<GateCount> gate_log;
  bool lockout = false;
  std::optional<std::int64_t> client_update_ns;  // newest applied client update (IMU time)
  std::uint64_t generation = 0;  // EstimatorBackend::generation: + 1 per initialisation and per reset
  int resets = 0;

  static sri::SriOptions filterOptions(const SriSwfConfig& c, std::uint64_t first_block_id) {
    sri::SriOptions o;
    o.first_block_id = first_block_id;
    if (c.float_householder) o.auto_givens_ratio_float = std::numeric_limits<double>::infinity();
    return o;
  }

  /// `first_block_id`: where the filter's block ids start (after a reset: the old filter's next id).
  Impl(const SriSwfConfig& c, std::uint64_t first_block_id)
      : cfg(c), f(filterOptions(c, first_block_id)), prop(c.imu, c.gravity), td_start(c.time_offset), initializer(c) {
    for (const CameraCalibration& cam : c.cameras) {
      CameraExtrinsic e;
      e.R_IC = Eigen::Quaterniond(Eigen::Matrix3d(cam.T_BS.topLeftCorner<3, 3>())).normalized().toRotationMatrix();
      e.p_IC = cam.T_BS.topRightCorner<3, 1>();
      ext_fixed.push_back(e);
      const double fmean = 0.5 * (cam.intrinsics.fx + cam.intrinsics.fy);
      sigma_n.push_back(c.pixel_noise / fmean);
    }
  }

  bool stereo() const { return cfg.cameras.size() > 1; }
  /// 1 / σ of an observation in normalised coordinates: pixel noise and surface noise at `depth`.
  double inverseSigma(int cam, double depth) const {
    const double sp = sigma_n[static_cast<std::size_t>(cam)];
    const double ss = cfg.surface_noise / depth;
    return 1.0 / std::sqrt(sp * sp + ss * ss);
  }

  double chi2Threshold(int dof) const {
    if (cfg.chi2_probability >= 1.0) return std::numeric_limits<double>::infinity();
    return chi2_thr(cfg.chi2_probability, dof);
  }

  /// Before a reset: the calibrated camera extrinsics and time offset become the start values of
  /// the next state (`next`, fresh from the configuration; the priors keep their configured σ),
  /// each only when it lies within 3 prior σ of its configured value (per axis, so √3·3σ in
  /// norm): a state that ran away may have dragged them off, and then the configuration is the
  /// better start.
  void carryCalibration(Impl& next) const {
    if (!initialized) return;
    const double k = 3.0 * std::sqrt(3.0);
    for (std::size_t c = 0; c < ext_ids.size() && c < next.ext_fixed.size(); ++c) {
      const CameraExtrinsic e = ext(static_cast<int>(c));
      const CameraExtrinsic& e0 = next.ext_fixed[c];
      const double dth = Eigen::AngleAxisd(e0.R_IC.transpose() * e.R_IC).angle();
      const double dp = (e.p_IC - e0.p_IC).norm();
      if (dth <= k * cfg.extrinsic_rotation_sigma && dp <= k * cfg.extrinsic_translation_sigma) next.ext_fixed[c] = e;
    }
    if (td_id.valid()) {
      const double td = timeOffset();
      if (std::abs(td - cfg.time_offset) <= 3.0 * cfg.time_offset_sigma) next.td_start = td;
    }
  }

  // ------------------------------------------------------------------ state access
  /// Mixed precision (sri_filter.hpp): blocks are created with values rounded to Scalar; a float
  /// filter then gets the double value it was computed as (R and r do not change).
  void setExact(BlockId id, const BlockEstimate<double>& v) {
    if constexpr (!std::is_same_v<Scalar, double>) f.setNominal(id, v);
  }
  CameraExtrinsic ext(int cam) const {
    if (!ext_ids.empty()) {
      const PoseEstimate p = poseOf(f.nominal(ext_ids[static_cast<std::size_t>(cam)]));
      return {p.R_WI, p.p_WI};
    }
    return ext_fixed[static_cast<std::size_t>(cam)];
  }
  const PoseEstimate& pose(BlockId id) {
    auto it = pose_cache.find(id.value);
    if (it == pose_cache.end()) it = pose_cache.emplace(id.value, poseOf(f.nominal(id))).first;
    return it->second;
  }
  /// Current t_d (s): the filter's estimate when calibrating, else td_start (the configured
  /// value, or the one carried over a reset).
  double timeOffset() const {
    if (td_id.valid()) return static_cast<double>(f.nominal(td_id).vector(0));
    return td_start;
  }
  /// Pose of clone `id` at the time its image was taken: the clone itself unless the time offset
  /// is calibrated, then the clone moved by its angular rate and velocity over t̂_d − td(clone).
  const PoseEstimate& obsPose(BlockId id) {
    if (!td_id.valid()) return pose(id);
    auto it = obs_pose_cache.find(id.value);
    if (it != obs_pose_cache.end()) return it->second;
    PoseEstimate P = pose(id);
    if (auto m = clone_motion.find(id.value); m != clone_motion.end()) {
      P = poseAfter(P, m->second.w, m->second.v, timeOffset() - m->second.td);
    }
    return obs_pose_cache.emplace(id.value, P).first->second;
  }
  /// ∂p_C/∂t_d of an observation from clone `id` (cp: its CameraPoint at the Jacobian's pose).
  Eigen::Vector3d timeOffsetColumn(BlockId id, const CameraPoint& cp) const {
    const auto m = clone_motion.find(id.value);
    if (m == clone_motion.end()) return Eigen::Vector3d::Zero();
    return timeOffsetJacobian(cp, m->second.w, m->second.v);
  }
  void recordCloneMotion(BlockId id, const ImuState& s, double td) {
    if (!cfg.calibrate_time_offset) return;
    CloneMotion m;
    m.v = s.v_WI;
    // Angular rate: the mean gyro over τ ± 10 ms (a single sample puts the full white gyro noise
    // into the t_d column), or the interpolated sample when the buffer has fewer than two there.
    // Measured: 60m-400m-8 feature tracks, t_d 15 ms: 14.968 → 14.973 ms; EuRoC static clip
    // (t_d unobservable): −2.0 ms (σ 2.5) → −1.9 ms (σ 2.8).
    constexpr std::int64_t kHalf = 10'000'000;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    int n = 0;
    auto it = std::lower_bound(imu.begin(), imu.end(), s.t_ns - kHalf,
                               [](const ImuSample& a, std::int64_t t) { return a.t_ns < t; });
    for (; it != imu.end() && it->t_ns <= s.t_ns + kHalf; ++it, ++n) sum += it->gyro;
    if (n >= 2) {
      m.w = sum / n - s.bg;
    } else if (imuCovers(s.t_ns, s.t_ns)) {
      m.w = interpolateImu(imuSpan(), s.t_ns).gyro - s.bg;
    }
    m.td = td;
    clone_motion[id.value] = m;
  }
  double frame_td = 0.0;  // t_d the current frame was shifted by (s, exact to the ns)

  /// Linearisation point of a clone for Jacobians: its first estimate, or the current estimate.
  const PoseEstimate& poseJ(BlockId id) {
    if (cfg.first_estimate_jacobians) {
      if (auto it = fe_pose.find(id.value); it != fe_pose.end()) return it->second;
    }
    return pose(id);
  }
  /// The bias block's value [bg; ba] of an IMU state.
  static Eigen::Matrix<double, 6, 1> biasVector(const ImuState& s) {
    Eigen::Matrix<double, 6, 1> b;
    b << s.bg, s.ba;
    return b;
  }
  ImuState newestState() const {
    ImuState s;
    if (!initialized) return s;
    s.t_ns = t_newest;
    const PoseEstimate p = poseOf(f.nominal(newest.pose));
    s.R_WI = p.R_WI;
    s.p_WI = p.p_WI;
    s.v_WI = f.nominal(newest.velocity).vector.template cast<double>();
    const Eigen::VectorXd b = f.nominal(newest.bias).vector.template cast<double>();
    s.bg = b.segment<3>(0);
    s.ba = b.segment<3>(3);
    return s;
  }

  // ------------------------------------------------------------------ IMU buffer
  void addImu(const ImuSample& s) {
    if (!imu.empty() && s.t_ns <= imu.back().t_ns) return;
    imu.push_back(s);
  }
  void trimImu() {
    if (imu.empty()) return;
    std::int64_t keep = imu.back().t_ns - static_cast<std::int64_t>(3.0e9);
    if (!initialized) {
      keep = imu.back().t_ns - static_cast<std::int64_t>((cfg.init_window + 2.0) * 1e9);
      if (auto t0 = initializer.oldestFrameTime()) keep = std::min(keep, *t0 - 100'000'000);
    } else if (!clones.empty()) {
      keep = std::min(keep, clones.front().t_ns - 100'000'000);
    }
    auto it = std::lower_bound(imu.begin(), imu.end(), keep,
                               [](const ImuSample& a, std::int64_t t) { return a.t_ns < t; });
    if (it - imu.begin() > 2000) imu.erase(imu.begin(), it - 1);  // amortised
  }
  std::span<const ImuSample> imuSpan() const { return {imu.data(), imu.size()}; }
  bool imuCovers(std::int64_t t0, std::int64_t t1) const { return vio::imuCovers(imuSpan(), t0, t1); }

  // ------------------------------------------------------------------ initialisation
  /// P: covariance in ImuErr order (external_initial_state.hpp); the per-block priors drop the
  /// correlations between pose, velocity and bias.
  void createState(const ImuState& s, const Matrix15d& Pimu) {
    const Eigen::Matrix<double, 6, 6> P = Pimu.topLeftCorner<6, 6>();
    const BlockId pid = f.addBlock(BlockSpec::pose("imu_pose"), poseEstimate<Scalar>(s.R_WI, s.p_WI),
                                   sri::Prior<Scalar>::covariance(P.cast<Scalar>()));
    setExact(pid, poseEstimate<double>(s.R_WI, s.p_WI));
    if (cfg.calibrate_extrinsics) {
      for (std::size_t c = 0; c < ext_fixed.size(); ++c) {
        Eigen::Matrix<Scalar, 6, 1> sd;
        sd << Eigen::Matrix<Scalar, 3, 1>::Constant(static_cast<Scalar>(cfg.extrinsic_rotation_sigma)),
            Eigen::Matrix<Scalar, 3, 1>::Constant(static_cast<Scalar>(cfg.extrinsic_translation_sigma));
        ext_ids.push_back(f.addBlock(BlockSpec::pose("T_IC" + std::to_string(c)),
                                     poseEstimate<Scalar>(ext_fixed[c].R_IC, ext_fixed[c].p_IC),
                                     sri::Prior<Scalar>::stdDevs(sd)));
        setExact(ext_ids.back(), poseEstimate<double>(ext_fixed[c].R_IC, ext_fixed[c].p_IC));
      }
    }
    if (cfg.calibrate_time_offset) {
      Eigen::Matrix<Scalar, 1, 1> x0, sd0;
      x0 << static_cast<Scalar>(frame_td);
      sd0 << static_cast<Scalar>(cfg.time_offset_sigma);
      td_id = f.addBlock(BlockSpec::vector("time_offset", 1), BlockEstimate<Scalar>::fromVector(x0),
                         sri::Prior<Scalar>::stdDevs(sd0));
      setExact(td_id, BlockEstimate<double>::fromVector(Eigen::Matrix<double, 1, 1>(frame_td)));
    }
    const Eigen::Matrix<double, 6, 1> xb = biasVector(s);
    const Eigen::Matrix<double, 6, 6> Pb = Pimu.bottomRightCorner<6, 6>();
    const Eigen::Matrix3d Pv = Pimu.block<3, 3>(ImuErr::kVel, ImuErr::kVel);
    // Bias, then velocity: with the extra last that is their order at the back; first, the
    // velocity goes in front of the bias.
    const BlockId bid = f.addBlock(BlockSpec::vector("imu_bias", 6), BlockEstimate<Scalar>::fromVector(xb.cast<Scalar>()),
                                   sri::Prior<Scalar>::covariance(Pb.cast<Scalar>()), extraPlacement());
    setExact(bid, BlockEstimate<double>::fromVector(xb));
    const BlockId vid = f.addBlock(BlockSpec::vector("imu_velocity", 3),
                                   BlockEstimate<Scalar>::fromVector(s.v_WI.cast<Scalar>()),
                                   sri::Prior<Scalar>::covariance(Pv.cast<Scalar>()), extraPlacement());
    setExact(vid, BlockEstimate<double>::fromVector(s.v_WI));
    newest = {pid, vid, bid};
    t_bias = s.t_ns;
    t_newest = s.t_ns;
    clones.push_back({pid, s.t_ns});
    recordCloneMotion(pid, s, frame_td);
    fe_pose[pid.value] = poseOf(f.nominal(pid));  // the gauge pose: its prior fixes it anyway
    fe_v = s.v_WI;
    t_init = s.t_ns;
    initialized = true;
    ++generation;
  }

  bool tryInitialize(const FeatureFrame& frame) {
    const std::optional<InitialState> s = initializer.tryInitialize(frame, imuSpan(), ext_fixed);
    if (!s) return false;
    createState(s->state, initialStateCovariance(*s, cfg));
    clearCaches();
    addObservations(frame);
    return true;
  }

  // ------------------------------------------------------------------ propagation
  bool propagateTo(std::int64_t t) {
    ImuState s = newestState();
    Matrix15d Phi, Qd;
    prop.propagate(s, imuSpan(), t, &Phi, &Qd);
    const double dt = static_cast<double>(t - t_newest) * 1e-9;
    if (cfg.first_estimate_jacobians) {
      if (auto it = fe_pose.find(newest.pose.value); it != fe_pose.end()) {
        applyFirstEstimates(Phi, it->second.R_WI, it->second.p_WI, fe_v, s.R_WI, s.p_WI, s.v_WI, dt, cfg.gravity);
      }
    }
    Qd.diagonal().array() += 1e-14;  // keeps Q' positive definite for back-to-back frames
    // Position random walk (SriSwfConfig::position_random_walk): white velocity noise of q m²/s
    // on the position rows, q·Δt per step, so it does not depend on how the interval is split.
    Qd.diagonal().segment<3>(3).array() += cfg.position_random_walk * cfg.position_random_walk * dt;
    Qd.diagonal().segment<3>(0).array() += cfg.attitude_random_walk * cfg.attitude_random_walk * dt;
    // The bias block is renewed every imu_bias_renewal seconds (0: at every propagation) with the
    // random walk of the whole time since the last renewal; in between, the new pose and velocity
    // rows act on the kept block (SriSwfConfig::imu_bias_renewal).
    const double since = static_cast<double>(t - t_bias) * 1e-9;
    const bool renew = cfg.imu_bias_renewal <= 0.0 || since >= cfg.imu_bias_renewal - 1e-3;
    const int d = renew ? 15 : 9;
    if (renew && since > dt) {
      const ImuNoise& q = prop.noise();
      Qd.block<3, 3>(ImuErr::kBg, ImuErr::kBg).diagonal().array() += q.gyroscope_random_walk * q.gyroscope_random_walk * (since - dt);
      Qd.block<3, 3>(ImuErr::kBa, ImuErr::kBa).diagonal().array() +=
          q.accelerometer_random_walk * q.accelerometer_random_walk * (since - dt);
    }
    sri::Propagation<Scalar> step;
    step.addNewBlock(BlockSpec::pose("imu_pose"), poseEstimate<Scalar>(s.R_WI, s.p_WI), Placement::after(newest.pose));
    step.addNewBlock(BlockSpec::vector("imu_velocity", 3), BlockEstimate<Scalar>::fromVector(s.v_WI.cast<Scalar>()),
                     extraPlacement());
    const Eigen::Matrix<double, 6, 1> xb = biasVector(s);
    if (renew) {
      // Placed like the velocity: at the back after it, or in front of it.
      step.addNewBlock(BlockSpec::vector("imu_bias", 6), BlockEstimate<Scalar>::fromVector(xb.cast<Scalar>()),
                       extraPlacement());
    }
    step.setTransition(newest.pose, Phi.topLeftCorner(d, 6).cast<Scalar>());
    step.setTransition(newest.velocity, Phi.block(0, 6, d, 3).cast<Scalar>());
    step.setTransition(newest.bias, Phi.topRightCorner(d, 6).cast<Scalar>());
    step.setNoiseCovariance(Qd.topLeftCorner(d, d).cast<Scalar>());
    step.marginalizeAfter(newest.velocity);
    if (renew) step.marginalizeAfter(newest.bias);
    const std::vector<BlockId> ids = f.propagate(step);
    setExact(ids[0], poseEstimate<double>(s.R_WI, s.p_WI));
    setExact(ids[1], BlockEstimate<double>::fromVector(s.v_WI));
    if (renew) {
      setExact(ids[2], BlockEstimate<double>::fromVector(xb));
      newest.bias = ids[2];
      t_bias = t;
    }
    newest.pose = ids[0];
    newest.velocity = ids[1];
    t_newest = t;
    clones.push_back({ids[0], t});
    recordCloneMotion(ids[0], s, frame_td);
    // Clones get first estimates once the initialisation transient is over (first_estimate_delay).
    if (static_cast<double>(t - t_init) * 1e-9 >= cfg.first_estimate_delay) {
      fe_pose[ids[0].value] = poseOf(f.nominal(ids[0]));
    }
    fe_v = s.v_WI;
    return true;
  }

  // ------------------------------------------------------------------ features
  void addObservations(const FeatureFrame& frame) {
    const BlockId c = newest.pose;
    for (const FeatureObservation& o : frame.features) {
      if (auto it = slam.find(o.id); it != slam.end()) {
        it->second.seen = true;
        continue;
      }
      Track& tr = tracks[o.id];
      tr.obs.push_back({c, 0, o.normalized0});
      if (stereo() && o.stereo) tr.obs.push_back({c, 1, o.normalized1});
      ++tr.frames;
    }
  }

  /// One observation as triangulation sees it: world-to-camera rotation, camera centre, bearing.
  struct Ray {
    Eigen::Matrix3d R_CW;
    Eigen::Vector3d c;
    Eigen::Vector2d z;
  };
  std::vector<Ray> rays;  // triangulate()'s buffer
  /// Whether the Jacobians linearize the newest velocity at fe_v: with first estimates, once the
  /// newest pose has one (unobservableDirections() and reanchorWorld() build N and B from it).
  bool velocityHasFirstEstimate() const {
    return cfg.first_estimate_jacobians && fe_pose.count(newest.pose.value) != 0;
  }
  /// EstimatorBackend::reanchorWorld: every clone (the newest pose is one) and the velocity in
  /// the extra change variables (world_frame_change.hpp), with the frame's Jacobian at the first
  /// estimates where they are used (the handed-over uncertainty then lies along the
  /// unobservable directions the visual rows keep: unobservableDirections()); the first
  /// estimates and clone velocities follow, the pose caches are dropped. SLAM features are
  /// anchored in a clone's camera and the calibration parameters live in the body: they do not
  /// change.
  WorldFrameChange reanchorWorld(BlockId frame) {
    std::vector<ReanchoredPose> poses;
    poses.reserve(clones.size());
    for (const Clone& c : clones) {
      ReanchoredPose rp{c.id, std::nullopt, std::nullopt};
      if (cfg.first_estimate_jacobians) {
        if (auto it = fe_pose.find(c.id.value); it != fe_pose.end()) {
          rp.R_lin = it->second.R_WI;
          rp.p_lin = it->second.p_WI;
        }
      }
      poses.push_back(rp);
    }
    const ReanchoredVelocity velocity[] = {
        {newest.velocity, velocityHasFirstEstimate() ? std::optional<Eigen::Vector3d>(fe_v) : std::nullopt}};
    const WorldFrameChange c = vio::reanchorWorld(f, frame, poses, velocity);
    for (auto& [id, P] : fe_pose) {
      P.R_WI = c.attitude(P.R_WI);
      P.p_WI = c.point(P.p_WI);
    }
    fe_v = c.direction(fe_v);
    for (auto& [id, m] : clone_motion) m.v = c.direction(m.v);
    clearCaches();
    return c;
  }

  /// Where the IMU extra (velocity and bias blocks) goes (SriSwfConfig::imu_extra_first).
  Placement extraPlacement() const { return cfg.imu_extra_first ? Placement::front() : Placement::back(); }
  /// A client's block: kFront in front of everything; parameters after the newest pose, i.e.
  /// at the back, or before the extra's blocks when they are last.
  Placement clientPlacement(ClientBlockRegion region) const {
    if (region == ClientBlockRegion::kFront) return Placement::front();
    if (cfg.imu_extra_first) return Placement::back();
    const bool biasFirst = f.layout().index(newest.bias) < f.layout().index(newest.velocity);
    return Placement::before(biasFirst ? newest.bias : newest.velocity);
  }

  /// Gauss-Newton triangulation (inverse depth in the first observing camera).
  bool triangulate(const std::vector<Obs>& obs, Eigen::Vector3d& p_W) {
    if (obs.size() < 2) return false;
    // The rays once (p_C = R_CW (p_W − c), as cameraPoint's p_C), then a linear initial guess:
    // the point closest to all rays.
    rays.resize(obs.size());
    Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
    Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
    for (std::size_t k = 0; k < obs.size(); ++k) {
      const PoseEstimate& P = obsPose(obs[k].clone);
      const CameraExtrinsic e = ext(obs[k].cam);
      Ray& ray = rays[k];
      ray.R_CW = e.R_IC.transpose() * P.R_WI.transpose();
      ray.c = P.p_WI + P.R_WI * e.p_IC;
      ray.z = obs[k].z;
      const Eigen::Vector3d b = (ray.R_CW.transpose() * Eigen::Vector3d(ray.z.x(), ray.z.y(), 1.0)).normalized();
      const Eigen::Matrix3d M = Eigen::Matrix3d::Identity() - b * b.transpose();
      A += M;
      rhs += M * ray.c;
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(A);
    if (es.eigenvalues()(0) < 1e-9 * es.eigenvalues()(2)) return false;
    p_W = A.ldlt().solve(rhs);
    const PoseEstimate& P0 = obsPose(obs[0].clone);
    const CameraExtrinsic e0 = ext(obs[0].cam);
    const Eigen::Vector3d c0 = rays[0].R_CW * (p_W - rays[0].c);
    if (!(c0.z() > cfg.min_depth)) return false;
    Eigen::Vector3d fpar(c0.x() / c0.z(), c0.y() / c0.z(), 1.0 / c0.z());
    for (int it = 0; it < 8; ++it) {
      const AnchoredPoint ap = anchoredPoint(fpar, P0, e0);
      Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
      Eigen::Vector3d g = Eigen::Vector3d::Zero();
      for (const Ray& ray : rays) {
        const Eigen::Vector3d p_C = ray.R_CW * (ap.p_W - ray.c);
        if (!(p_C.z() > 1e-6)) return false;
        const Eigen::Vector2d r = ray.z - p_C.head<2>() / p_C.z();
        const Eigen::Matrix<double, 2, 3> J = projectionJacobian(p_C) * ray.R_CW * ap.J_feature;
        H += J.transpose() * J;
        g += J.transpose() * r;
      }
      const Eigen::Vector3d d = H.ldlt().solve(g);
      if (!d.allFinite()) return false;
      fpar += d;
      if (!(fpar.z() > 0.0)) return false;
      if (d.norm() < 1e-10 * (1.0 + fpar.norm())) break;
    }
    p_W = anchoredPoint(fpar, P0, e0).p_W;
    double depth0 = 0.0, base = 0.0;
    for (std::size_t k = 0; k < rays.size(); ++k) {
      const double z = (rays[k].R_CW * (p_W - rays[k].c)).z();
      if (!(z >= cfg.min_depth && z <= cfg.max_depth)) return false;
      if (k == 0) depth0 = z;
      base = std::max(base, (rays[k].c - rays[0].c).norm());
    }
    return base >= cfg.min_baseline_ratio * depth0;
  }

  /// Declares the block columns of a feature's rows at once (one allocation): the feature and
  /// anchor blocks (if valid), the observing clones, the extrinsics.
  std::vector<BlockId> decl_ids;
  std::vector<int> decl_dims;
  std::vector<std::uint64_t> observed_ids;  // processImuTime's per-frame list (capacity kept)
  void declareBlocks(Meas& m, BlockId feature, BlockId anchor, const std::vector<Obs>& obs) {
    decl_ids.clear();
    decl_dims.clear();
    auto add = [&](BlockId id, int d) {
      if (std::find(decl_ids.begin(), decl_ids.end(), id) != decl_ids.end()) return;
      decl_ids.push_back(id);
      decl_dims.push_back(d);
    };
    if (feature.valid()) add(feature, 3);
    if (anchor.valid()) add(anchor, 6);
    for (const Obs& o : obs) add(o.clone, 6);
    for (BlockId e : ext_ids) add(e, 6);
    if (td_id.valid()) add(td_id, 1);
    m.addBlocks(decl_ids, decl_dims);
  }

  /// Rows of a feature at world point p_W (nuisance columns) for the listed observations; the
  /// Jacobians at p_J (default p_W; a new SLAM feature's at the point its first-estimate anchor
  /// gives, as slamRows).
  void featureRows(const std::vector<Obs>& obs, const Eigen::Vector3d& p_W, Meas& m,
                   const Eigen::Vector3d* p_J = nullptr) {
    m.reset(2 * static_cast<int>(obs.size()));
    declareBlocks(m, BlockId{}, BlockId{}, obs);
    auto N = m.nuisance(3);
    for (std::size_t k = 0; k < obs.size(); ++k) {
      const Obs& o = obs[k];
      const int r = 2 * static_cast<int>(k);
      // Jacobians at the first estimates, the residual at the current poses (p_C only).
      const bool fej = cfg.first_estimate_jacobians;
      const CameraPoint cj = cameraPoint(fej ? poseJ(o.clone) : obsPose(o.clone), ext(o.cam), p_J ? *p_J : p_W);
      const Eigen::Vector3d p_C = fej || p_J ? pointInCamera(obsPose(o.clone), ext(o.cam), p_W) : cj.p_C;
      const double is = inverseSigma(o.cam, p_C.z());
      const Eigen::Matrix<double, 2, 3> Jp = is * projectionJacobian(cj.p_C);
      m.jacobian(o.clone, 6).middleRows(r, 2) += (Jp * cj.J_pose).template cast<Scalar>();
      if (!ext_ids.empty()) {
        m.jacobian(ext_ids[static_cast<std::size_t>(o.cam)], 6).middleRows(r, 2) +=
            (Jp * cj.J_ext).template cast<Scalar>();
      }
      if (td_id.valid()) {
        m.jacobian(td_id, 1).middleRows(r, 2) += (Jp * timeOffsetColumn(o.clone, cj)).template cast<Scalar>();
      }
      N.middleRows(r, 2) = (Jp * cj.J_point).template cast<Scalar>();
      m.residual().segment(r, 2) = (is * (o.z - p_C.head<2>() / p_C.z())).template cast<Scalar>();
    }
    m.setWhitened();
  }

  /// Rows of a SLAM feature (state block) for observations from the listed clones.
  bool slamRows(const Slam& s, const std::vector<Obs>& obs, Meas& m) {
    m.reset(2 * static_cast<int>(obs.size()));
    declareBlocks(m, s.block, s.anchor, obs);
    const Eigen::Vector3d fx = f.nominal(s.block).vector.template cast<double>();
    const AnchoredPoint ap = anchoredPoint(fx, pose(s.anchor), ext(0));
    // Jacobians at the first estimates of anchor and clone (the residual at the current ones).
    const bool fej = cfg.first_estimate_jacobians;
    const AnchoredPoint apj = fej ? anchoredPoint(fx, poseJ(s.anchor), ext(0)) : ap;
    for (std::size_t k = 0; k < obs.size(); ++k) {
      const Obs& o = obs[k];
      const int r = 2 * static_cast<int>(k);
      const Eigen::Vector3d p_C = pointInCamera(obsPose(o.clone), ext(o.cam), ap.p_W);
      if (!(p_C.z() > cfg.min_depth)) return false;
      const CameraPoint cj = cameraPoint(fej ? poseJ(o.clone) : obsPose(o.clone), ext(o.cam), apj.p_W);
      const double is = inverseSigma(o.cam, p_C.z());
      const Eigen::Matrix<double, 2, 3> Jp = is * projectionJacobian(cj.p_C);
      const Eigen::Matrix<double, 2, 3> A = Jp * cj.J_point;
      m.jacobian(s.block, 3).middleRows(r, 2) += (A * apj.J_feature).template cast<Scalar>();
      m.jacobian(s.anchor, 6).middleRows(r, 2) += (A * apj.J_anchor).template cast<Scalar>();
      m.jacobian(o.clone, 6).middleRows(r, 2) += (Jp * cj.J_pose).template cast<Scalar>();
      if (!ext_ids.empty()) {
        m.jacobian(ext_ids[0], 6).middleRows(r, 2) += (A * apj.J_ext).template cast<Scalar>();
        m.jacobian(ext_ids[static_cast<std::size_t>(o.cam)], 6).middleRows(r, 2) +=
            (Jp * cj.J_ext).template cast<Scalar>();
      }
      if (td_id.valid()) {
        m.jacobian(td_id, 1).middleRows(r, 2) += (Jp * timeOffsetColumn(o.clone, cj)).template cast<Scalar>();
      }
      m.residual().segment(r, 2) = (is * (o.z - p_C.head<2>() / p_C.z())).template cast<Scalar>();
    }
    m.setWhitened();
    triangularizeBlock(m, s.block, 3);
    return true;
  }

  /// Rotates the rows of m (Givens, orthogonal: same information and χ²) so that its columns of
  /// block `id` are upper triangular: rows ≥ d then have exact zeros there and start at a later
  /// column of R. For a stereo SLAM re-observation (4 rows, 3 feature columns) one of the four
  /// rows no longer starts at the feature, i.e. it skips the columns of all SLAM features in
  /// the update (docs/vio_estimator.md, speed).
  static void triangularizeBlock(Meas& m, BlockId id, int d) {
    const int rows = m.rows();
    if (rows <= d) return;
    int b = -1;
    for (int i = 0; i < m.numBlocks(); ++i) {
      if (m.blockId(i) == id) b = i;
    }
    if (b < 0) return;
    for (int j = 0; j < d; ++j) {
      for (int i = rows - 1; i > j; --i) {
        auto F = m.jacobianAt(b);
        const Scalar y = F(i, j);
        if (y == Scalar(0)) continue;
        Scalar c, sn;
        sri::makeGivens(F(i - 1, j), y, c, sn);
        m.rotateRows(i - 1, i, c, sn);
        F(i, j) = Scalar(0);
      }
    }
  }

  /// Stacks whitened measurements without nuisance columns into one (single allocation).
  static void stackAll(const std::vector<Meas>& ms, Meas& out) {
    int rows = 0;
    std::vector<BlockId> ids;
    std::vector<int> dims;
    for (const Meas& m : ms) {
      rows += m.rows();
      for (int i = 0; i < m.numBlocks(); ++i) {
        if (std::find(ids.begin(), ids.end(), m.blockId(i)) != ids.end()) continue;
        ids.push_back(m.blockId(i));
        dims.push_back(m.blockDim(i));
      }
    }
    out.reset(rows);
    out.addBlocks(ids, dims);  // one allocation
    int r0 = 0;
    for (const Meas& m : ms) {
      for (int i = 0; i < m.numBlocks(); ++i) {
        out.jacobian(m.blockId(i), m.blockDim(i)).middleRows(r0, m.rows()) = m.jacobianAt(i);
      }
      out.residual().segment(r0, m.rows()) = m.residual();
      r0 += m.rows();
    }
    out.setWhitened();
  }

  // Window covariance for gating MSCKF-type rows (clones, extrinsics, time offset): once per
  // frame a factor Pw = F Fᵀ (SriFilter::covarianceFactor: the window's rows of the inverse of
  // the trailing block of R, which starts at the oldest clone; no covariance is formed), then
  // χ² = zᵀ(I + G Gᵀ)⁻¹z with G = H F per feature. H is zero before the first block it touches
  // (s), and the window blocks lead the trailing block in this order, so F[s:, :s] = 0 and
  // G = H[:, s:] F[s:, s:] (fewer flops for short tracks on the newest clones); I + G Gᵀ is a
  // rank update. Cheaper than SriFilter::chiSquare's per-feature triangular solve and QR. Valid
  // when r = 0 (right after correct()). Two exact bounds decide most features without G:
  // I ≤ I + G Gᵀ ≤ (1 + ‖H‖²_F tr(Pw)) I, so χ² ≤ ‖z‖² (accept when ‖z‖² is below the
  // threshold) and χ² ≥ ‖z‖² / (1 + ‖H‖²_F tr(Pw)) (reject when that is above it).
  Eigen::MatrixXd Fw;
  double pw_trace = 0.0;
  bool fw_leading_triangular = false;
  std::unordered_map<std::uint64_t, int> pw_off;
  mutable Eigen::MatrixXd gate_H, gate_G, gate_S;
  mutable Eigen::VectorXd gate_z;
  void windowCovariance() {
    std::vector<BlockId> ids;
    pw_off.clear();
    int off = 0;
    for (const Clone& c : clones) {
      ids.push_back(c.id);
      pw_off[c.id.value] = off;
      off += 6;
    }
    for (BlockId e : ext_ids) {
      ids.push_back(e);
      pw_off[e.value] = off;
      off += 6;
    }
    if (td_id.valid()) {
      ids.push_back(td_id);
      pw_off[td_id.value] = off;
      off += 1;
    }
    Fw = f.covarianceFactor(ids).template cast<double>();
    pw_trace = Fw.squaredNorm();
    // The structure the gate uses (checked, not assumed: client blocks could sit in between).
    const int d = static_cast<int>(Fw.rows());
    fw_leading_triangular = Fw.cols() >= d;
    for (int j = 0; j < d && fw_leading_triangular; ++j) {
      fw_leading_triangular = Fw.col(j).tail(d - j - 1).isZero(0.0);
    }
  }
  bool gateWindow(const Meas& m) const {
    if (cfg.chi2_probability >= 1.0) return true;
    const int rows = m.rows();
    const double thr = chi2Threshold(rows);
    const double zz = static_cast<double>(m.residual().squaredNorm());
    if (zz <= thr) return true;
    double hh = 0.0;
    for (int i = 0; i < m.numBlocks(); ++i) hh += static_cast<double>(m.jacobianAt(i).squaredNorm());
    if (zz > thr * (1.0 + hh * pw_trace)) return false;
    const int d = static_cast<int>(Fw.rows());
    int s0 = d;
    for (int i = 0; i < m.numBlocks(); ++i) s0 = std::min(s0, pw_off.at(m.blockId(i).value));
    const int k = d - s0;
    gate_H.setZero(rows, k);
    for (int i = 0; i < m.numBlocks(); ++i) {
      gate_H.middleCols(pw_off.at(m.blockId(i).value) - s0, m.blockDim(i)) = m.jacobianAt(i).template cast<double>();
    }
    const int cols = static_cast<int>(Fw.cols());
    if (fw_leading_triangular) {
      gate_G.noalias() = gate_H * Fw.bottomRightCorner(k, cols - s0);
    } else {
      gate_G.noalias() = gate_H * Fw.bottomRows(k);
    }
    gate_S.setIdentity(rows, rows);
    gate_S.template selfadjointView<Eigen::Lower>().rankUpdate(gate_G);
    const Eigen::LLT<Eigen::MatrixXd> llt(gate_S);
    if (llt.info() != Eigen::Success) return false;
    gate_z = m.residual().template cast<double>();
    llt.matrixL().solveInPlace(gate_z);
    return gate_z.squaredNorm() <= thr;
  }

  bool gate(const Meas& m) const {
    if (cfg.chi2_probability >= 1.0) return true;
    const auto c = f.chiSquare(m);
    return c && static_cast<double>(c->value) <= chi2Threshold(c->dof);
  }

  /// Re-anchors SLAM features anchored at `old_anchor` to the newest clone: with reanchor_sigma 0
  /// an exact change of variables of each feature block in place (SriFilter::substitute), else a
  /// Propagation with that noise into new blocks, then the old blocks are marginalized.
  /// Features that cannot be re-anchored are returned for marginalization.
  std::vector<BlockId> reanchor(BlockId old_anchor) {
    std::vector<std::uint64_t> ids;
    std::vector<BlockId> drop;
    for (auto& [id, s] : slam) {
      if (s.anchor == old_anchor) ids.push_back(id);
    }
    if (ids.empty()) return drop;
    std::sort(ids.begin(), ids.end());
    const PoseEstimate& Pa = pose(old_anchor);
    const PoseEstimate& Pb = pose(newest.pose);
    const PoseEstimate& PaJ = poseJ(old_anchor);
    const PoseEstimate& PbJ = poseJ(newest.pose);
    const CameraExtrinsic e0 = ext(0);
    struct Item {
      std::uint64_t id;
      Eigen::Vector3d fnew;
      Eigen::Matrix3d Jf;
      Eigen::Matrix<double, 3, 6> Ja, Jb, Je;
    };
    std::vector<Item> items;
    for (std::uint64_t id : ids) {
      Slam& s = slam[id];
      const Eigen::Vector3d fx = f.nominal(s.block).vector.template cast<double>();
      const AnchoredPoint ap0 = anchoredPoint(fx, Pa, e0);
      CameraPoint cp0;
      const Eigen::Vector3d fn = inverseDepthOf(ap0.p_W, Pb, e0, nullptr, &cp0);
      if (!(cp0.p_C.z() > cfg.min_depth)) {
        drop.push_back(s.block);
        slam.erase(id);
        continue;
      }
      // Jacobians at the first estimates of both anchors (first_estimate_jacobians).
      const AnchoredPoint ap = anchoredPoint(fx, PaJ, e0);
      Eigen::Matrix3d D;
      CameraPoint cp;
      inverseDepthOf(ap.p_W, PbJ, e0, &D, &cp);
      Item it;
      it.id = id;
      it.fnew = fn;
      it.Jf = D * cp.J_point * ap.J_feature;
      it.Ja = D * cp.J_point * ap.J_anchor;
      it.Jb = D * cp.J_pose;
      it.Je = D * (cp.J_point * ap.J_ext + cp.J_ext);
      items.push_back(it);
    }
    if (items.empty()) return drop;
    if (!(cfg.reanchor_sigma > 0.0)) {
      // Without noise the re-anchoring is an exact change of variables of each feature block in
      // place (SriFilter::substitute: its columns and own rows only, no new block, no sweep).
      for (const Item& it : items) {
        Slam& s = slam[it.id];
        std::vector<std::pair<BlockId, MatrixS>> B;
        B.emplace_back(old_anchor, it.Ja.template cast<Scalar>());
        B.emplace_back(newest.pose, it.Jb.template cast<Scalar>());
        if (!ext_ids.empty()) B.emplace_back(ext_ids[0], it.Je.template cast<Scalar>());
        f.substitute(s.block, MatrixS(it.Jf.template cast<Scalar>()), B, BlockEstimate<double>::fromVector(it.fnew));
        s.anchor = newest.pose;
      }
      return drop;
    }
    const int K = static_cast<int>(items.size());
    sri::Propagation<Scalar> step;
    MatrixS Pa_phi = MatrixS::Zero(3 * K, 6), Pb_phi = MatrixS::Zero(3 * K, 6), Pe_phi = MatrixS::Zero(3 * K, 6);
    VectorS q(3 * K);
    for (int k = 0; k < K; ++k) {
      const Item& it = items[static_cast<std::size_t>(k)];
      const Slam& s = slam[it.id];
      step.addNewBlock(BlockSpec::vector("slam", 3), BlockEstimate<Scalar>::fromVector(it.fnew.template cast<Scalar>()),
                       Placement::after(s.block));
      MatrixS Pf = MatrixS::Zero(3 * K, 3);
      Pf.middleRows(3 * k, 3) = it.Jf.template cast<Scalar>();
      step.setTransition(s.block, Pf);
      Pa_phi.middleRows(3 * k, 3) = it.Ja.template cast<Scalar>();
      Pb_phi.middleRows(3 * k, 3) = it.Jb.template cast<Scalar>();
      Pe_phi.middleRows(3 * k, 3) = it.Je.template cast<Scalar>();
      const double sg = cfg.reanchor_sigma;
      q.segment(3 * k, 3) << Scalar(sg * sg), Scalar(sg * sg), Scalar(sg * sg * it.fnew.z() * it.fnew.z());
      step.marginalizeAfter(s.block);
    }
    step.setTransition(old_anchor, Pa_phi);
    step.setTransition(newest.pose, Pb_phi);
    if (!ext_ids.empty()) step.setTransition(ext_ids[0], Pe_phi);
    step.setNoiseCovariance(MatrixS(q.asDiagonal()));
    const std::vector<BlockId> nids = f.propagate(step);
    for (int k = 0; k < K; ++k) {
      Slam& s = slam[items[static_cast<std::size_t>(k)].id];
      s.block = nids[static_cast<std::size_t>(k)];
      s.anchor = newest.pose;
      setExact(s.block, BlockEstimate<double>::fromVector(items[static_cast<std::size_t>(k)].fnew));
    }
    return drop;
  }

  /// The four unobservable directions of VIO (global yaw about the z axis through the origin,
  /// global x, y, z translation) in the current error state, at the linearisation points the
  /// Jacobians use (first estimates where the clones have them): clones δθ = R̂ᵀe_z, δp = e_z × p̂
  /// (yaw) and δp = e_k (translation); IMU velocity δv = e_z × v̂; IMU bias, SLAM features
  /// (anchored inverse depth), extrinsics and client blocks 0.
  Eigen::MatrixXd unobservableDirections() const {
    Eigen::MatrixXd N = Eigen::MatrixXd::Zero(f.dim(), 4);
    if (!initialized) return N;
    const Eigen::Vector3d ez = Eigen::Vector3d::UnitZ();
    const bool fej = cfg.first_estimate_jacobians;
    for (const sri::BlockInfo& b : f.layout().blocks()) {
      if (b.id == newest.velocity) {
        const Eigen::Vector3d v = velocityHasFirstEstimate() ? fe_v : Eigen::Vector3d(f.nominal(b.id).vector);
        N.block<3, 1>(b.offset, 0) = ez.cross(v);
        continue;
      }
      const bool is_clone =
          std::any_of(clones.begin(), clones.end(), [&](const Clone& c) { return c.id == b.id; });
      if (!is_clone) continue;
      PoseEstimate P;
      auto it = fe_pose.find(b.id.value);
      P = (fej && it != fe_pose.end()) ? it->second : poseOf(f.nominal(b.id));
      N.block<3, 1>(b.offset, 0) = P.R_WI.transpose() * ez;
      N.block<3, 1>(b.offset + 3, 0) = ez.cross(P.p_WI);
      N.block<3, 3>(b.offset + 3, 1).setIdentity();
    }
    return N;
  }

  /// Frames enter in IMU time: t_cam + t̂_d (rounded to the ns; frame_td is the exact shift).
  FrameResult process(const FeatureFrame& input) {
    const double td = timeOffset();
    const auto shift = static_cast<std::int64_t>(std::llround(td * 1e9));
    frame_td = static_cast<double>(shift) * 1e-9;
    if (shift == 0) return processImuTime(input);
    FeatureFrame shifted = input;
    shifted.t_ns += shift;
    return processImuTime(shifted);
  }
  FrameResult processImuTime(const FeatureFrame& frame) {
    FrameResult res;
    clearCaches();
    if (!initialized) {
      res.initialized = tryInitialize(frame);
      res.init_status = initializer.status();
      trimImu();
      return res;
    }
    res.initialized = true;
    res.init_status = InitStatus::kInitialized;
    if (frame.t_ns <= t_newest || !imuCovers(t_newest, frame.t_ns)) {
      res.slam_features = static_cast<int>(slam.size());
      return res;
    }
    const BlockId previous_pose = newest.pose;
    propagateTo(frame.t_ns);
    notify("propagate");
    // Zero-velocity update at a detected standstill (as at the static initialisation): v = 0 and
    // no displacement since the previous clone. Without it a mono rig at rest has no
    // triangulable features and drifts with the IMU.
    recent.push_back(frame);
    while (!recent.empty() && frame.t_ns - recent.front().t_ns > static_cast<std::int64_t>(cfg.init_window * 1.5e9)) {
      recent.pop_front();
    }
    if (cfg.zero_velocity_update) {
      Eigen::Vector3d ma, mg;
      int n = 0;
      // Without tracks (init_static_without_tracks) the IMU alone decides; the χ² gate rejects the
      // update when the state is known to move (a constant-velocity climb has a quiet IMU too).
      const Standstill st = standstill(cfg, imuSpan(), frame, recent, ma, mg, n);
      if (st == Standstill::kYes || (st == Standstill::kImuOnly && cfg.init_static_without_tracks)) {
        const ImuState s = newestState();
        const PoseEstimate prev = poseOf(f.nominal(previous_pose));
        Meas z(6);
        const double sv = cfg.zero_velocity_sigma;
        const double sp = sv * static_cast<double>(frame.t_ns - recent[recent.size() - 2].t_ns) * 1e-9;
        z.jacobian(newest.velocity, 3).setIdentity();
        z.jacobian(newest.pose, 6).block(3, 3, 3, 3).setIdentity();
        z.jacobian(previous_pose, 6).block(3, 3, 3, 3) = -Eigen::Matrix<Scalar, 3, 3>::Identity();
        z.residual().head(3) = (-s.v_WI).template cast<Scalar>();
        z.residual().tail(3) = (prev.p_WI - s.p_WI).template cast<Scalar>();
        Eigen::Matrix<Scalar, 6, 1> sd;
        sd << Eigen::Matrix<Scalar, 3, 1>::Constant(Scalar(sv)), Eigen::Matrix<Scalar, 3, 1>::Constant(Scalar(sp));
        z.whitenStdDevs(sd);
        if (gate(z)) {
          f.update(z);
          res.updated = true;
          res.zero_velocity = true;
          notify("zupt");
        }
      }
    }
    for (auto& [id, s] : slam) s.seen = false;
    addObservations(frame);
    const bool dropping = static_cast<int>(clones.size()) > cfg.window;
    const BlockId oldest = clones.front().id;
    // Ids seen in this frame, sorted (binary search: ~150 ids, looked up for every track).
    std::vector<std::uint64_t>& observed = observed_ids;
    observed.clear();
    for (const FeatureObservation& o : frame.features) observed.push_back(o.id);
    std::sort(observed.begin(), observed.end());
    auto isObserved = [&observed](std::uint64_t id) { return std::binary_search(observed.begin(), observed.end(), id); };

    // 1. SLAM re-observations (newest clone). The update's post-fit residual ‖e‖² equals the
    // innovation χ² (docs/sri_core.md §5), so all rows are applied at once (R and r saved
    // before) and kept if the joint χ² passes; only otherwise is every feature tested on its
    // own (SriFilter::chiSquare, a triangular solve from the feature's column each).
    Meas total;
    std::vector<Meas> parts;
    std::vector<BlockId> lost_slam;
    {
      std::vector<std::uint64_t> part_ids;
      for (const FeatureObservation& o : frame.features) {
        auto it = slam.find(o.id);
        if (it == slam.end()) continue;
        std::vector<Obs> obs{{newest.pose, 0, o.normalized0}};
        if (stereo() && o.stereo) obs.push_back({newest.pose, 1, o.normalized1});
        parts.emplace_back();
        if (slamRows(it->second, obs, parts.back())) {
          part_ids.push_back(o.id);
        } else {
          parts.pop_back();
          it->second.seen = false;  // behind the camera: treat as lost
        }
      }
      if (!parts.empty()) {
        backup_R = f.rawR();
        backup_r = f.rawResidual();
        const sri::UpdateResult<Scalar> u = f.update(std::span<const Meas>(parts));
        res.gated_features += static_cast<int>(parts.size());
        if (static_cast<double>(u.chi2) <= chi2Threshold(u.dof)) {
          res.updated = true;
        } else {
          f.rawR() = backup_R;
          f.rawResidual() = backup_r;
          std::vector<Meas> kept;
          for (std::size_t k = 0; k < parts.size(); ++k) {
            if (gate(parts[k])) {
              kept.push_back(std::move(parts[k]));
            } else {
              slam[part_ids[k]].seen = false;
              ++res.rejected_features;
            }
          }
          if (!kept.empty()) {
            f.update(std::span<const Meas>(kept));
            res.updated = true;
          }
        }
        notify("slam_update");
      }
      std::vector<std::uint64_t> sids;
      for (auto& [id, s] : slam) sids.push_back(id);
      std::sort(sids.begin(), sids.end());
      for (std::uint64_t id : sids) {
        if (!slam[id].seen) {
          lost_slam.push_back(slam[id].block);
          slam.erase(id);
        }
      }
    }

    if (res.updated) {
      f.correct();
      notify("correct");
    }
    clearCaches();
    windowCovariance();

    // 2. Candidates: lost tracks and window-long tracks.
    struct Cand {
      std::uint64_t id;
      int frames;
      bool alive;
    };
    std::vector<Cand> cands;
    for (auto& [id, tr] : tracks) {
      const bool alive = isObserved(id);
      if (!alive) {
        if (tr.frames >= cfg.min_track_msckf) cands.push_back({id, tr.frames, false});
      } else if (dropping && !tr.obs.empty() && tr.obs.front().clone == oldest) {
        cands.push_back({id, tr.frames, true});
      }
    }
    std::sort(cands.begin(), cands.end(), [](const Cand& a, const Cand& b) {
      return a.frames != b.frames ? a.frames > b.frames : a.id < b.id;
    });
    // 2a. SLAM initialisation from window-long tracks.
    int slots = cfg.max_slam_features - static_cast<int>(slam.size());
    std::vector<std::uint64_t> msckf_ids;
    std::vector<std::uint64_t> slam_new;
    for (const Cand& c : cands) {
      if (c.alive && slots > 0) {
        slam_new.push_back(c.id);
        --slots;
      } else if (static_cast<int>(msckf_ids.size()) < cfg.max_msckf_per_frame && c.frames >= cfg.min_track_msckf) {
        msckf_ids.push_back(c.id);
      }
    }
    // 2b. MSCKF features and new SLAM features: rows projected onto the left null space of
    // the feature's position, gated, stacked, compressed and applied in one update. A new SLAM
    // feature's projected rows are exactly those of its full rows [H_f H_x] after they have been
    // triangularized in the feature columns (all Jacobians with respect to the point, its inverse
    // depth and its anchor pose lie in the span of H_f), so they join the stack; its state block is
    // then initialised by the three rows Q₁ᵀ[H_f H_x r] alone (2c).
    parts.clear();
    Meas m;
    for (std::uint64_t id : msckf_ids) {
      const Track& tr = tracks[id];
      Eigen::Vector3d p;
      if (!triangulate(tr.obs, p)) continue;
      featureRows(tr.obs, p, m);
      m.projectNuisance();
      ++res.gated_features;
      if (!gateWindow(m)) {
        ++res.rejected_features;
        continue;
      }
      parts.push_back(std::move(m));
      ++res.msckf_features;
    }
    struct NewSlam {
      std::uint64_t id;
      Eigen::Vector3d f0;   // inverse depth in camera 0 of the newest clone
      AnchoredPoint apj;    // its world point and Jacobians at the anchor's first estimate
      Meas top;  // Q₁ᵀ[H_f H_x r]: feature position (nuisance, triangular), H_x, residual
    };
    std::vector<NewSlam> fresh;
    for (std::uint64_t id : slam_new) {
      const Track& tr = tracks[id];
      Eigen::Vector3d p;
      if (!triangulate(tr.obs, p)) continue;
      NewSlam ns{id, inverseDepthOf(p, pose(newest.pose), ext(0)), AnchoredPoint{}, Meas{}};
      // Linearised where the SLAM rows of this feature will be (slamRows): at the point that the
      // inverse depth gives with the anchor's first estimate, so that the rows keep the
      // unobservable directions of the first-estimate Jacobians.
      ns.apj = anchoredPoint(ns.f0, cfg.first_estimate_jacobians ? poseJ(newest.pose) : pose(newest.pose), ext(0));
      featureRows(tr.obs, p, m, &ns.apj.p_W);
      m.projectNuisance(&ns.top);
      ++res.gated_features;
      if (!gateWindow(m)) {
        ++res.rejected_features;
        continue;
      }
      if (ns.top.rows() != 3) continue;  // too few observations to fix the point
      if (m.rows() > 0) parts.push_back(std::move(m));
      fresh.push_back(std::move(ns));
    }
    if (!parts.empty()) {
      stackAll(parts, total);
      total.compress();
      f.update(total);
      res.updated = true;
      notify("msckf_update");
    }
    // 2c. New SLAM features: the block (inverse depth in camera 0 of the newest clone, no prior)
    // and its three rows, by the chain rule δp_W = J_f δf + J_a δx_anchor + J_e δext₀ at the
    // Jacobians' linearisation point (first estimates with FEJ, as slamRows).
    for (NewSlam& ns : fresh) {
      const Eigen::Vector3d& f0 = ns.f0;
      const AnchoredPoint& apj = ns.apj;
      Slam s;
      s.block = f.addBlock(BlockSpec::vector("slam", 3), BlockEstimate<Scalar>::fromVector(f0.cast<Scalar>()),
                           sri::Prior<Scalar>::uninformative(), Placement::before(clones.front().id));
      setExact(s.block, BlockEstimate<double>::fromVector(f0));
      s.anchor = newest.pose;
      s.seen = true;
      const Meas& top = ns.top;
      const Eigen::Matrix3d Rf = top.nuisanceJacobian().template cast<double>();
      m.reset(3);
      declareBlocks(m, s.block, s.anchor, tracks[ns.id].obs);  // top's blocks and the feature
      for (int b = 0; b < top.numBlocks(); ++b) m.jacobian(top.blockId(b), top.blockDim(b)) = top.jacobianAt(b);
      m.jacobian(s.block, 3) = (Rf * apj.J_feature).template cast<Scalar>();
      m.jacobian(s.anchor, 6) += (Rf * apj.J_anchor).template cast<Scalar>();
      if (!ext_ids.empty()) m.jacobian(ext_ids[0], 6) += (Rf * apj.J_ext).template cast<Scalar>();
      m.residual() = top.residual();
      m.setWhitened();
      f.update(m);
      slam.emplace(ns.id, s);
      res.updated = true;
    }
    if (!slam_new.empty()) notify("slam_init");
    for (const Cand& c : cands) tracks.erase(c.id);  // used (or unusable): restart alive ones
    for (auto it = tracks.begin(); it != tracks.end();) {
      it = isObserved(it->first) ? std::next(it) : tracks.erase(it);
    }
    f.correct();
    notify("correct");
    clearCaches();

    // 3. Marginalization: lost SLAM features, oldest clone (after re-anchoring).
    std::vector<BlockId> marg = lost_slam;
    if (dropping) {
      const std::vector<BlockId> d = reanchor(oldest);
      notify("reanchor");
      marg.insert(marg.end(), d.begin(), d.end());
      marg.push_back(oldest);
      clones.pop_front();
      fe_pose.erase(oldest.value);
      clone_motion.erase(oldest.value);
      for (auto& [id, tr] : tracks) {
        auto& o = tr.obs;
        const auto n0 = o.size();
        o.erase(std::remove_if(o.begin(), o.end(), [&](const Obs& x) { return x.clone == oldest; }), o.end());
        if (o.size() != n0) --tr.frames;
      }
    }
    if (!marg.empty()) {
      f.marginalize(marg);
      notify("marginalize");
    }
    clearCaches();
    trimImu();
    res.slam_features = static_cast<int>(slam.size());
    checkLockout(frame.t_ns, res);
    return res;
  }

  void checkLockout(std::int64_t t_ns, const FrameResult& res) {
    if (!(cfg.lockout_reset_s > 0.0)) return;
    const auto span = static_cast<std::int64_t>(std::llround(cfg.lockout_reset_s * 1e9));
    gate_log.push_back({t_ns, res.gated_features, res.rejected_features});
    while (!gate_log.empty() && t_ns - gate_log.front().t_ns > span) gate_log.pop_front();
    if (t_ns - t_init < span) return;  // a whole span of this state first
    // A client's measurements (GNSS) applied within the span hold the state: then the rejected
    // features are a camera problem (time offset, calibration, a moving scene) that a restart
    // would not fix, and it would throw the client's state away.
    if (client_update_ns && t_ns - *client_update_ns <= span) return;
    int gated = 0;
    int rejected = 0;
    for (const GateCount& g : gate_log) {
      gated += g.gated;
      rejected += g.rejected;
    }
    if (gated >= 20 && 10 * rejected >= 9 * gated) lockout = true;
  }
};

// ======================================================================================= API
template <typename Scalar>
SriSwfEstimator<Scalar>::SriSwfEstimator(const SriSwfConfig& config) : config_(config) {
  config_.validate();
  impl_ = std::make_unique<Impl>(config_, 1);
}

template <typename Scalar>
void SriSwfEstimator<Scalar>::reset() {
  auto fresh = std::make_unique<Impl>(config_, impl_->f.nextBlockId());
  impl_->carryCalibration(*fresh);
  fresh->imu = std::move(impl_->imu);
  fresh->observer = std::move(impl_->observer);
  // A new generation at once: the old state is gone even before the next one is created, and a
  // client must not use its ids in between (its getters are called between epochs).
  fresh->generation = impl_->generation + 1;
  fresh->resets = impl_->resets + 1;
  impl_ = std::move(fresh);
}

template <typename Scalar>
int SriSwfEstimator<Scalar>::resets() const {
  return impl_->resets;
}

template <typename Scalar>
std::uint64_t SriSwfEstimator<Scalar>::generation() const {
  return impl_->generation;
}

template <typename Scalar>
SriSwfEstimator<Scalar>::~SriSwfEstimator() = default;

template <typename Scalar>
void SriSwfEstimator<Scalar>::addImu(const ImuSample& sample) {
  impl_->addImu(sample);
}

template <typename Scalar>
bool SriSwfEstimator<Scalar>::initializeFrom(const ExternalInitialState& s) {
  if (impl_->initialized || !externalInitialStateError(s).empty() || !impl_->imuCovers(s.state.t_ns, s.state.t_ns)) return false;
  impl_->createState(s.state, s.covariance);
  impl_->initializer.clear();
  impl_->clearCaches();
  return true;
}

template <typename Scalar>
std::span<const ImuSample> SriSwfEstimator<Scalar>::bufferedImu() const {
  return impl_->imuSpan();
}

template <typename Scalar>
FrameResult SriSwfEstimator<Scalar>::processFrame(const FeatureFrame& frame) {
  const auto t0 = std::chrono::steady_clock::now();
  FrameResult r = impl_->process(frame);
  if (impl_->lockout) {
    reset();
    r.reset = true;
    r.initialized = false;
    r.slam_features = 0;
  }
  r.estimator_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

template <typename Scalar>
Eigen::Matrix<double, 6, 6> SriSwfEstimator<Scalar>::poseCovariance() const {
  if (!impl_->initialized) return Eigen::Matrix<double, 6, 6>::Zero();
  const sri::BlockId id = impl_->newest.pose;
  return impl_->f.covariance(std::span<const sri::BlockId>(&id, 1)).template cast<double>();
}

template <typename Scalar>
Eigen::Matrix<double, 15, 15> SriSwfEstimator<Scalar>::imuCovariance() const {
  if (!impl_->initialized) return Eigen::Matrix<double, 15, 15>::Zero();
  const std::vector<sri::BlockId> ids{impl_->newest.pose, impl_->newest.velocity, impl_->newest.bias};
  return impl_->f.covariance(ids).template cast<double>();
}

template <typename Scalar>
std::vector<std::int64_t> SriSwfEstimator<Scalar>::cloneTimes() const {
  std::vector<std::int64_t> t;
  for (const auto& c : impl_->clones) t.push_back(c.t_ns);
  return t;
}

template <typename Scalar>
std::vector<sri::BlockId> SriSwfEstimator<Scalar>::cloneBlocks() const {
  std::vector<sri::BlockId> ids;
  for (const auto& c : impl_->clones) ids.push_back(c.id);
  return ids;
}

template <typename Scalar>
int SriSwfEstimator<Scalar>::slamFeatureCount() const {
  return static_cast<int>(impl_->slam.size());
}

template <typename Scalar>
Eigen::Matrix4d SriSwfEstimator<Scalar>::cameraExtrinsic(int cam) const {
  if (cam < 0 || cam >= static_cast<int>(config_.cameras.size())) throw std::out_of_range("cameraExtrinsic");
  const CameraExtrinsic e = impl_->initialized ? impl_->ext(cam) : impl_->ext_fixed[static_cast<std::size_t>(cam)];
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.topLeftCorner<3, 3>() = e.R_IC;
  T.topRightCorner<3, 1>() = e.p_IC;
  return T;
}

template <typename Scalar>
typename SriSwfEstimator<Scalar>::TimeOffset SriSwfEstimator<Scalar>::timeOffset() const {
  TimeOffset t;
  t.value = impl_->timeOffset();
  if (impl_->td_id.valid()) {
    const sri::BlockId id = impl_->td_id;
    t.sigma = std::sqrt(static_cast<double>(impl_->f.covariance(std::span<const sri::BlockId>(&id, 1))(0, 0)));
  }
  return t;
}

template <typename Scalar>
std::int64_t SriSwfEstimator<Scalar>::imuLeadNs() const {
  const double lead = config_.time_offset + (config_.calibrate_time_offset ? 5.0 * config_.time_offset_sigma : 0.0);
  return lead > 0.0 ? static_cast<std::int64_t>(std::ceil(lead * 1e9)) : 0;
}

template <typename Scalar>
const sri::SriFilter<Scalar>& SriSwfEstimator<Scalar>::filter() const {
  return impl_->f;
}

template <typename Scalar>
Eigen::MatrixXd SriSwfEstimator<Scalar>::unobservableDirections() const {
  return impl_->unobservableDirections();
}

template <typename Scalar>
void SriSwfEstimator<Scalar>::setStepObserver(std::function<void(const char* step)> observer) {
  impl_->observer = std::move(observer);
}

template <typename Scalar>
bool SriSwfEstimator<Scalar>::initialized() const {
  return impl_->initialized;
}

template <typename Scalar>
std::int64_t SriSwfEstimator<Scalar>::newestTime() const {
  return impl_->t_newest;
}

template <typename Scalar>
ImuState SriSwfEstimator<Scalar>::newestImuState() const {
  return impl_->newestState();
}

template <typename Scalar>
ImuBlocks SriSwfEstimator<Scalar>::newestImuBlocks() const {
  return impl_->newest;
}

template <typename Scalar>
Eigen::Vector3d SriSwfEstimator<Scalar>::gravity() const {
  return {0.0, 0.0, -config_.gravity};
}

template <typename Scalar>
ImuNoise SriSwfEstimator<Scalar>::imuNoise() const {
  return config_.imu;
}

template <typename Scalar>
std::optional<ImuIntegration> SriSwfEstimator<Scalar>::integrateToNewest(std::int64_t t_ns) const {
  const Impl& I = *impl_;
  if (!I.initialized || t_ns > I.t_newest || !I.imuCovers(t_ns, I.t_newest)) return std::nullopt;
  const ImuState s = I.newestState();
  ImuIntegration integ(config_.imu, s.bg, s.ba);
  integ.integrate(I.imuSpan(), t_ns, I.t_newest);
  return integ;
}

template <typename Scalar>
std::optional<Eigen::Vector3d> SriSwfEstimator<Scalar>::angularRateAt(std::int64_t t_ns) const {
  const Impl& I = *impl_;
  if (!I.imuCovers(t_ns, t_ns)) return std::nullopt;
  const ImuSample s = interpolateImu(I.imuSpan(), t_ns);
  return Eigen::Vector3d(s.gyro - (I.initialized ? I.newestState().bg : Eigen::Vector3d::Zero()));
}

template <typename Scalar>
sri::BlockId SriSwfEstimator<Scalar>::addBlock(const sri::BlockSpec& spec, const sri::BlockEstimate<Scalar>& estimate,
                                               const sri::Prior<Scalar>& prior, ClientBlockRegion region) {
  if (!impl_->initialized) throw std::logic_error("SriSwfEstimator::addBlock: not initialised");
  return impl_->f.addBlock(spec, estimate, prior, impl_->clientPlacement(region));
}

template <typename Scalar>
std::vector<sri::BlockId> SriSwfEstimator<Scalar>::propagate(const sri::Propagation<Scalar>& step,
                                                             ClientBlockRegion region) {
  if (!impl_->initialized) throw std::logic_error("SriSwfEstimator::propagate: not initialised");
  sri::Propagation<Scalar> p;
  for (const auto& nb : step.newBlocks()) {
    p.addNewBlock(nb.spec, nb.estimate, impl_->clientPlacement(region));
  }
  for (const auto& [id, phi] : step.transitions()) p.setTransition(id, phi);
  if (step.noiseIsSqrtInformation()) {
    p.setNoiseSqrtInformation(step.noise());
  } else {
    p.setNoiseCovariance(step.noise());
  }
  if (step.residual().size() > 0) p.setResidual(step.residual());
  for (const sri::BlockId id : step.marginalized()) p.marginalizeAfter(id);
  return impl_->f.propagate(p);
}

template <typename Scalar>
void SriSwfEstimator<Scalar>::marginalize(std::span<const sri::BlockId> ids) {
  impl_->f.marginalize(ids);
}

template <typename Scalar>
WorldFrameChange SriSwfEstimator<Scalar>::reanchorWorld(sri::BlockId frame) {
  if (!impl_->initialized) throw std::logic_error("SriSwfEstimator::reanchorWorld: not initialised");
  return impl_->reanchorWorld(frame);
}

template <typename Scalar>
bool SriSwfEstimator<Scalar>::contains(sri::BlockId id) const {
  return impl_->f.layout().contains(id);
}

template <typename Scalar>
const sri::BlockEstimate<Scalar>& SriSwfEstimator<Scalar>::estimate(sri::BlockId id) const {
  return impl_->f.estimate(id);
}

template <typename Scalar>
typename SriSwfEstimator<Scalar>::Matrix SriSwfEstimator<Scalar>::covariance(std::span<const sri::BlockId> ids) const {
  return impl_->f.covariance(ids);
}

template <typename Scalar>
std::optional<sri::ChiSquare<Scalar>> SriSwfEstimator<Scalar>::chiSquare(const sri::Measurement<Scalar>& m) const {
  return impl_->f.chiSquare(m);
}

template <typename Scalar>
BackendUpdate<Scalar> SriSwfEstimator<Scalar>::update(const sri::Measurement<Scalar>& m, double gate_probability) {
  BackendUpdate<Scalar> out;
  // The gate is the update's own post-fit χ² (undone if too large, sri::UpdateOptions::max_chi2):
  // for rows on the trailing blocks (GNSS) a copy of that block instead of chiSquare()'s solves.
  sri::UpdateOptions opt;
  const int dof = m.rows() + m.discardedRows();
  if (gate_probability < 1.0 && dof > 0) opt.max_chi2 = impl_->client_gate(gate_probability, dof);
  const sri::UpdateResult<Scalar> u = impl_->f.update(m, opt);
  out.chi2 = u.chi2;
  out.dof = u.dof;
  if (!u.applied) return out;
  impl_->f.correct();
  impl_->client_update_ns = impl_->t_newest;
  out.applied = true;
  return out;
}

template class SriSwfEstimator<float>;
template class SriSwfEstimator<double>;

}  // namespace gvins::vio
