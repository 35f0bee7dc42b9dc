// The ionosphere-weighted model of RtkSolver (rtk_config.hpp RtkConfig::ionosphereSigmaPpm): one
// state per satellite for the single-differenced slant ionospheric delay on L1, I (m). A signal of
// wavelength λ sees μ I with μ = (λ / λ_L1)² (first-order delay ∝ 1/f²): the code is delayed by
// μ I, the phase advanced by μ I. The states have a prior proportional to the baseline (the
// "ionosphere-weighted" pseudo-observation I = 0 ± σ of Odijk 2002, ch. 5, here as the prior of
// the state) and walk slowly; only differences between satellites enter the double differences,
// the common part stays at its prior.
#include <algorithm>
#include <cmath>
#include <vector>

#include "gvins/base/signal.hpp"
#include "gvins/gnss/klobuchar.hpp"
#include "gvins/gnss/rtk.hpp"

namespace gvins {


double RtkSolver::ionosphereSigma(double elevation) const {
  const double zenith = cfg_.ionosphereSigmaPpm * 1e-6 * baseline_;
  if (!(zenith > 0.0) || zenith < cfg_.ionosphereMinSigma) return 0.0;
  return zenith * klobucharObliquity(std::max(elevation, 0.0));
}

double ionosphereDelayFactor(double wavelength) {
  static const double l1 = *carrierWavelength(System::Gps, '1');
  if (!(wavelength > 0.0)) return 0.0;
  const double r = wavelength / l1;
  return r * r;
}

double ddIonosphericDelay(double wavelengthS, double ionosphereS, double wavelengthR, double ionosphereR) {
  return ionosphereDelayFactor(wavelengthS) * ionosphereS - ionosphereDelayFactor(wavelengthR) * ionosphereR;
}

double RtkSolver::ionosphereEstimate(SatId sat) const {
  const auto it = iono_.find(satIndex(sat));
  return it == iono_.end() ? 0.0 : filter_.estimate(it->second.id).vector[0];
}

sri::BlockId RtkSolver::ionosphereBlock(SatId sat) const {
  const auto it = iono_.find(satIndex(sat));
  return it == iono_.end() ? sri::BlockId{} : it->second.id;
}

double RtkSolver::ddIonosphere(const SingleDifference& s, const SingleDifference& r,
                               const std::unordered_map<int, double>* conditioned) const {
  auto value = [&](SatId sat) {
    if (conditioned) {
      const auto it = conditioned->find(satIndex(sat));
      if (it != conditioned->end()) return it->second;
    }
    return ionosphereEstimate(sat);
  };
  return ddIonosphericDelay(s.wavelength, value(s.sat), r.wavelength, value(r.sat));
}

void RtkSolver::ionosphereColumns(sri::Measurement<double>& m, int row, const SingleDifference& s,
                                  const SingleDifference& r, double sign) const {
  const sri::BlockId is = ionosphereBlock(s.sat), ir = ionosphereBlock(r.sat);
  // (jacobian() of a new block reallocates: take the block afresh each time.)
  if (is.valid()) m.jacobian(is, 1)(row, 0) += sign * ionosphereDelayFactor(s.wavelength);
  if (ir.valid()) m.jacobian(ir, 1)(row, 0) -= sign * ionosphereDelayFactor(r.wavelength);
}

void RtkSolver::manageIonosphere() {
  std::vector<char> used(dd_.sd.size(), 0);
  for (const auto* list : {&dd_.phase, &dd_.code}) {
    for (const DoubleDifference& d : *list) {
      used[static_cast<std::size_t>(d.satellite)] = 1;
      used[static_cast<std::size_t>(d.reference)] = 1;
    }
  }
  for (std::size_t i = 0; i < dd_.sd.size(); ++i) {
    if (!used[i]) continue;
    const SingleDifference& sd = dd_.sd[i];
    const int k = satIndex(sd.sat);
    const auto it = iono_.find(k);
    if (it != iono_.end()) {
      it->second.lastSeen = dd_.time;
      it->second.elevation = sd.elevation;
      continue;
    }
    const double sigma = ionosphereSigma(sd.elevation);
    if (!(sigma > 0.0)) continue;
    Ionosphere s;
    s.id = filter_.addBlock(sri::BlockSpec::vector("ionosphere", 1), sri::BlockEstimate<double>::fromVector(Eigen::VectorXd::Zero(1)),
                            sri::Prior<double>::stdDev(1, sigma), sri::Placement::before(pos_));
    s.lastSeen = dd_.time;
    s.elevation = sd.elevation;
    iono_[k] = s;
  }
  std::vector<int> stale;
  for (const auto& [k, s] : iono_) {
    if (elapsed(direction_, dd_.time, s.lastSeen) > cfg_.ambiguityOutage) stale.push_back(k);
  }
  for (int k : stale) {
    filter_.marginalize(iono_.at(k).id);
    iono_.erase(k);
  }
}

void RtkSolver::propagateIonosphere(double dt) {
  if (iono_.empty()) return;
  const double adt = std::abs(dt);
  if (!(adt > 0.0)) return;
  const int n = static_cast<int>(iono_.size());
  sri::Propagation<double> p;
  Eigen::MatrixXd Q = Eigen::MatrixXd::Zero(n, n);
  std::vector<int> order;
  int row = 0;
  for (const auto& [k, s] : iono_) {
    order.push_back(k);
    p.addNewBlock(sri::BlockSpec::vector("ionosphere", 1), filter_.estimate(s.id));
    const double q = cfg_.ionosphereRatePpm * 1e-6 * baseline_ * klobucharObliquity(std::max(s.elevation, 0.0));
    Q(row, row) = q * q * adt + 1e-12;
    ++row;
  }
  row = 0;
  for (int k : order) {
    Eigen::MatrixXd phi = Eigen::MatrixXd::Zero(n, 1);
    phi(row, 0) = 1.0;
    p.setTransition(iono_.at(k).id, phi);
    p.marginalizeAfter(iono_.at(k).id);
    ++row;
  }
  p.setNoiseCovariance(Q);
  const auto ids = filter_.propagate(p);
  row = 0;
  for (int k : order) iono_.at(k).id = ids[static_cast<std::size_t>(row++)];
}

}  // namespace gvins
