#include "gvins/gnss/fault_exclusion.hpp"

#include <algorithm>
#include <limits>

#include "gvins/sri/chi_square.hpp"

namespace gvins {

double globalTestThreshold(int dof, double pfa) {
  if (dof < 1) return 0.0;
  if (!(pfa > 0.0 && pfa < 1.0)) return std::numeric_limits<double>::infinity();  // no test
  // The common case repeats the same pfa: each quantile is computed once per dof.
  static thread_local sri::ChiSquareQuantiles quantiles;
  return quantiles(1.0 - pfa, dof);
}

FaultExclusionResult detectAndExclude(std::vector<char>& use,
                                      const std::function<SubsetFit(const std::vector<char>&)>& fit,
                                      const FaultExclusionOptions& opt) {
  FaultExclusionResult res;
  res.fit = fit(use);
  ++res.fits;
  auto passes = [&](const SubsetFit& f) {
    return f.ok && (f.dof < 1 || f.chi2 <= globalTestThreshold(f.dof, opt.falseAlarmProbability));
  };
  res.testPassed = passes(res.fit);
  if (!opt.enabled) return res;
  while (!res.testPassed && res.fit.ok && static_cast<int>(res.excluded.size()) < opt.maxExclusions &&
         res.fit.dof - 1 >= opt.minRedundancy) {
    // Candidates: measurements in use, largest normalised residual first.
    std::vector<int> cand;
    for (int i = 0; i < static_cast<int>(use.size()); ++i) {
      if (use[i]) cand.push_back(i);
    }
    const auto& nr = res.fit.normalizedResidual;
    if (nr.size() == use.size()) {
      std::sort(cand.begin(), cand.end(), [&](int a, int b) { return nr[a] > nr[b]; });
    }
    if (opt.maxCandidates > 0 && static_cast<int>(cand.size()) > opt.maxCandidates) cand.resize(opt.maxCandidates);
    int best = -1;
    double bestRatio = 0.0;
    SubsetFit bestFit;
    for (int i : cand) {
      use[i] = 0;
      SubsetFit f = fit(use);
      ++res.fits;
      use[i] = 1;
      if (!f.ok || f.dof < 1) continue;
      const double ratio = f.chi2 / globalTestThreshold(f.dof, opt.falseAlarmProbability);
      if (best < 0 || ratio < bestRatio) {
        best = i;
        bestRatio = ratio;
        bestFit = std::move(f);
      }
    }
    if (best < 0) break;
    use[best] = 0;
    res.excluded.push_back(best);
    res.fit = std::move(bestFit);
    res.testPassed = passes(res.fit);
  }
  return res;
}

}  // namespace gvins
