// The backend interface of a VIO estimator: what fusion/ (GNSS) or any other client may do with
// the filter, without touching its internals. The SRI-SWF (sri_swf_estimator.hpp) implements it;
// another backend (e.g. a covariance MSCKF) could be plugged in behind the same interface.
//
// Model. The estimator owns a state of named blocks (gvins/sri/block.hpp): its own (IMU pose
// clones, the newest IMU state, SLAM features, camera extrinsics) and those a client adds
// (GNSS clock biases/drift, lever arm, VIO-to-ENU frame yaw/position, ambiguities). A client
//   - adds, propagates and marginalizes its own blocks (addBlock / propagate / marginalize);
//   - reads estimates and marginal covariances of any block (estimate / covariance);
//   - feeds linearized, whitened residual/Jacobian rows on named blocks (chiSquare / update);
//   - asks for the newest IMU state, its blocks, and the IMU integration terms between an earlier
//     time and the newest state (for measurements older than the newest state, paper Sec. III-C).
//
// The newest IMU state is three blocks (paper eq. (1)): `pose` (kPose, [δθ; δp] with
// R_WI = R̂_WI·Exp(δθ), p_WI = p̂_WI + δp, i.e. ImuErr's θ and p), `velocity` (kVector, δv_WI) and
// `bias` (kVector, 6 entries [δbg; δba]). So a Jacobian w.r.t. the 15-dim ImuErr vector splits as
// columns 0..5 → pose, 6..8 → velocity and 9..14 → bias. The pose and velocity ids change at
// every propagation, the bias id whenever the bias is renewed (SriSwfConfig::imu_bias_renewal):
// ask for them (newestImuBlocks()) right before building a measurement.
//
// Blocks a client owns keep their id until the client marginalizes or propagates them, or the
// estimator starts a new state (generation()). Time-varying client blocks (receiver clocks) are
// propagated lazily by the client at its own measurement times with propagate() — exact for
// linear models such as clock bias/drift, since nothing else observes them in between.
//
// Threading: not thread-safe; the driver calls the estimator and its clients from one thread, in
// time order (see fusion/ and apps/replay).
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "gvins/sri/block.hpp"
#include "gvins/sri/block_estimate.hpp"
#include "gvins/sri/measurement.hpp"
#include "gvins/sri/prior.hpp"
#include "gvins/sri/propagation.hpp"
#include "gvins/sri/sri_filter.hpp"
#include "gvins/sri/state_layout.hpp"
#include "gvins/vio/external_initial_state.hpp"
#include "gvins/vio/imu_integration.hpp"
#include "gvins/vio/imu_sample.hpp"
#include "gvins/vio/imu_state.hpp"
#include "gvins/vio/world_frame_change.hpp"

namespace gvins::vio {

/// Ids of the newest IMU state (see the file comment).
struct ImuBlocks {
  sri::BlockId pose;      ///< kPose: [δθ; δp] of R_WI, p_WI.
  sri::BlockId velocity;  ///< kVector(3): δv_WI.
  sri::BlockId bias;      ///< kVector(6): [δbg; δba].
};

/// Where a client block goes in the elimination order (sri_filter.hpp explains the trade-off).
enum class ClientBlockRegion : std::uint8_t {
  kParameters,  ///< With the calibration parameters, after the clones (lever arm, frame, clocks).
  kFront,       ///< In front of everything (cheap to marginalize, e.g. ambiguities that come and go).
};

/// Result of feeding rows to the backend.
template <typename Scalar>
struct BackendUpdate {
  bool applied = false;  ///< False if gated out (then the state is untouched).
  Scalar chi2 = 0;       ///< Innovation Mahalanobis distance (before the update).
  int dof = 0;
};

template <typename Scalar>
class EstimatorBackend {
 public:
  using Matrix = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>;
  using Vector = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>;

  virtual ~EstimatorBackend() = default;

