#include "gvins/fusion/gnss_zwd_state.hpp"

#include <span>

#include "gvins/fusion/gnss_clock_states.hpp"  // randomWalkStep

namespace gvins::fusion {

template <typename Scalar>
void GnssZwdState<Scalar>::create(vio::EstimatorBackend<Scalar>& est, const GpsTime& t, double sigma) {
  const Eigen::Matrix<Scalar, Eigen::Dynamic, 1> z = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>::Zero(1);
  block_ = est.addBlock(sri::BlockSpec::vector("gnss_zwd", 1), sri::BlockEstimate<Scalar>::fromVector(z),
                        sri::Prior<Scalar>::stdDev(1, static_cast<Scalar>(sigma)));
  time_ = t;
}

template <typename Scalar>
void GnssZwdState<Scalar>::propagate(vio::EstimatorBackend<Scalar>& est, const GpsTime& t, double randomWalk) {
  const double dt = t - time_;
  if (!block_.valid() || dt <= 0.0) return;
  block_ = randomWalkStep(est, block_, "gnss_zwd", 1, randomWalk * randomWalk * dt);
  time_ = t;
}

template <typename Scalar>
double GnssZwdState<Scalar>::value(const vio::EstimatorBackend<Scalar>& est) const {
  return static_cast<double>(est.estimate(block_).vector[0]);
}

template <typename Scalar>
void GnssZwdState<Scalar>::marginalize(vio::EstimatorBackend<Scalar>& est) {
  if (block_.valid() && est.contains(block_)) est.marginalize(std::span<const sri::BlockId>(&block_, 1));
  block_ = {};
}

template class GnssZwdState<float>;
template class GnssZwdState<double>;

}  // namespace gvins::fusion
