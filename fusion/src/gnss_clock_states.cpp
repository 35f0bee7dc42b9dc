#include "gvins/fusion/gnss_clock_states.hpp"

#include <algorithm>
#include <cmath>

namespace gvins::fusion {

template <typename Scalar>
sri::BlockId randomWalkStep(vio::EstimatorBackend<Scalar>& est, sri::BlockId id, const char* name, int size,
                            double variance) {
  using Mat = typename sri::Propagation<Scalar>::Matrix;
  sri::Propagation<Scalar> step;
  step.addNewBlock(sri::BlockSpec::vector(name, size), est.estimate(id));
  step.setTransition(id, Mat::Identity(size, size));
  step.setNoiseCovariance(Mat::Identity(size, size) * static_cast<Scalar>(variance));
  step.marginalizeAfter(id);
  return est.propagate(step, vio::ClientBlockRegion::kParameters).at(0);
}

template <typename Scalar>
int GnssClockStates<Scalar>::index(SatId sat) const {
  const System s = clockSystemOf(sat.system);
  for (std::size_t i = 0; i < systems_.size(); ++i) {
    if (systems_[i] == s) return static_cast<int>(i);
  }
  return -1;
}

template <typename Scalar>
bool GnssClockStates<Scalar>::setSystems(std::span<const SatId> sats) {
  systems_.clear();
  for (const SatId& sat : sats) {
    const System s = clockSystemOf(sat.system);
    if (std::find(systems_.begin(), systems_.end(), s) == systems_.end()) systems_.push_back(s);
  }
  std::sort(systems_.begin(), systems_.end());
  return !systems_.empty();
}

template <typename Scalar>
void GnssClockStates<Scalar>::create(vio::EstimatorBackend<Scalar>& est, const std::vector<double>& x,
                                     const std::vector<double>& sigma, const GpsTime& t) {
  const int n = static_cast<int>(systems_.size());
  using Vec = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>;
  Vec xc(2), sc(2);
  xc << static_cast<Scalar>(x[0]), static_cast<Scalar>(x[static_cast<std::size_t>(n)]);
  sc << static_cast<Scalar>(sigma[0]), static_cast<Scalar>(sigma[static_cast<std::size_t>(n)]);
  clock_ = est.addBlock(sri::BlockSpec::vector("gnss_clock", 2), sri::BlockEstimate<Scalar>::fromVector(xc),
                        sri::Prior<Scalar>::stdDevs(sc));
  if (n > 1) {
    Vec xi(n - 1);
    for (int s = 1; s < n; ++s) xi[s - 1] = static_cast<Scalar>(x[static_cast<std::size_t>(s)] - x[0]);
    isb_ = est.addBlock(sri::BlockSpec::vector("gnss_isb", n - 1), sri::BlockEstimate<Scalar>::fromVector(xi),
                        sri::Prior<Scalar>::uninformative());
    sri::Measurement<Scalar> m(n - 1);
    Vec w(n - 1);
    for (int s = 1; s < n; ++s) w[s - 1] = static_cast<Scalar>(1.0 / sigma[static_cast<std::size_t>(s)]);
    m.jacobian(clock_, 2).col(0) = w;  // (each jacobian() call may move the storage)
    m.jacobian(isb_, n - 1) = w.asDiagonal();
    m.residual().setZero();  // at the estimates above, c + i_s = x_s
    m.setWhitened();
    est.update(m, 1.0);
    isbTime_ = t;
  }
  clockTime_ = t;
}

template <typename Scalar>
void GnssClockStates<Scalar>::addSystem(vio::EstimatorBackend<Scalar>& est, System s, double isb, double sigma,
                                        const GpsTime& t, const GnssFusionConfig& config) {
  const int n = static_cast<int>(systems_.size());  // systems so far; the new one is index n, ISB entry n-1
  using Mat = typename sri::Propagation<Scalar>::Matrix;
  using Vec = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>;
  if (!isb_.valid()) {
    Vec x(1);
    x << static_cast<Scalar>(isb);
    isb_ = est.addBlock(sri::BlockSpec::vector("gnss_isb", 1), sri::BlockEstimate<Scalar>::fromVector(x),
                        sri::Prior<Scalar>::stdDev(1, static_cast<Scalar>(sigma)));
  } else {
    const Vec old = est.estimate(isb_).vector;
    Vec x(n);
    x.head(n - 1) = old;
    x[n - 1] = static_cast<Scalar>(isb);
    Mat phi = Mat::Zero(n, n - 1);
    phi.topRows(n - 1).setIdentity();
    const double q = std::max(config.isbRandomWalk * config.isbRandomWalk * std::max(t - isbTime_, 0.0), 1e-6);
    Mat Q = Mat::Identity(n, n) * static_cast<Scalar>(q);
    Q(n - 1, n - 1) = static_cast<Scalar>(sigma * sigma);
    sri::Propagation<Scalar> step;
    step.addNewBlock(sri::BlockSpec::vector("gnss_isb", n), sri::BlockEstimate<Scalar>::fromVector(x));
    step.setTransition(isb_, phi);
    step.setNoiseCovariance(Q);
    step.marginalizeAfter(isb_);
    isb_ = est.propagate(step, vio::ClientBlockRegion::kParameters).at(0);
  }
  isbTime_ = t;
  systems_.push_back(s);
}

template <typename Scalar>
void GnssClockStates<Scalar>::propagate(vio::EstimatorBackend<Scalar>& est, const GpsTime& t,
                                        const GnssFusionConfig& config) {
  const double dt = t - clockTime_;
  if (!clock_.valid() || dt <= 0.0) return;
  using Mat = typename sri::Propagation<Scalar>::Matrix;
  Mat phi = Mat::Identity(2, 2);
  phi(0, 1) = static_cast<Scalar>(dt);
  // Bias b' = b + d·dt, drift d' = d: white-noise drift q_d and bias random walk q_b over dt
  // (two-state clock model, e.g. Brown & Hwang, "Introduction to Random Signals and Applied
  // Kalman Filtering", 4th ed., sec. 9.3). The inter-system biases are constant: only these two
  // columns are replaced (and swept past the state) per epoch.
  const double qb = std::pow(config.clockBiasRandomWalk, 2), qd = std::pow(config.clockDriftRandomWalk, 2);
  Eigen::Matrix2d Q;
  Q << qb * dt + qd * dt * dt * dt / 3.0, qd * dt * dt / 2.0, qd * dt * dt / 2.0, qd * dt;
  const Eigen::VectorXd x = est.estimate(clock_).vector.template cast<double>();
  const Eigen::VectorXd xp = phi.template cast<double>() * x;
  sri::Propagation<Scalar> step;
  step.addNewBlock(sri::BlockSpec::vector("gnss_clock", 2),
                   sri::BlockEstimate<Scalar>::fromVector(xp.template cast<Scalar>()));
  step.setTransition(clock_, phi);
  step.setNoiseCovariance(Q.template cast<Scalar>());
  step.marginalizeAfter(clock_);
  clock_ = est.propagate(step, vio::ClientBlockRegion::kParameters).at(0);
  clockTime_ = t;
  // The inter-system biases: a random walk stepped every isbRenewalInterval seconds with the
  // variance accumulated since the last step (Brown & Hwang, sec. 9.3: a Wiener process sampled
  // at those instants; no columns swept in between).
  const double di = t - isbTime_;
  if (!isb_.valid() || !(config.isbRandomWalk > 0.0) || di < config.isbRenewalInterval) return;
  isb_ = randomWalkStep(est, isb_, "gnss_isb", static_cast<int>(systems_.size()) - 1,
                        config.isbRandomWalk * config.isbRandomWalk * di);
  isbTime_ = t;
}

template <typename Scalar>
Eigen::VectorXd GnssClockStates<Scalar>::values(const vio::EstimatorBackend<Scalar>& est) const {
  const int n = static_cast<int>(systems_.size());
  const Eigen::VectorXd c = est.estimate(clock_).vector.template cast<double>();
  Eigen::VectorXd out = Eigen::VectorXd::Constant(n + 1, c[0]);
  out[n] = c[1];
  if (isb_.valid()) out.segment(1, n - 1) += est.estimate(isb_).vector.template cast<double>();
  return out;
}

template <typename Scalar>
void GnssClockStates<Scalar>::marginalize(vio::EstimatorBackend<Scalar>& est) {
  for (sri::BlockId* id : {&clock_, &isb_}) {
    if (id->valid() && est.contains(*id)) est.marginalize(std::span<const sri::BlockId>(id, 1));
    *id = {};
  }
}

template <typename Scalar>
void GnssClockStates<Scalar>::forget() {
  clock_ = {};
  isb_ = {};
  systems_.clear();
}

template sri::BlockId randomWalkStep(vio::EstimatorBackend<float>&, sri::BlockId, const char*, int, double);
template sri::BlockId randomWalkStep(vio::EstimatorBackend<double>&, sri::BlockId, const char*, int, double);
template class GnssClockStates<float>;
template class GnssClockStates<double>;

}  // namespace gvins::fusion
