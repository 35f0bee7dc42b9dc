#include "gvins/fusion/gnss_lever_arm_state.hpp"

namespace gvins::fusion {

template <typename Scalar>
void GnssLeverArmState<Scalar>::create(vio::EstimatorBackend<Scalar>& est) {
  if (block_.valid()) return;
  block_ = est.addBlock(sri::BlockSpec::vector("gnss_lever_arm", 3),
                        sri::BlockEstimate<Scalar>::fromVector(start_.template cast<Scalar>()),
                        sri::Prior<Scalar>::stdDev(3, static_cast<Scalar>(sigma_)));
}

template <typename Scalar>
Eigen::Vector3d GnssLeverArmState<Scalar>::value(const vio::EstimatorBackend<Scalar>* est) const {
  if (block_.valid() && est) return est->estimate(block_).vector.template cast<double>();
  return carried();  // no block yet, or the state is gone (its last estimate, if plausible)
}

template <typename Scalar>
void GnssLeverArmState<Scalar>::record(const vio::EstimatorBackend<Scalar>& est) {
  if (block_.valid()) last_ = est.estimate(block_).vector.template cast<double>();
}

template <typename Scalar>
Eigen::Vector3d GnssLeverArmState<Scalar>::carried() const {
  if (last_ && ((*last_ - configured_).cwiseAbs().array() <= 3.0 * sigma_).all()) return *last_;
  return start_;
}

template <typename Scalar>
void GnssLeverArmState<Scalar>::forget() {
  start_ = carried();
  last_.reset();
  block_ = {};
}

template class GnssLeverArmState<float>;
template class GnssLeverArmState<double>;

}  // namespace gvins::fusion
