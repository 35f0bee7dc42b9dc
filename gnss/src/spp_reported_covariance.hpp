// The reported covariance of SPP's weighted least-squares solution under an error model with
// errors correlated between satellites (SppConfig::reportedError, docs/spp.md "Standard
// deviation").
#pragma once

#include <vector>

#include <Eigen/Core>

#include "gvins/gnss/spp_config.hpp"

namespace gvins::detail {

/// One pseudorange of the fit and its error budget.
struct ReportedRow {
  Eigen::VectorXd h;             ///< design row (size of the unknowns)
  double weight = 1.0;           ///< weight of the final fit (after robust re-weighting)
  double priorWeight = 1.0;      ///< a-priori weight (before robust re-weighting)
  double independentVariance = 0.0;  ///< m^2: noise and multipath, broadcast orbit and clock
  double ionosphereSigma = 0.0;  ///< m: slant broadcast-ionosphere error
  Eigen::Vector3d piercePoint = Eigen::Vector3d::UnitZ();  ///< unit vector (ECEF) of the pierce point
  double troposphereMap = 0.0;   ///< slant/zenith of the troposphere residual
  double residual = 0.0;         ///< m, post-fit, a-priori fit (before robust re-weighting)
  /// Removed by fault exclusion: not in the fit (its weights are ignored); its residual is the
  /// prediction residual at the a-priori fit's solution and enters only the median estimate of
  /// the variance factor.
  bool excluded = false;
};

struct ReportedInputs {
  Eigen::MatrixXd q;  ///< inverse normal matrix of the final fit, with its prior rows
  std::vector<ReportedRow> rows;
  int ionosphereColumn = -1;          ///< column of the zenith ionosphere correction, -1: none
  double ionosphereCorrection = 0.0;  ///< its estimate (m)
  double ionospherePriorWeight = 0.0;
  double troposphereZenithSigma = 0.0;   ///< m
  double ionosphereCorrelationLength = 1.0;  ///< m, between pierce points
  int dof = 0;  ///< degrees of freedom of the fit (no variance factor without)
  double minVarianceFactor = 1.0;  ///< floor of the independent part's variance factor
  double excessCorrelation = 0.0;  ///< rho of the excess over the noise model (k > 1) between rows
};

struct ReportedCovariance {
  Eigen::MatrixXd covariance;   ///< k G R G^T + the prior rows' own share
  double varianceFactor = 1.0;  ///< k, of the independent part
  double excessFactor = 0.0;    ///< x, of the excess R_exc (0 when k <= 1 or rho = 0)
  double chi2 = 0.0;            ///< weighted a-priori residuals (measurements, ionosphere prior)
  double expectedChi2 = 0.0;    ///< its expectation under R (before k)
};

/// The pierce point (unit vector from the Earth's centre) of the line of sight from `receiver`
/// to `satellite` (ECEF, m) through a thin shell `shellHeight` above a sphere of the Earth's mean
/// radius.
Eigen::Vector3d ionosphericPiercePoint(const Eigen::Vector3d& receiver, const Eigen::Vector3d& satellite,
                                       double shellHeight);

/// The error covariance R of the rows: independent variances on the diagonal, the broadcast
/// ionosphere error correlated as exp(-d^2 / (2 L^2)) with d the distance of the pierce points on
/// a 350 km shell, and the troposphere residual at the zenith common to all lines of sight.
Eigen::MatrixXd rowErrorCovariance(const std::vector<ReportedRow>& rows, double troposphereZenithSigma,
                                   double ionosphereCorrelationLength);

/// The covariance of the weighted solution x = G y (G = Q H^T W) under R, k G R_ind G^T +
/// G R_common G^T, plus the share of the prior rows other than the ionosphere's (the inter-system
/// biases, taken as honest). The ionosphere prior carries no error of its own: the whole
/// ionosphere error is in R. k = max(minVarianceFactor, (chi2 - E_common + nu0) / (E_ind + nu0))
/// when `scaling` is enabled (else 1), chi2 the weighted residuals of the a-priori fit
/// (measurements and the ionosphere prior) and E their expectations under the two parts of R.
/// With excluded rows, chi2 is that of the rows fault exclusion kept, the smallest residuals: a
/// truncated sample that understates the noise when the exclusions took its tail rather than
/// faults. k is then at least the median over all rows, excluded ones included, of
/// (v_i^2 - E_common,i) / E_ind,i divided by the median of chi-square with one degree of freedom
/// (0.4549): a scale estimate that a minority of faults cannot move and the truncation cannot
/// bias (cf. the MAD scale of robust estimation, Huber 1981, Robust Statistics, ch. 5).
/// With k > 1 and excessCorrelation rho > 0 the excess k - 1 is not independent: the covariance
/// is G (R_ind + x R_exc + R_common) G^T + (prior rows), R_exc = (1 - rho) R_ind + rho s s^T
/// (s_i = sqrt(R_ind,ii)), x = (k - 1) E_ind / E_exc with E_exc its expectation in the residuals.
ReportedCovariance reportedCovariance(const ReportedInputs& in, const CovarianceScaling& scaling);

}  // namespace gvins::detail
