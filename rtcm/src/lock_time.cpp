#include "gvins/rtcm/lock_time.hpp"

#include <algorithm>

namespace gvins::rtcm {
namespace {

constexpr std::int64_t kOpenEnded = std::int64_t{1} << 50;

// RTCM 10403.3 table 3.4-2 (seconds): i for 0-23, 2i-24 for 24-47, 4i-120 for 48-71,
// 8i-408 for 72-95, 16i-1176 for 96-119, 32i-3096 for 120-126, 127 means >= 937 s.
std::int64_t legacyMinS(int i) {
  if (i < 24) return i;
  if (i < 48) return 2 * i - 24;
  if (i < 72) return 4 * i - 120;
  if (i < 96) return 8 * i - 408;
  if (i < 120) return 16 * i - 1176;
  if (i < 127) return 32 * i - 3096;
  return 937;
}

// RTCM 10403.3 table 3.5-75 (milliseconds): in 32-value blocks from 64 on, block b (b = 0 for
// 64-95) has step 2^(b+1) ms and offset so that the table is continuous: 2i-64, 4i-256, 8i-768,
// ..., 2^21 i - 671088640 for 672-703; 704 means >= 67108864 ms; 705-1023 reserved.
std::int64_t extMinMs(int i) {
  if (i < 64) return i;
  if (i >= 704) return 67108864;
  const int block = (i - 64) / 32;       // 0..19
  const std::int64_t step = std::int64_t{2} << block;
  const int first = 64 + 32 * block;     // first indicator of the block
  // Value at the start of the block: 64 * 2^block ms (continuity with the previous block).
  const std::int64_t start = std::int64_t{64} << block;
  return start + step * (i - first);
}

}  // namespace

std::int64_t lockTimeMinMs(LockTimeKind kind, int i) {
  switch (kind) {
    case LockTimeKind::Legacy: return 1000 * legacyMinS(std::clamp(i, 0, 127));
    case LockTimeKind::Msm:
      // Table 3.5-74: 0 means < 32 ms, i = 1..15 means >= 2^(i+4) ms.
      i = std::clamp(i, 0, 15);
      return i == 0 ? 0 : std::int64_t{1} << (i + 4);
    case LockTimeKind::MsmExt: return extMinMs(std::clamp(i, 0, 1023));
  }
  return 0;
}

std::int64_t lockTimeMaxMs(LockTimeKind kind, int i) {
  switch (kind) {
    case LockTimeKind::Legacy: return i >= 127 ? kOpenEnded : lockTimeMinMs(kind, i + 1);
    case LockTimeKind::Msm: return i >= 15 ? kOpenEnded : lockTimeMinMs(kind, i + 1);
    case LockTimeKind::MsmExt: return i >= 704 ? kOpenEnded : lockTimeMinMs(kind, i + 1);
  }
  return kOpenEnded;
}

int lockTimeIndicator(LockTimeKind kind, std::int64_t ms) {
  const int top = kind == LockTimeKind::Legacy ? 127 : kind == LockTimeKind::Msm ? 15 : 704;
  // Binary search for the largest i with min(i) <= ms (min is non-decreasing in i).
  int lo = 0, hi = top;
  while (lo < hi) {
    const int mid = (lo + hi + 1) / 2;
    if (lockTimeMinMs(kind, mid) <= ms) lo = mid;
    else hi = mid - 1;
  }
  return lo;
}

bool lockLost(std::int64_t previousMinMs, std::int64_t currentMinMs, std::int64_t currentMaxMs,
              std::int64_t dtMs) {
  return currentMinMs < previousMinMs || currentMaxMs <= dtMs;
}

}  // namespace gvins::rtcm
