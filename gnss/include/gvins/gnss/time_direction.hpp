// Direction in which a stream of epochs is processed: forward (increasing time, real time and the
// forward pass of post-processing) or backward (decreasing time, the backward pass of the
// combined forward + backward solution, rtk_combination.hpp).
//
// Every component that keeps history across epochs (BaseStation, CycleSlipDetector,
// DopplerConsistency, RtkSolver) orders epochs, measures gaps and ages and sizes process noise with
// `elapsed`: the seconds from one epoch to a later one in processing order, positive in either
// direction. Rates and predictions (phase change from the Doppler, position change from the
// velocity) use the signed real time difference, which is the same physics both ways.
#pragma once

#include <cstdint>

#include "gvins/base/gnss_time.hpp"

namespace gvins {

enum class TimeDirection : std::int8_t { Forward = 1, Backward = -1 };

/// Seconds from `from` to `to` in processing order (positive when `to` is processed after `from`).
inline double elapsed(TimeDirection d, const GpsTime& to, const GpsTime& from) {
  return d == TimeDirection::Forward ? to - from : from - to;
}

inline const char* toString(TimeDirection d) { return d == TimeDirection::Forward ? "forward" : "backward"; }

}  // namespace gvins
