// The reported covariance of a weighted least-squares solution under an error model other than
// its weights (SppConfig::reportedError, docs/spp.md "Standard deviation").
#pragma once

#include <vector>

#include <Eigen/Core>

#include "gvins/gnss/spp_config.hpp"

namespace gvins::detail {

/// One row of the fit: design row h (size of the unknowns), the variance its weight came from
/// (1/w), the error variance r of the reported model and the post-fit residual.
struct ReportedRow {
  Eigen::VectorXd h;
  double weightVariance = 1.0;
  double errorVariance = 1.0;
  double residual = 0.0;
};

struct ReportedCovariance {
  Eigen::MatrixXd covariance;  ///< k Q (H^T W R W H) Q, Q = (H^T W H)^-1
  double varianceFactor = 1.0;  ///< k
};

/// `q`: the inverse of the normal matrix of the fit, which may hold further prior rows than
/// `rows` (those are taken as honest: their error variance is their weight's). `dof`: degrees of
/// freedom of the fit. The variance factor is max(1, (chi2_R + nu0) / (dof + nu0)), chi2_R the
/// sum of residual^2 / r over `rows`, when `scaling` is enabled (else 1).
ReportedCovariance reportedCovariance(const Eigen::MatrixXd& q, const std::vector<ReportedRow>& rows, int dof,
                                      const CovarianceScaling& scaling);

}  // namespace gvins::detail
