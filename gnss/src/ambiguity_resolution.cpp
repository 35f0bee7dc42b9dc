#include "gvins/gnss/ambiguity_resolution.hpp"

#include <algorithm>
#include <cmath>

namespace gvins {

bool passesValidation(double ratio, double successRate, const AmbiguityResolutionOptions& o) {
  const bool r = ratio >= o.ratioThreshold;
  const bool s = successRate >= 1.0 - o.maxFailureRate;
  switch (o.validation) {
    case AmbiguityValidation::Ratio: return r;
    case AmbiguityValidation::SuccessRate: return s;
    case AmbiguityValidation::RatioAndSuccessRate: return r && s;
  }
  return false;
}

AmbiguityFix resolveAmbiguities(const Eigen::VectorXd& afloat, const Eigen::MatrixXd& Q,
                                const AmbiguityResolutionOptions& o, const ReductionStart* basis) {
  AmbiguityFix fix;
  const int n = static_cast<int>(afloat.size());
  if (n == 0 || n < std::max(1, o.minFixed)) return fix;
  IlsSearchOptions so;
  so.candidates = 2;
  so.maxNodes = o.maxNodes;
  const LambdaResult full = lambda(afloat, Q, so, basis);
  if (full.reduction.factor.d.size() == n) fix.basis = {full.reduction.Z, full.reduction.Zinv};
  fix.attempts = 1;
  fix.nodes = full.nodes;
  fix.fullRatio = full.ratio;
  fix.fullSuccessRate = full.successRate;
  fix.ratio = full.ratio;
  fix.successRate = full.successRate;
  if (full.ok && passesValidation(full.ratio, full.successRate, o)) {
    fix.fixed = true;
    fix.T = Eigen::MatrixXd::Identity(n, n);
    fix.values = full.fixed[0];
    fix.fullSolution = full.fixed[0];
    fix.bestNorm = full.squaredNorms[0];
    return fix;
  }
  if (!o.partial || full.reduction.factor.d.size() != n) return fix;

  // Partial fixing in the decorrelated parametrisation. The trailing block of Q_z = LᵀDL is
  // L_22ᵀ D_2 L_22, so a trailing subset keeps its own factor.
  const Eigen::VectorXd& d = full.reduction.factor.d;
  // Shortest start index whose trailing subset still reaches the success-rate target.
  int start = n;
  double p = 1.0;
  for (int k = n - 1; k >= 0; --k) {
    const double pk = std::erf(1.0 / (2.0 * std::sqrt(2.0) * std::sqrt(std::max(d[k], 1e-300))));
    if (p * pk < o.partialSuccessRate) break;
    p *= pk;
    start = k;
  }
  // The full set (start = 0) was already tried.
  if (start == 0) start = 1;
  // Integer shift as in lambda(): work with fractional parts, add the shift back.
  Eigen::VectorXd shift(n);
  for (int i = 0; i < n; ++i) shift[i] = std::nearbyint(afloat[i]);
  const Eigen::VectorXd zfrac = full.reduction.Z.transpose() * (afloat - shift);
  for (int attempt = 0; attempt < o.maxPartialAttempts && n - start >= std::max(1, o.minFixed); ++attempt, ++start) {
    const int m = n - start;
    LtdlFactor sub;
    sub.L = full.reduction.factor.L.bottomRightCorner(m, m);
    sub.d = d.tail(m);
    const IlsSearchResult s = searchIntegerLeastSquares(sub, zfrac.tail(m), so);
    ++fix.attempts;
    fix.nodes += s.nodes;
    if (!s.complete || s.candidates.size() < 2) continue;
    const double ratio = s.squaredNorms[0] > 0.0 ? s.squaredNorms[1] / s.squaredNorms[0] : 1e12;
    const double ps = bootstrapSuccessRate(sub.d);
    if (!passesValidation(ratio, ps, o)) continue;
    fix.fixed = true;
    fix.partial = true;
    fix.T = full.reduction.Z.rightCols(m).transpose();  // z_sub = T a
    fix.values = s.candidates[0] + fix.T * shift;
    fix.ratio = ratio;
    fix.successRate = ps;
    fix.bestNorm = s.squaredNorms[0];
    return fix;
  }
  return fix;
}

}  // namespace gvins
