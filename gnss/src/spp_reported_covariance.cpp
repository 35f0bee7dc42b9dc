#include "spp_reported_covariance.hpp"

#include <algorithm>

namespace gvins::detail {

ReportedCovariance reportedCovariance(const Eigen::MatrixXd& q, const std::vector<ReportedRow>& rows, int dof,
                                      const CovarianceScaling& scaling) {
  // With N = H^T W H the sum over all rows of w h h^T, and the rows not listed honest (w^2 r = w):
  //   H^T W R W H = N + sum_listed w (w r - 1) h h^T,  so  Q M Q = Q + Q D Q.
  const auto m = q.rows();
  Eigen::MatrixXd d = Eigen::MatrixXd::Zero(m, m);
  double chi2 = 0.0;
  for (const ReportedRow& row : rows) {
    const double w = 1.0 / row.weightVariance;
    d.noalias() += (w * (w * row.errorVariance - 1.0)) * row.h * row.h.transpose();
    chi2 += row.residual * row.residual / row.errorVariance;
  }
  ReportedCovariance out;
  out.covariance = q + q * d * q;
  out.covariance = 0.5 * (out.covariance + out.covariance.transpose());
  if (scaling.enabled && dof >= 1) {
    out.varianceFactor = std::max(1.0, (chi2 + scaling.priorDof) / (dof + scaling.priorDof));
  }
  out.covariance *= out.varianceFactor;
  return out;
}

}  // namespace gvins::detail
