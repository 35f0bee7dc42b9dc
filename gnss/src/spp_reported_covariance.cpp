#include "spp_reported_covariance.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>

namespace gvins::detail {

namespace {
constexpr double kEarthMeanRadius = 6371000.0;  // m (IUGG mean radius)

Eigen::MatrixXd symmetricInverse(const Eigen::MatrixXd& n) {
  return n.ldlt().solve(Eigen::MatrixXd::Identity(n.rows(), n.cols()));
}
}  // namespace

Eigen::Vector3d ionosphericPiercePoint(const Eigen::Vector3d& receiver, const Eigen::Vector3d& satellite,
                                       double shellHeight) {
  // |r + s e| = R + h for the line of sight e, the positive root s.
  const Eigen::Vector3d e = (satellite - receiver).normalized();
  const double shell = kEarthMeanRadius + shellHeight;
  const double b = receiver.dot(e);
  const double c = receiver.squaredNorm() - shell * shell;
  const double s = -b + std::sqrt(std::max(b * b - c, 0.0));
  return (receiver + s * e).normalized();
}

Eigen::MatrixXd rowErrorCovariance(const std::vector<ReportedRow>& rows, double troposphereZenithSigma,
                                   double ionosphereCorrelationLength) {
  const auto n = static_cast<Eigen::Index>(rows.size());
  Eigen::MatrixXd r(n, n);
  const double shell = kEarthMeanRadius + 350e3;  // distances on the model's shell (no need for precision)
  const double st2 = troposphereZenithSigma * troposphereZenithSigma;
  for (Eigen::Index i = 0; i < n; ++i) {
    const ReportedRow& a = rows[i];
    for (Eigen::Index j = 0; j <= i; ++j) {
      const ReportedRow& b = rows[j];
      const double angle = std::acos(std::clamp(a.piercePoint.dot(b.piercePoint), -1.0, 1.0));
      const double dl = shell * angle / ionosphereCorrelationLength;
      const double rho = std::exp(-0.5 * dl * dl);
      r(i, j) = r(j, i) = a.ionosphereSigma * b.ionosphereSigma * rho + st2 * a.troposphereMap * b.troposphereMap;
    }
    r(i, i) += a.independentVariance;
  }
  return r;
}

namespace {
/// The median estimate of the variance factor over all rows (see reportedCovariance): v = B e
/// with B = [A 0; -H_x G0 I] for the kept rows f and the excluded rows x.
double medianVarianceFactor(const ReportedInputs& in, const std::vector<Eigen::Index>& kept,
                            const std::vector<Eigen::Index>& excluded, const Eigen::MatrixXd& a,
                            const Eigen::MatrixXd& g0, const Eigen::MatrixXd& rIndAll, const Eigen::MatrixXd& rCommonAll) {
  const auto nf = static_cast<Eigen::Index>(kept.size());
  const auto nAll = nf + static_cast<Eigen::Index>(excluded.size());
  std::vector<Eigen::Index> order = kept;
  order.insert(order.end(), excluded.begin(), excluded.end());
  Eigen::MatrixXd b = Eigen::MatrixXd::Zero(nAll, nAll);
  b.topLeftCorner(nf, nf) = a;
  for (Eigen::Index r = nf; r < nAll; ++r) {
    b.block(r, 0, 1, nf) = -in.rows[order[r]].h.transpose() * g0;
    b(r, r) = 1.0;
  }
  const Eigen::MatrixXd ri = rIndAll(order, order), rc = rCommonAll(order, order);
  const Eigen::VectorXd dInd = (b * ri * b.transpose()).diagonal(), dCommon = (b * rc * b.transpose()).diagonal();
  std::vector<double> q;
  for (Eigen::Index i = 0; i < nAll; ++i) {
    const double v = in.rows[order[i]].residual;
    if (dInd[i] > 0.0) q.push_back((v * v - dCommon[i]) / dInd[i]);
  }
  if (q.empty()) return 0.0;
  std::nth_element(q.begin(), q.begin() + static_cast<long>(q.size() / 2), q.end());
  constexpr double kChi2Median1 = 0.454936;  // median of chi-square with one degree of freedom
  return q[q.size() / 2] / kChi2Median1;
}
}  // namespace

ReportedCovariance reportedCovariance(const ReportedInputs& in, const CovarianceScaling& scaling) {
  std::vector<Eigen::Index> kept, excluded;
  for (Eigen::Index i = 0; i < static_cast<Eigen::Index>(in.rows.size()); ++i) {
    (in.rows[i].excluded ? excluded : kept).push_back(i);
  }
  const auto n = static_cast<Eigen::Index>(kept.size());
  const auto m = in.q.rows();
  Eigen::MatrixXd h(n, m);
  Eigen::VectorXd w(n), w0(n), v(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const ReportedRow& row = in.rows[kept[i]];
    h.row(i) = row.h.transpose();
    w[i] = row.weight;
    w0[i] = row.priorWeight;
    v[i] = row.residual;
  }
  // The independent and the common (correlated) parts of R apart: residuals scale the former.
  const Eigen::MatrixXd rAll = rowErrorCovariance(in.rows, in.troposphereZenithSigma, in.ionosphereCorrelationLength);
  Eigen::MatrixXd rIndAll = Eigen::MatrixXd::Zero(rAll.rows(), rAll.cols());
  for (Eigen::Index i = 0; i < rAll.rows(); ++i) rIndAll(i, i) = in.rows[i].independentVariance;
  const Eigen::MatrixXd rCommonAll = rAll - rIndAll;
  const Eigen::MatrixXd rCommon = rCommonAll(kept, kept);
  const Eigen::VectorXd rIndependent = rIndAll.diagonal()(kept);
  // Information of the prior rows: the normal matrix minus the measurements' share; the
  // inter-system bias priors are what remains after the ionosphere prior.
  const Eigen::MatrixXd nFinal = symmetricInverse(in.q);
  const Eigen::MatrixXd nPrior = nFinal - h.transpose() * w.asDiagonal() * h;
  Eigen::MatrixXd nIsb = nPrior;
  if (in.ionosphereColumn >= 0) nIsb(in.ionosphereColumn, in.ionosphereColumn) -= in.ionospherePriorWeight;
  const Eigen::MatrixXd g = in.q * h.transpose() * w.asDiagonal();
  // The expectation of the a-priori fit's weighted residuals under each part of R: v = (I - H G0) e
  // for the measurements, and -(G0 e)_ion for the ionosphere prior.
  const Eigen::MatrixXd q0 = symmetricInverse(nPrior + h.transpose() * w0.asDiagonal() * h);
  const Eigen::MatrixXd g0 = q0 * h.transpose() * w0.asDiagonal();
  const Eigen::MatrixXd a = Eigen::MatrixXd::Identity(n, n) - h * g0;
  auto expected = [&](const Eigen::MatrixXd& r) {
    double e = (w0.asDiagonal() * a * r * a.transpose()).trace();
    if (in.ionosphereColumn >= 0) {
      const auto c = in.ionosphereColumn;
      e += in.ionospherePriorWeight * (g0.row(c) * r * g0.row(c).transpose())(0, 0);
    }
    return e;
  };
  ReportedCovariance out;
  const Eigen::MatrixXd rInd = rIndependent.asDiagonal();
  const double eInd = expected(rInd), eCommon = expected(rCommon);
  out.expectedChi2 = eInd + eCommon;
  out.chi2 = v.dot(w0.asDiagonal() * v);
  if (in.ionosphereColumn >= 0) out.chi2 += in.ionospherePriorWeight * in.ionosphereCorrection * in.ionosphereCorrection;
  if (scaling.enabled && in.dof >= 1) {
    out.varianceFactor = std::max(in.minVarianceFactor, (out.chi2 - eCommon + scaling.priorDof) / (eInd + scaling.priorDof));
    if (!excluded.empty()) {
      out.varianceFactor =
          std::max(out.varianceFactor, medianVarianceFactor(in, kept, excluded, a, g0, rIndAll, rCommonAll));
    }
  }
  const double k = out.varianceFactor;
  if (k > 1.0 && in.excessCorrelation > 0.0) {
    // The excess over the noise model, correlated by rho between the rows (one sign: delays that
    // are never negative): R_exc = (1 - rho) D + rho s s^T, scaled so that its expectation in the
    // residuals is the excess (k - 1) E_ind that k found.
    const Eigen::VectorXd sd = rIndependent.cwiseSqrt();
    const Eigen::MatrixXd rExcess = (1.0 - in.excessCorrelation) * rInd + in.excessCorrelation * sd * sd.transpose();
    const double eExcess = expected(rExcess);
    out.excessFactor = eExcess > 0.0 ? (k - 1.0) * eInd / eExcess : 0.0;
    out.covariance = g * (rInd + out.excessFactor * rExcess + rCommon) * g.transpose() + in.q * nIsb * in.q;
  } else {
    out.covariance = k * g * rInd * g.transpose() + g * rCommon * g.transpose() + in.q * nIsb * in.q;
  }
  out.covariance = 0.5 * (out.covariance + out.covariance.transpose());
  return out;
}

}  // namespace gvins::detail
