// SRI-SWF visual-inertial estimator (see sri_swf_estimator.hpp and docs/vio_estimator.md): the
// frame loop, which runs the units in order, the visual lock-out and the public API. The units:
//   swf_state               shared state, accessors, first state, gauge
//   swf_propagation         IMU propagation to the frame (clone, velocity/bias renewal)
//   zero_velocity_update    standstill rows
//   slam_update             SLAM re-observations and new SLAM features
//   msckf_update            track selection, triangulation, MSCKF rows, window χ² gate
//   window_marginalization  SLAM re-anchoring, marginalization of lost features and oldest clone
#include "gvins/vio/sri_swf_estimator.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "msckf_update.hpp"
#include "slam_update.hpp"
#include "swf_propagation.hpp"
#include "swf_state.hpp"
#include "window_marginalization.hpp"
#include "zero_velocity_update.hpp"

namespace gvins::vio {

// ======================================================================================= Impl
template <typename Scalar>
struct SriSwfEstimator<Scalar>::Impl : detail::SwfState<Scalar> {
  using State = detail::SwfState<Scalar>;

  Impl(const SriSwfConfig& c, std::uint64_t first_block_id) : State(c, first_block_id) {}

  detail::ZeroVelocityUpdater<Scalar> zupt;
  detail::SlamUpdater<Scalar> slam_updater;
  detail::MsckfUpdater<Scalar> msckf;
  std::vector<std::uint64_t> observed_ids;  // ids of the frame's features, sorted (capacity kept)

  // Visual lock-out (SriSwfConfig::lockout_reset_s): features gated and rejected per frame over
  // the last lockout_reset_s, and whether they were ≥ 20 with ≥ 90 % rejected.
  struct GateCount {
    std::int64_t t_ns;
    int gated;
    int rejected;
  };
  std::deque<GateCount> gate_log;
  bool lockout = false;

  bool tryInitialize(const FeatureFrame& frame) {
    const std::optional<InitialState> s = this->initializer.tryInitialize(frame, this->imuSpan(), this->ext_fixed);
    if (!s) return false;
    this->createState(s->state, initialStateCovariance(*s, this->cfg));
    this->clearCaches();
    this->addObservations(frame);
    return true;
  }

  /// Frames enter in IMU time: t_cam + t̂_d (rounded to the ns; frame_td is the exact shift).
  FrameResult process(const FeatureFrame& input) {
    const double td = this->timeOffset();
    const auto shift = static_cast<std::int64_t>(std::llround(td * 1e9));
    this->frame_td = static_cast<double>(shift) * 1e-9;
    if (shift == 0) return processImuTime(input);
    FeatureFrame shifted = input;
    shifted.t_ns += shift;
    return processImuTime(shifted);
  }

  /// One frame (IMU time): propagation, zero-velocity update, SLAM re-observations, MSCKF and
  /// new SLAM features, marginalization; docs/vio_estimator.md "A frame, step by step".
  FrameResult processImuTime(const FeatureFrame& frame) {
    FrameResult res;
    State& S = *this;
    S.clearCaches();
    if (!S.initialized) {
      res.initialized = tryInitialize(frame);
      res.init_status = S.initializer.status();
      S.trimImu();
      return res;
    }
    res.initialized = true;
    res.init_status = InitStatus::kInitialized;
    if (frame.t_ns <= S.t_newest || !S.imuCovers(S.t_newest, frame.t_ns)) {
      res.slam_features = static_cast<int>(S.slam.size());
      return res;
    }
    // 0. Propagation to the frame (its clone), zero-velocity update at a standstill.
    const sri::BlockId previous_pose = S.newest.pose;
    detail::propagateToFrame(S, frame.t_ns);
    S.notify("propagate");
    if (zupt.update(S, frame, previous_pose)) {
      res.updated = true;
      res.zero_velocity = true;
    }
    for (auto& [id, s] : S.slam) s.seen = false;
    S.addObservations(frame);
    const bool dropping = static_cast<int>(S.clones.size()) > S.cfg.window;
    observed_ids.clear();
    for (const FeatureObservation& o : frame.features) observed_ids.push_back(o.id);
    std::sort(observed_ids.begin(), observed_ids.end());
    // 1. SLAM re-observations (newest clone).
    std::vector<sri::BlockId> lost_slam = slam_updater.updateReobserved(S, frame, res);
    if (res.updated) {
      S.f.correct();
      S.notify("correct");
    }
    S.clearCaches();
    // 2. MSCKF features and new SLAM features from the tracks, one stacked update; then the
    // new SLAM features' blocks and rows.
    const detail::FeatureSelection sel = detail::selectFeatures(S, observed_ids, dropping, S.clones.front().id);
    const std::vector<detail::NewSlamFeature<Scalar>> fresh = msckf.update(S, sel, res);
    slam_updater.initialize(S, fresh, res);
    if (!sel.slam_new.empty()) S.notify("slam_init");
    detail::retireTracks(S, sel, observed_ids);
    S.f.correct();
    S.notify("correct");
    S.clearCaches();
    // 3. Marginalization: lost SLAM features, oldest clone (after re-anchoring).
    detail::marginalizeWindow(S, std::move(lost_slam), dropping);
    S.clearCaches();
    S.trimImu();
    res.slam_features = static_cast<int>(S.slam.size());
    checkLockout(frame.t_ns, res);
    return res;
  }

  void checkLockout(std::int64_t t_ns, const FrameResult& res) {
    const SriSwfConfig& cfg = this->cfg;
    if (!(cfg.lockout_reset_s > 0.0)) return;
    const auto span = static_cast<std::int64_t>(std::llround(cfg.lockout_reset_s * 1e9));
    gate_log.push_back({t_ns, res.gated_features, res.rejected_features});
    while (!gate_log.empty() && t_ns - gate_log.front().t_ns > span) gate_log.pop_front();
    if (t_ns - this->t_init < span) return;  // a whole span of this state first
    // A client's measurements (GNSS) applied within the span hold the state: then the rejected
    // features are a camera problem (time offset, calibration, a moving scene) that a restart
    // would not fix, and it would throw the client's state away.
    if (this->client_update_ns && t_ns - *this->client_update_ns <= span) return;
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
