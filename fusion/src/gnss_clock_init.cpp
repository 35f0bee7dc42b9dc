#include "gvins/fusion/gnss_clock_init.hpp"

#include <cmath>
#include <random>

namespace gvins::fusion {

ClockInitResult initializeClocksRansac(std::span<const ClockRow> rows, int numUnknowns, int iterations,
                                       int minInliers, std::uint64_t seed) {
  ClockInitResult out;
  const std::size_t n = static_cast<std::size_t>(numUnknowns);
  out.x.assign(n, 0.0);
  out.sigma.assign(n, 0.0);
  out.inliers.assign(n, 0);
  out.inlier.assign(rows.size(), false);
  std::vector<std::vector<std::size_t>> byUnknown(n);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const int u = rows[i].unknown;
    if (u >= 0 && u < numUnknowns) byUnknown[static_cast<std::size_t>(u)].push_back(i);
  }
  std::mt19937_64 rng(seed);
  // A X = b is block diagonal (every row observes one unknown), so the consensus of a minimal
  // sample (one row per unknown) is the sum of per-unknown consensus sets: the best hypothesis is
  // found per unknown with the same number of samples.
  out.ok = true;
  for (std::size_t u = 0; u < n; ++u) {
    const auto& idx = byUnknown[u];
    if (idx.empty()) {
      out.ok = false;
      continue;
    }
    std::vector<bool> best;
    int bestCount = -1;
    double bestSpread = 0.0;
    const int iters = std::min<int>(iterations, static_cast<int>(idx.size()) * 4);
    std::uniform_int_distribution<std::size_t> pick(0, idx.size() - 1);
    for (int it = 0; it < std::max(iters, 1); ++it) {
      // Without replacement while the set is small: every row is tried once first.
      const std::size_t s = it < static_cast<int>(idx.size()) ? static_cast<std::size_t>(it) : pick(rng);
      const double hyp = rows[idx[s]].value;
      std::vector<bool> in(idx.size(), false);
      int count = 0;
      double spread = 0.0;
      for (std::size_t j = 0; j < idx.size(); ++j) {
        const double d = std::abs(rows[idx[j]].value - hyp);
        if (d <= rows[idx[j]].threshold) {
          in[j] = true;
          ++count;
          spread += d * d;
        }
      }
      if (count > bestCount || (count == bestCount && spread < bestSpread)) {
        bestCount = count;
        bestSpread = spread;
        best = in;
      }
    }
    // Least squares on the consensus set (unit weights: the mean), then one re-selection.
    double sum = 0.0;
    int m = 0;
    for (std::size_t j = 0; j < idx.size(); ++j) {
      if (best[j]) {
        sum += rows[idx[j]].value;
        ++m;
      }
    }
    double mean = sum / m;
    sum = 0.0;
    m = 0;
    for (std::size_t j = 0; j < idx.size(); ++j) {
      best[j] = std::abs(rows[idx[j]].value - mean) <= rows[idx[j]].threshold;
      if (best[j]) {
        sum += rows[idx[j]].value;
        ++m;
      }
    }
    if (m == 0) {
      out.ok = false;
      continue;
    }
    mean = sum / m;
    double ss = 0.0;
    for (std::size_t j = 0; j < idx.size(); ++j) {
      if (best[j]) ss += std::pow(rows[idx[j]].value - mean, 2);
      out.inlier[idx[j]] = best[j];
    }
    out.x[u] = mean;
    out.sigma[u] = m > 1 ? std::sqrt(ss / (m - 1) / m) : rows[idx[0]].threshold;
    out.inliers[u] = m;
    if (m < minInliers) out.ok = false;
  }
  return out;
}

}  // namespace gvins::fusion
