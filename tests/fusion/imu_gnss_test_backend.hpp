// Test-only EstimatorBackend: an IMU-driven SRI filter (gvins::sri::SriFilter) without vision, so
// that GnssFusion can run GNSS/INS end-to-end on simulated IMU + GNSS before (and independently
// of) the SRI-SWF estimator. Newest IMU state = pose block (kPose, right perturbation, ImuErr's
// [δθ, δp]) + velocity block (kVector 3) + bias block (kVector 6, [δbg, δba]), all three renewed at
// every propagation with vio::ImuPropagator's Φ and Q_d (paper eq. (8)); client blocks are placed before the IMU blocks (kParameters) or at the
// front (kFront).
#pragma once

#include <algorithm>
#include <cstdint>
#include <optional>
#include <span>
#include <stdexcept>
#include <vector>

#include <Eigen/Geometry>

#include "gvins/sri/chi_square.hpp"
#include "gvins/sri/sri_filter.hpp"
#include "gvins/vio/estimator_backend.hpp"
#include "gvins/vio/imu_propagation.hpp"

namespace gvins::fusion::testing {

template <typename Scalar>
class ImuGnssTestBackend final : public vio::EstimatorBackend<Scalar> {
 public:
  using Matrix = typename vio::EstimatorBackend<Scalar>::Matrix;
  using Vector = typename vio::EstimatorBackend<Scalar>::Vector;

  /// `samples` (sorted) must outlive the backend. Prior standard deviations per ImuErr block.
  ImuGnssTestBackend(const vio::ImuNoise& noise, double gravity, std::span<const vio::ImuSample> samples,
                     const vio::ImuState& initial, const Eigen::Matrix<double, 15, 1>& priorSigma)
      : prop_(noise, gravity), samples_(samples), t_(initial.t_ns) {
    blocks_.pose = filter_.addBlock(sri::BlockSpec::pose("imu_pose"), poseOf(initial),
                                    sri::Prior<Scalar>::stdDevs(priorSigma.head<6>().template cast<Scalar>()));
    blocks_.velocity = filter_.addBlock(sri::BlockSpec::vector("imu_velocity", 3), velocityOf(initial),
                                        sri::Prior<Scalar>::stdDevs(priorSigma.segment<3>(6).template cast<Scalar>()));
    blocks_.bias = filter_.addBlock(sri::BlockSpec::vector("imu_bias", 6), biasOf(initial),
                                    sri::Prior<Scalar>::stdDevs(priorSigma.tail<6>().template cast<Scalar>()));
  }

  /// Propagates the newest state to t_ns.
  void propagateTo(std::int64_t t_ns) {
    if (t_ns <= t_) return;
    vio::ImuState s = newestImuState();
    vio::Matrix15d Phi, Qd;
    prop_.propagate(s, window(t_, t_ns), t_ns, &Phi, &Qd);
    sri::Propagation<Scalar> step;
    step.addNewBlock(sri::BlockSpec::pose("imu_pose"), poseOf(s));
    step.addNewBlock(sri::BlockSpec::vector("imu_velocity", 3), velocityOf(s));
    step.addNewBlock(sri::BlockSpec::vector("imu_bias", 6), biasOf(s));
    step.setTransition(blocks_.pose, Phi.leftCols<6>().template cast<Scalar>());
    step.setTransition(blocks_.velocity, Phi.middleCols<3>(6).template cast<Scalar>());
    step.setTransition(blocks_.bias, Phi.rightCols<6>().template cast<Scalar>());
    Qd += 1e-12 * vio::Matrix15d::Identity();
    step.setNoiseCovariance(Qd.template cast<Scalar>());
    step.marginalizeAfter(blocks_.pose);
    step.marginalizeAfter(blocks_.velocity);
    step.marginalizeAfter(blocks_.bias);
    const auto ids = filter_.propagate(step);
    blocks_ = {ids.at(0), ids.at(1), ids.at(2)};
    t_ = t_ns;
  }

  bool initialized() const override { return true; }
  std::uint64_t generation() const override { return generation_; }
  /// Simulates an estimator that dropped its state and started again (SriSwfEstimator::reset):
  /// every client block is gone and generation() counts up; the IMU state stays.
  bool restart() override {
    std::vector<sri::BlockId> clients;
    for (const sri::BlockInfo& b : filter_.layout().blocks()) {
      if (b.id != blocks_.pose && b.id != blocks_.velocity && b.id != blocks_.bias) clients.push_back(b.id);
    }
    if (!clients.empty()) filter_.marginalize(clients);
    ++generation_;
    return true;
  }
  std::int64_t newestTime() const override { return t_; }
  vio::ImuState newestImuState() const override {
    vio::ImuState s;
    s.t_ns = t_;
    const auto& p = filter_.estimate(blocks_.pose);
    s.R_WI = p.rotation.template cast<double>().toRotationMatrix();
    s.p_WI = p.vector.template cast<double>();
    s.v_WI = filter_.estimate(blocks_.velocity).vector.template cast<double>();
    const Eigen::VectorXd b = filter_.estimate(blocks_.bias).vector.template cast<double>();
    s.bg = b.segment<3>(0);
    s.ba = b.segment<3>(3);
    return s;
  }
  vio::ImuBlocks newestImuBlocks() const override { return blocks_; }
  Eigen::Vector3d gravity() const override { return prop_.gravity(); }
  vio::ImuNoise imuNoise() const override { return prop_.noise(); }
  std::optional<vio::ImuIntegration> integrateToNewest(std::int64_t t_ns) const override {
    if (t_ns > t_ || t_ - t_ns > 2000000000LL || t_ns < samples_.front().t_ns) return std::nullopt;
    const vio::ImuState s = newestImuState();
    vio::ImuIntegration integ(prop_.noise(), s.bg, s.ba);
    integ.integrate(window(t_ns, t_), t_ns, t_);
    return integ;
  }
  std::optional<Eigen::Vector3d> angularRateAt(std::int64_t t_ns) const override {
    if (t_ns < samples_.front().t_ns || t_ns > samples_.back().t_ns) return std::nullopt;
    return vio::interpolateImu(window(t_ns, t_ns), t_ns).gyro - newestImuState().bg;
  }