  // ------------------------------------------------------------------ status and IMU state
  /// True once the VIO is initialised (gravity aligned, newest state exists).
  virtual bool initialized() const = 0;
  /// Changes whenever the estimator's state is replaced: 0 before the first initialisation, + 1
  /// at each initialisation and + 1 when a state is dropped (e.g. after a visual lock-out,
  /// SriSwfEstimator::reset). The client blocks of an earlier generation are gone: a client
  /// that sees a new generation forgets its ids and starts its own initialisation again.
  virtual std::uint64_t generation() const = 0;
  /// Time of the newest IMU state (ns, on the sensor clock = GPST in our datasets).
  virtual std::int64_t newestTime() const = 0;
  /// The newest navigation state (double, whatever Scalar the filter runs in).
  virtual ImuState newestImuState() const = 0;
  virtual ImuBlocks newestImuBlocks() const = 0;
  /// Gravity vector in the world frame W (z up: (0, 0, −g)).
  virtual Eigen::Vector3d gravity() const = 0;
  /// IMU noise model used for propagation (clients use it for integration noise).
  virtual ImuNoise imuNoise() const = 0;
  /// Integration terms γ, β, α over [t_ns, newestTime()] from the buffered IMU samples at the
  /// newest bias estimates, with their bias Jacobians and noise covariance Σ_g. nullopt if t_ns is
  /// later than the newest state or older than the buffer (the estimator keeps at least 2 s).
  virtual std::optional<ImuIntegration> integrateToNewest(std::int64_t t_ns) const = 0;
  /// Bias-corrected angular rate of the IMU (rad/s, IMU frame) at t_ns, interpolated from the
  /// buffer; nullopt outside it.
  virtual std::optional<Eigen::Vector3d> angularRateAt(std::int64_t t_ns) const = 0;

  /// Starts a state from `s` (external_initial_state.hpp) while not initialised: s.state.t_ns must
  /// lie within the buffered IMU samples (bufferedImu) and not after the next frame; the next
  /// frame is propagated from it. False (nothing changes) when initialised already, when `s` is
  /// invalid or outside the buffer, or when the backend does not support it.
  virtual bool initializeFrom(const ExternalInitialState& s) {
    (void)s;
    return false;
  }
  /// Drops the whole state (client blocks included; generation() changes) and initialises again
  /// from the next frames or initializeFrom, keeping the buffered IMU samples: for a client whose
  /// measurements show that the state cannot be linearised about (e.g. a long IMU-only stretch).
  /// False (nothing changes) when the backend does not support it.
  virtual bool restart() { return false; }
  /// The IMU samples the estimator holds (oldest first; before initialisation at least the last
  /// init_window + 2 s): for a client's own alignment before the state exists. Empty when the
  /// backend does not expose them.
  virtual std::span<const ImuSample> bufferedImu() const { return {}; }

  // ------------------------------------------------------------------ client blocks
  virtual sri::BlockId addBlock(const sri::BlockSpec& spec, const sri::BlockEstimate<Scalar>& estimate,
                                const sri::Prior<Scalar>& prior,
                                ClientBlockRegion region = ClientBlockRegion::kParameters) = 0;
  /// Appends a propagation block row for client blocks (new blocks are placed in `region`);
  /// returns the new ids. Transitions may only reference client blocks or the newest IMU blocks.
  virtual std::vector<sri::BlockId> propagate(const sri::Propagation<Scalar>& step,
                                              ClientBlockRegion region = ClientBlockRegion::kParameters) = 0;
  virtual void marginalize(std::span<const sri::BlockId> ids) = 0;
  /// Re-expresses the whole state in the world frame W' held by the client block `frame`
  /// (kVector(4) [ψ; t]: x_W' = Rz(ψ) x_W + t, world_frame_change.hpp) and marginalizes the
  /// block: poses, velocity and the estimator's first estimates move to W', the block's
  /// information moves into them, and newestImuState() etc. are in W' from then on. Returns the
  /// change applied. Ids of the estimator's own blocks stay valid.
  virtual WorldFrameChange reanchorWorld(sri::BlockId frame) = 0;
  virtual bool contains(sri::BlockId id) const = 0;
  virtual const sri::BlockEstimate<Scalar>& estimate(sri::BlockId id) const = 0;
  /// Joint marginal covariance of the listed blocks (sri_filter.hpp's rules apply).
  virtual Matrix covariance(std::span<const sri::BlockId> ids) const = 0;
  /// Whether covariance(ids) is defined (sri::SriFilter::informed): every listed block carries
  /// information, e.g. not a block added with an uninformative prior that no row reached yet.
  virtual bool informed(std::span<const sri::BlockId> ids) const = 0;

  // ------------------------------------------------------------------ measurements
  /// Innovation Mahalanobis distance of whitened rows, or nullopt if it cannot be formed.
  virtual std::optional<sri::ChiSquare<Scalar>> chiSquare(const sri::Measurement<Scalar>& m) const = 0;
  /// Gates the whitened rows with a chi-square test at `gate_probability` (≥ 1: no gate), and
  /// if accepted updates and corrects the state (x̂ ← x̂ ⊞ R⁻¹r).
  virtual BackendUpdate<Scalar> update(const sri::Measurement<Scalar>& m, double gate_probability) = 0;
};

}  // namespace gvins::vio
