// Lock time indicators of RTCM 3 and their conversion to loss-of-lock flags.
//
// Each indicator value i stands for an interval of continuous-lock time [min(i), max(i)); the
// tables are RTCM 10403.3 table 3.4-2 (DF013/DF019/DF043/DF049, 7 bits, seconds), table 3.5-74
// (DF402, MSM1-5, 4 bits) and table 3.5-75 (DF407, MSM6-7, 10 bits).
#pragma once

#include <cstdint>

namespace gvins::rtcm {

enum class LockTimeKind : std::uint8_t {
  Legacy,  ///< DF013 etc., 7 bits
  Msm,     ///< DF402, 4 bits
  MsmExt,  ///< DF407, 10 bits
};

/// Lower bound of the lock time, in milliseconds, that an indicator value stands for.
std::int64_t lockTimeMinMs(LockTimeKind kind, int indicator);
/// Exclusive upper bound in milliseconds; a very large number for the open-ended top value.
std::int64_t lockTimeMaxMs(LockTimeKind kind, int indicator);
/// Indicator value for a lock time in milliseconds (the inverse; the largest value whose lower
/// bound does not exceed `ms`).
int lockTimeIndicator(LockTimeKind kind, std::int64_t ms);

/// Decides whether lock was lost between two observations of the same signal, from the lock time
/// bounds [min, max) of the previous and current indicators (which may be of different kinds).
/// Lock time only grows while a receiver keeps lock, so a smaller lower bound than last time
/// means the lock restarted; so does an upper bound no larger than the time since the last
/// observation `dtMs`. (Tighter tests such as currentMax <= previousMin + dt would also flag
/// receivers whose lock-time counters are sampled a little off the epoch, so they are not used.)
bool lockLost(std::int64_t previousMinMs, std::int64_t currentMinMs, std::int64_t currentMaxMs,
              std::int64_t dtMs);

}  // namespace gvins::rtcm
