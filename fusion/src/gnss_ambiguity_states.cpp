#include "gvins/fusion/gnss_ambiguity_states.hpp"

#include <span>
#include <stdexcept>
#include <string>

namespace gvins::fusion {

template <typename Scalar>
sri::BlockId GnssAmbiguityStates<Scalar>::block(SatId sat) const {
  const auto it = states_.find(sat);
  return it == states_.end() ? sri::BlockId{} : it->second.id;
}

template <typename Scalar>
GnssAmbiguityArc* GnssAmbiguityStates<Scalar>::arc(SatId sat) {
  const auto it = states_.find(sat);
  return it == states_.end() ? nullptr : &it->second.arc;
}

template <typename Scalar>
double GnssAmbiguityStates<Scalar>::value(const vio::EstimatorBackend<Scalar>& est, SatId sat) const {
  return static_cast<double>(est.estimate(states_.at(sat).id).vector[0]);
}

template <typename Scalar>
std::map<SatId, double> GnssAmbiguityStates<Scalar>::values(const vio::EstimatorBackend<Scalar>& est) const {
  std::map<SatId, double> out;
  for (const auto& [sat, s] : states_) out[sat] = static_cast<double>(est.estimate(s.id).vector[0]);
  return out;
}

template <typename Scalar>
GnssAmbiguityArc& GnssAmbiguityStates<Scalar>::add(vio::EstimatorBackend<Scalar>& est, SatId sat, double x,
                                                   double sigma, const GpsTime& arcStart) {
  if (states_.count(sat)) {
    throw std::logic_error("GnssAmbiguityStates::add: satellite " + sat.str() + " already has a state");
  }
  Eigen::Matrix<Scalar, Eigen::Dynamic, 1> v(1);
  v[0] = static_cast<Scalar>(x);
  State s;
  s.id = est.addBlock(sri::BlockSpec::vector("gnss_ambiguity", 1), sri::BlockEstimate<Scalar>::fromVector(v),
                      sri::Prior<Scalar>::stdDev(1, static_cast<Scalar>(sigma)), vio::ClientBlockRegion::kFront);
  s.arc.start = arcStart;
  return states_.emplace(sat, s).first->second.arc;
}

template <typename Scalar>
void GnssAmbiguityStates<Scalar>::propagate(vio::EstimatorBackend<Scalar>& est, const std::vector<SatId>& sats,
                                            const GpsTime& t, double randomWalk) {
  const double dt = time_ ? t - *time_ : 0.0;
  time_ = t;
  const double q = randomWalk;
  if (!(dt > 0.0) || !(q > 0.0)) return;
  std::vector<SatId> stepped;
  for (const SatId& s : sats)
    if (states_.count(s)) stepped.push_back(s);
  if (stepped.empty()) return;
  // One propagation for all: x' = x with noise q²·Δt I, each old block marginalized after its new
  // one is in.
  using Mat = typename sri::Propagation<Scalar>::Matrix;
  const auto n = static_cast<Eigen::Index>(stepped.size());
  sri::Propagation<Scalar> step;
  for (Eigen::Index i = 0; i < n; ++i) {
    const sri::BlockId old = states_.at(stepped[static_cast<std::size_t>(i)]).id;
    step.addNewBlock(sri::BlockSpec::vector("gnss_ambiguity", 1), est.estimate(old));
    Mat phi = Mat::Zero(n, 1);
    phi(i, 0) = Scalar(1);
    step.setTransition(old, phi);
    step.marginalizeAfter(old);
  }
  step.setNoiseCovariance(Mat::Identity(n, n) * static_cast<Scalar>(q * q * dt));
  const std::vector<sri::BlockId> ids = est.propagate(step, vio::ClientBlockRegion::kFront);
  for (Eigen::Index i = 0; i < n; ++i)
    states_.at(stepped[static_cast<std::size_t>(i)]).id = ids.at(static_cast<std::size_t>(i));
}

template <typename Scalar>
void GnssAmbiguityStates<Scalar>::drop(vio::EstimatorBackend<Scalar>& est, SatId sat) {
  const auto it = states_.find(sat);
  if (it == states_.end()) return;
  const sri::BlockId id = it->second.id;
  if (id.valid() && est.contains(id)) est.marginalize(std::span<const sri::BlockId>(&id, 1));
  states_.erase(it);
}

template <typename Scalar>
void GnssAmbiguityStates<Scalar>::dropStale(vio::EstimatorBackend<Scalar>& est, const GpsTime& now, double maxAge) {
  for (auto it = states_.begin(); it != states_.end();) {
    const SatId sat = it->first;
    const bool stale = now - it->second.arc.lastRow > maxAge;
    ++it;
    if (stale) drop(est, sat);
  }
}

template <typename Scalar>
void GnssAmbiguityStates<Scalar>::dropAll(vio::EstimatorBackend<Scalar>& est) {
  while (!states_.empty()) drop(est, states_.begin()->first);
  time_.reset();
}

template <typename Scalar>
void GnssAmbiguityStates<Scalar>::forget() {
  states_.clear();
  time_.reset();
}

template class GnssAmbiguityStates<float>;
template class GnssAmbiguityStates<double>;

}  // namespace gvins::fusion
