// The shared state of the SRI-SWF estimator: accessors, IMU buffer, creation of the first
// state, placement of blocks, feature observations and the gauge (swf_state.hpp).
#include "swf_state.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <type_traits>

namespace gvins::vio::detail {
namespace {

using sri::BlockEstimate;
using sri::BlockId;
using sri::BlockSpec;
using sri::Placement;

sri::SriOptions filterOptions(const SriSwfConfig& c, std::uint64_t first_block_id) {
  sri::SriOptions o;
  o.first_block_id = first_block_id;
  if (c.float_householder) o.auto_givens_ratio_float = std::numeric_limits<double>::infinity();
  return o;
}

}  // namespace

template <typename Scalar>
SwfState<Scalar>::SwfState(const SriSwfConfig& c, std::uint64_t first_block_id)
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

// A state that ran away may have dragged the calibration off, and then the configuration is the
// better start: each is carried only within 3 prior σ of its configured value (per axis, so
// √3·3σ in norm); the priors keep their configured σ.
template <typename Scalar>
void SwfState<Scalar>::carryCalibration(SwfState& next) const {
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
template <typename Scalar>
void SwfState<Scalar>::setExact(BlockId id, const BlockEstimate<double>& v) {
  if constexpr (!std::is_same_v<Scalar, double>) f.setNominal(id, v);
}

template <typename Scalar>
CameraExtrinsic SwfState<Scalar>::ext(int cam) const {
  if (!ext_ids.empty()) {
    const PoseEstimate p = poseOf(f.nominal(ext_ids[static_cast<std::size_t>(cam)]));
    return {p.R_WI, p.p_WI};
  }
  return ext_fixed[static_cast<std::size_t>(cam)];
}

template <typename Scalar>
const PoseEstimate& SwfState<Scalar>::pose(BlockId id) {
  auto it = pose_cache.find(id.value);
  if (it == pose_cache.end()) it = pose_cache.emplace(id.value, poseOf(f.nominal(id))).first;
  return it->second;
}

template <typename Scalar>
double SwfState<Scalar>::timeOffset() const {
  if (td_id.valid()) return static_cast<double>(f.nominal(td_id).vector(0));
  return td_start;
}

template <typename Scalar>
const PoseEstimate& SwfState<Scalar>::obsPose(BlockId id) {
  if (!td_id.valid()) return pose(id);
  auto it = obs_pose_cache.find(id.value);
  if (it != obs_pose_cache.end()) return it->second;
  PoseEstimate P = pose(id);
  if (auto m = clone_motion.find(id.value); m != clone_motion.end()) {
    P = poseAfter(P, m->second.w, m->second.v, timeOffset() - m->second.td);
  }
  return obs_pose_cache.emplace(id.value, P).first->second;
}

template <typename Scalar>
Eigen::Vector3d SwfState<Scalar>::timeOffsetColumn(BlockId id, const CameraPoint& cp) const {
  const auto m = clone_motion.find(id.value);
  if (m == clone_motion.end()) return Eigen::Vector3d::Zero();
  return timeOffsetJacobian(cp, m->second.w, m->second.v);
}

template <typename Scalar>
void SwfState<Scalar>::recordCloneMotion(BlockId id, const ImuState& s, double td) {
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

template <typename Scalar>
const PoseEstimate& SwfState<Scalar>::poseJ(BlockId id) {
  if (cfg.first_estimate_jacobians) {
    if (auto it = fe_pose.find(id.value); it != fe_pose.end()) return it->second;
  }
  return pose(id);
}

template <typename Scalar>
bool SwfState<Scalar>::velocityHasFirstEstimate() const {
  return cfg.first_estimate_jacobians && fe_pose.count(newest.pose.value) != 0;
}

template <typename Scalar>
Eigen::Matrix<double, 6, 1> SwfState<Scalar>::biasVector(const ImuState& s) {
  Eigen::Matrix<double, 6, 1> b;
  b << s.bg, s.ba;
  return b;
}

template <typename Scalar>
ImuState SwfState<Scalar>::newestState() const {
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
template <typename Scalar>
void SwfState<Scalar>::addImu(const ImuSample& s) {
  if (!imu.empty() && s.t_ns <= imu.back().t_ns) return;
  imu.push_back(s);
}

// Kept: 3 s, and from 0.1 s before the oldest clone (before initialisation: init_window + 2 s,
// and from 0.1 s before the initialiser's oldest frame).
template <typename Scalar>
void SwfState<Scalar>::trimImu() {
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

// ------------------------------------------------------------------ state creation
template <typename Scalar>
void SwfState<Scalar>::createState(const ImuState& s, const Matrix15d& Pimu) {
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

// ------------------------------------------------------------------ placement
template <typename Scalar>
Placement SwfState<Scalar>::extraPlacement() const {
  return cfg.imu_extra_first ? Placement::front() : Placement::back();
}

template <typename Scalar>
Placement SwfState<Scalar>::clientPlacement(ClientBlockRegion region) const {
  if (region == ClientBlockRegion::kFront) return Placement::front();
  if (cfg.imu_extra_first) return Placement::back();
  const bool biasFirst = f.layout().index(newest.bias) < f.layout().index(newest.velocity);
  return Placement::before(biasFirst ? newest.bias : newest.velocity);
}

// ------------------------------------------------------------------ visual rows
template <typename Scalar>
void SwfState<Scalar>::addObservations(const FeatureFrame& frame) {
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

template <typename Scalar>
void SwfState<Scalar>::declareBlocks(Meas& m, BlockId feature, BlockId anchor, const std::vector<Obs>& obs) {
  decl_ids_.clear();
  decl_dims_.clear();
  auto add = [&](BlockId id, int d) {
    if (std::find(decl_ids_.begin(), decl_ids_.end(), id) != decl_ids_.end()) return;
    decl_ids_.push_back(id);
    decl_dims_.push_back(d);
  };
  if (feature.valid()) add(feature, 3);
  if (anchor.valid()) add(anchor, 6);
  for (const Obs& o : obs) add(o.clone, 6);
  for (BlockId e : ext_ids) add(e, 6);
  if (td_id.valid()) add(td_id, 1);
  m.addBlocks(decl_ids_, decl_dims_);
}

template <typename Scalar>
double SwfState<Scalar>::inverseSigma(int cam, double depth) const {
  const double sp = sigma_n[static_cast<std::size_t>(cam)];
  const double ss = cfg.surface_noise / depth;
  return 1.0 / std::sqrt(sp * sp + ss * ss);
}

template <typename Scalar>
double SwfState<Scalar>::chi2Threshold(int dof) const {
  if (cfg.chi2_probability >= 1.0) return std::numeric_limits<double>::infinity();
  return chi2_thr(cfg.chi2_probability, dof);
}

template <typename Scalar>
bool SwfState<Scalar>::gate(const Meas& m) const {
  if (cfg.chi2_probability >= 1.0) return true;
  const auto c = f.chiSquare(m);
  return c && static_cast<double>(c->value) <= chi2Threshold(c->dof);
}

// ------------------------------------------------------------------ gauge
// Every clone (the newest pose is one) and the velocity in the extra change variables, with the
// frame's Jacobian at the first estimates where they are used (the handed-over uncertainty then
// lies along the unobservable directions the visual rows keep: unobservableDirections()); the
// first estimates and clone velocities follow, the pose caches are dropped. SLAM features are
// anchored in a clone's camera and the calibration parameters live in the body: they do not
// change.
template <typename Scalar>
WorldFrameChange SwfState<Scalar>::reanchorWorld(BlockId frame) {
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

// The four unobservable directions of VIO (global yaw about the z axis through the origin,
// global x, y, z translation) in the current error state, at the linearisation points the
// Jacobians use (first estimates where the clones have them): clones δθ = R̂ᵀe_z, δp = e_z × p̂
// (yaw) and δp = e_k (translation); IMU velocity δv = e_z × v̂; IMU bias, SLAM features
// (anchored inverse depth), extrinsics and client blocks 0.
template <typename Scalar>
Eigen::MatrixXd SwfState<Scalar>::unobservableDirections() const {
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
    const bool is_clone = std::any_of(clones.begin(), clones.end(), [&](const Clone& c) { return c.id == b.id; });
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

template struct SwfState<float>;
template struct SwfState<double>;

}  // namespace gvins::vio::detail
