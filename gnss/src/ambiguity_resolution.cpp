#include "gvins/gnss/ambiguity_resolution.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <vector>

namespace gvins {

const char* toString(AmbiguityValidation v) { return enumName(kAmbiguityValidationNames, v); }

std::optional<AmbiguityValidation> parseAmbiguityValidation(std::string_view text) {
  return enumFromName(kAmbiguityValidationNames, text);
}

bool passesValidation(double ratio, double successRate, const AmbiguityResolutionOptions& o, double criticalRatio) {
  const bool r = ratio >= o.ratioThreshold;
  const bool s = successRate >= 1.0 - o.maxFailureRate;
  switch (o.validation) {
    case AmbiguityValidation::Ratio: return r;
    case AmbiguityValidation::SuccessRate: return s;
    case AmbiguityValidation::RatioAndSuccessRate: return r && s;
    case AmbiguityValidation::FixedFailureRate: return r && ratio >= criticalRatio;
  }
  return false;
}

double fixedFailureRateCriticalRatio(const LtdlFactor& f, const AmbiguityResolutionOptions& o) {
  const int n = static_cast<int>(f.d.size());
  const int samples = std::max(1, o.ffrtSamples);
  // Draws of ẑ − z = Lᵀw, w ~ N(0, diag(d)) (the factor's definition, lambda.hpp), around z = 0.
  std::mt19937_64 rng(0x9e3779b97f4a7c15ULL);
  std::normal_distribution<double> normal;
  IlsSearchOptions so;
  so.candidates = 2;
  so.maxNodes = o.ffrtMaxNodes;
  const Eigen::VectorXd sd = f.d.cwiseMax(0.0).cwiseSqrt();
  const Eigen::MatrixXd Lt = f.L.transpose();
  std::vector<double> wrong;  // ratios of the draws whose best candidate is not z
  Eigen::VectorXd w(n), zhat(n);
  for (int k = 0; k < samples; ++k) {
    for (int i = 0; i < n; ++i) w[i] = sd[i] * normal(rng);
    zhat.noalias() = Lt.triangularView<Eigen::Upper>() * w;
    const IlsSearchResult r = searchIntegerLeastSquares(f, zhat, so);
    if (!r.complete || r.candidates.size() < 2) {
      wrong.push_back(std::numeric_limits<double>::infinity());
      continue;
    }
    if (r.candidates[0].cwiseAbs().maxCoeff() < 0.5) continue;  // the true integers
    wrong.push_back(r.squaredNorms[0] > 0.0 ? r.squaredNorms[1] / r.squaredNorms[0]
                                            : std::numeric_limits<double>::infinity());
  }
  const auto allowed = static_cast<std::size_t>(std::floor(o.maxFailureRate * samples));
  if (wrong.size() <= allowed) return 1.0;
  std::nth_element(wrong.begin(), wrong.begin() + static_cast<std::ptrdiff_t>(allowed), wrong.end(),
                   std::greater<double>());
  const double t = wrong[allowed];  // more than `allowed` wrong draws reach t: accept only above it
  return std::isfinite(t) ? std::nextafter(t, std::numeric_limits<double>::infinity()) : t;
}

namespace {

/// The critical ratio a set with factor `f` and bootstrapped success rate `ps` must reach beyond
/// the ratio threshold (FixedFailureRate; 0 for the other rules).
double criticalRatioOf(const LtdlFactor& f, double ps, const AmbiguityResolutionOptions& o) {
  if (o.validation != AmbiguityValidation::FixedFailureRate) return 0.0;
  if (ps >= 1.0 - o.maxFailureRate) return 1.0;
  if (f.d.size() > o.ffrtMaxDimension) return std::numeric_limits<double>::infinity();
  return fixedFailureRateCriticalRatio(f, o);
}

}  // namespace

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
  const bool reduced = full.reduction.factor.d.size() == n;
  // The simulation runs only for a set whose ratio passes the threshold (it could not pass else).
  fix.criticalRatio = o.ratioThreshold;
  if (reduced && full.ratio >= o.ratioThreshold)
    fix.criticalRatio = std::max(o.ratioThreshold, criticalRatioOf(full.reduction.factor, full.successRate, o));
  if (full.ok && passesValidation(full.ratio, full.successRate, o, fix.criticalRatio)) {
    fix.fixed = true;
    fix.T = Eigen::MatrixXd::Identity(n, n);
    fix.values = full.fixed[0];
    fix.fullSolution = full.fixed[0];
    fix.bestNorm = full.squaredNorms[0];
    return fix;
  }
  if (!o.partial || !reduced) return fix;

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
    const double critical = ratio >= o.ratioThreshold ? criticalRatioOf(sub, ps, o) : 0.0;
    if (!passesValidation(ratio, ps, o, critical)) continue;
    fix.fixed = true;
    fix.partial = true;
    fix.T = full.reduction.Z.rightCols(m).transpose();  // z_sub = T a
    fix.values = s.candidates[0] + fix.T * shift;
    fix.ratio = ratio;
    fix.successRate = ps;
    fix.criticalRatio = std::max(o.ratioThreshold, critical);
    fix.bestNorm = s.squaredNorms[0];
    return fix;
  }
  return fix;
}

}  // namespace gvins