  sri::BlockId addBlock(const sri::BlockSpec& spec, const sri::BlockEstimate<Scalar>& estimate,
                        const sri::Prior<Scalar>& prior, vio::ClientBlockRegion region) override {
    return filter_.addBlock(spec, estimate, prior, placement(region));
  }
  std::vector<sri::BlockId> propagate(const sri::Propagation<Scalar>& step, vio::ClientBlockRegion region) override {
    sri::Propagation<Scalar> s;
    for (const auto& b : step.newBlocks()) s.addNewBlock(b.spec, b.estimate, placement(region));
    for (const auto& [id, phi] : step.transitions()) s.setTransition(id, phi);
    if (step.noiseIsSqrtInformation()) s.setNoiseSqrtInformation(step.noise());
    else s.setNoiseCovariance(step.noise());
    if (step.residual().size()) s.setResidual(step.residual());
    for (sri::BlockId id : step.marginalized()) s.marginalizeAfter(id);
    return filter_.propagate(s);
  }
  void marginalize(std::span<const sri::BlockId> ids) override { filter_.marginalize(ids); }
  vio::WorldFrameChange reanchorWorld(sri::BlockId frame) override {
    const vio::ReanchoredPose poses[] = {{blocks_.pose, std::nullopt, std::nullopt}};
    const vio::ReanchoredVelocity velocities[] = {{blocks_.velocity, std::nullopt}};
    return vio::reanchorWorld(filter_, frame, poses, velocities);
  }
  bool contains(sri::BlockId id) const override { return filter_.layout().contains(id); }
  const sri::BlockEstimate<Scalar>& estimate(sri::BlockId id) const override { return filter_.estimate(id); }
  Matrix covariance(std::span<const sri::BlockId> ids) const override { return filter_.covariance(ids); }
  bool informed(std::span<const sri::BlockId> ids) const override { return filter_.informed(ids); }
  std::optional<sri::ChiSquare<Scalar>> chiSquare(const sri::Measurement<Scalar>& m) const override {
    return filter_.chiSquare(m);
  }
  vio::BackendUpdate<Scalar> update(const sri::Measurement<Scalar>& m, double gate_probability) override {
    vio::BackendUpdate<Scalar> u;
    const auto c = filter_.chiSquare(m);
    if (c) {
      u.chi2 = c->value;
      u.dof = c->dof;
      if (gate_probability < 1.0 && static_cast<double>(c->value) > sri::chiSquareQuantile(gate_probability, c->dof)) {
        return u;
      }
    }
    filter_.update(m);
    filter_.correct();
    u.applied = true;
    return u;
  }
  const sri::SriFilter<Scalar>& filter() const { return filter_; }

 private:
  std::uint64_t generation_ = 1;
  static sri::BlockEstimate<Scalar> poseOf(const vio::ImuState& s) {
    return sri::BlockEstimate<Scalar>::fromPose(Eigen::Quaterniond(s.R_WI).template cast<Scalar>(),
                                                s.p_WI.template cast<Scalar>());
  }
  static sri::BlockEstimate<Scalar> velocityOf(const vio::ImuState& s) {
    return sri::BlockEstimate<Scalar>::fromVector(s.v_WI.template cast<Scalar>());
  }
  static sri::BlockEstimate<Scalar> biasOf(const vio::ImuState& s) {
    Eigen::Matrix<double, 6, 1> x;
    x << s.bg, s.ba;
    return sri::BlockEstimate<Scalar>::fromVector(x.template cast<Scalar>());
  }
  sri::Placement placement(vio::ClientBlockRegion r) const {
    return r == vio::ClientBlockRegion::kFront ? sri::Placement::front() : sri::Placement::before(blocks_.pose);
  }
  /// Samples covering [t0, t1] with two neighbours on each side.
  std::span<const vio::ImuSample> window(std::int64_t t0, std::int64_t t1) const {
    auto lo = std::upper_bound(samples_.begin(), samples_.end(), t0,
                               [](std::int64_t t, const vio::ImuSample& s) { return t < s.t_ns; });
    auto hi = std::lower_bound(samples_.begin(), samples_.end(), t1,
                               [](const vio::ImuSample& s, std::int64_t t) { return s.t_ns < t; });
    const std::ptrdiff_t a = std::max<std::ptrdiff_t>(0, (lo - samples_.begin()) - 3);
    const std::ptrdiff_t b =
        std::min<std::ptrdiff_t>(static_cast<std::ptrdiff_t>(samples_.size()), (hi - samples_.begin()) + 3);
    return samples_.subspan(static_cast<std::size_t>(a), static_cast<std::size_t>(b - a));
  }

  vio::ImuPropagator prop_;
  std::span<const vio::ImuSample> samples_;
  sri::SriFilter<Scalar> filter_;
  vio::ImuBlocks blocks_;
  std::int64_t t_ = 0;
};

}  // namespace gvins::fusion::testing
