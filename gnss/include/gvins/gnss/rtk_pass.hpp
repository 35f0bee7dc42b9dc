// One post-processing pass of an RtkSolver over buffered rover and base epochs, forward or
// backward in time: the pass of gvins-rtk's combined mode (rtk_combination.hpp) and of tests.
#pragma once

#include <cstddef>
#include <functional>
#include <vector>

#include "gvins/base/observation.hpp"
#include "gvins/gnss/rtk.hpp"
#include "gvins/gnss/time_direction.hpp"

namespace gvins {

/// Called after each rover epoch of a pass: epochs done, epochs in all, the epoch's solution.
using RtkPassProgress = std::function<void(std::size_t done, std::size_t total, const RtkSolution& sol)>;

/// Runs `solver` over `rover` (epochs in increasing time) in `direction`, feeding it the `base`
/// epochs (increasing time) in the same direction: before each rover epoch every base epoch up to
/// it and the first one past it (for interpolation), in processing order, as a real-time feed
/// would. Sets the solver's time direction first (which clears its state). Returns the solutions
/// in increasing time order (one per rover epoch, forward or backward).
std::vector<RtkSolution> runRtkPass(RtkSolver& solver, const std::vector<ObsEpoch>& rover,
                                    const std::vector<ObsEpoch>& base, TimeDirection direction,
                                    const RtkPassProgress& progress = {});

}  // namespace gvins
