#include "gvins/gnss/rtk_pass.hpp"

#include <algorithm>

#include "gvins/gnss/base_station.hpp"

namespace gvins {

std::vector<RtkSolution> runRtkPass(RtkSolver& solver, const std::vector<ObsEpoch>& rover,
                                    const std::vector<ObsEpoch>& base, TimeDirection direction,
                                    const RtkPassProgress& progress) {
  solver.setTimeDirection(direction);
  const bool fwd = direction == TimeDirection::Forward;
  const std::size_t n = rover.size(), nb = base.size();
  std::vector<RtkSolution> out(n);
  std::size_t nextBase = 0;  // base epochs fed so far, in processing order
  auto baseAt = [&](std::size_t j) -> const ObsEpoch& { return base[fwd ? j : nb - 1 - j]; };
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t i = fwd ? k : n - 1 - k;
    const ObsEpoch& r = rover[i];
    // Base epochs up to the rover time and the first one after it (in processing order).
    while (nextBase < nb &&
           !(nextBase > 0 && elapsed(direction, baseAt(nextBase - 1).time, r.time) > BaseStation::kSyncTolerance)) {
      solver.addBaseEpoch(baseAt(nextBase++));
    }
    out[i] = solver.process(r);
    if (progress) progress(k + 1, n, out[i]);
  }
  return out;
}

}  // namespace gvins
