// The receiver clock states of the GNSS fusion (gnss_fusion.hpp, step 3) in the estimator's
// state: [c·dt, c·ḋt] of the first clock system as one client block, propagated at each GNSS
// epoch (bias += drift·Δt, random walks), and the inter-system biases c·(dt_s − dt_0) of the
// other clock systems as one block, constant but for a random walk stepped every
// isbRenewalInterval seconds: the receiver has one oscillator, the ISBs are hardware delays.
// GnssClockStates owns those two blocks: creation, propagation, values and removal.
#pragma once

#include <span>
#include <vector>

#include <Eigen/Core>

#include "gvins/base/gnss_time.hpp"
#include "gvins/base/satellite.hpp"
#include "gvins/fusion/gnss_fusion_config.hpp"
#include "gvins/vio/estimator_backend.hpp"

namespace gvins::fusion {

/// The receiver clock a constellation's signals use: QZSS shares GPS's.
inline System clockSystemOf(System s) { return s == System::Qzss ? System::Gps : s; }

/// One random-walk step of a vector block of `size` (parameter region): the same estimate,
/// `variance` added to each component; returns the new block's id.
template <typename Scalar>
sri::BlockId randomWalkStep(vio::EstimatorBackend<Scalar>& est, sri::BlockId id, const char* name, int size,
                            double variance);

template <typename Scalar>
class GnssClockStates {
 public:
  /// Whether the blocks exist.
  bool valid() const { return clock_.valid(); }
  /// The clock systems, in the order of the clock entries (set by create(), kept by marginalize()).
  const std::vector<System>& systems() const { return systems_; }
  /// Index of a satellite's clock system among systems(), -1 if none.
  int index(SatId sat) const;
  sri::BlockId clockBlock() const { return clock_; }
  sri::BlockId isbBlock() const { return isb_; }
  /// The time the receiver clock block refers to.
  const GpsTime& time() const { return clockTime_; }

  /// The systems of the signals of `sats`' constellations, sorted; false if none.
  bool setSystems(std::span<const SatId> sats);
  /// Adds the blocks at time t from per-system biases and the drift, x = [b_0 … b_{n−1}, ḋ] (m,
  /// m/s) with their σ: the prior b_s ~ N(x_s, σ_s²) independently per system and ḋ ~ N(x_n,
  /// σ_n²), written on the receiver clock c = b_0 and the inter-system biases i_s = b_s − b_0:
  /// a prior on [c, ḋ] and, for each other system, the row (c + i_s − x_s)/σ_s on both blocks.
  void create(vio::EstimatorBackend<Scalar>& est, const std::vector<double>& x, const std::vector<double>& sigma,
              const GpsTime& t);
  /// The blocks at time t (no step backwards): the clock by the two-state model, the ISBs by
  /// their random walk when isbRenewalInterval has passed.
  void propagate(vio::EstimatorBackend<Scalar>& est, const GpsTime& t, const GnssFusionConfig& config);
  /// [c·dt per clock system…, c·ḋt] (valid() only).
  Eigen::VectorXd values(const vio::EstimatorBackend<Scalar>& est) const;
  /// A system that joins after create() (its ephemerides came later) with inter-system bias
  /// `isb` ± `sigma` (m) at time t: the ISB block grows by one entry, x_new = [I; 0] x_old +
  /// [0; isb] + w, w ~ N(0, diag(q, σ²)) with q the ISBs' random walk since their last step
  /// (floored at 1 mm²: the step needs a regular Q).
  void addSystem(vio::EstimatorBackend<Scalar>& est, System s, double isb, double sigma, const GpsTime& t,
                 const GnssFusionConfig& config);
  /// Marginalizes the blocks (an outage); the systems stay until the next create().
  void marginalize(vio::EstimatorBackend<Scalar>& est);
  /// Forgets the blocks and the systems (the estimator's state is gone).
  void forget();

 private:
  sri::BlockId clock_, isb_;
  std::vector<System> systems_;
  GpsTime clockTime_;
  GpsTime isbTime_;  // last random-walk step of isb_ (or its creation)
};

extern template class GnssClockStates<float>;
extern template class GnssClockStates<double>;

}  // namespace gvins::fusion
