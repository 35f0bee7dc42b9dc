// Receiver clock jumps of whole milliseconds, found and removed from one receiver's stream before
// any user sees it.
//
// Receivers that let their clock run free keep it within a millisecond of GPS time by jumping it
// by ±1 ms (u-blox, several geodetic receivers): every pseudorange of the epoch then moves by
// c·1 ms = 299 792.458 m, and the carrier phases too or not, depending on the receiver. A
// snapshot solution (SPP) absorbs the jump in its clock estimate; a filter that carries the
// receiver clock from epoch to epoch (the fusion's clock state, carrier smoothing, phase arcs)
// sees every row 300 km off and rejects them all until it starts over.
//
// Detection needs neither Doppler (whose sign convention may be wrong) nor the position: per
// signal, the second difference of the pseudorange (and of the phase, in metres) over three
// consecutive epochs, x = P₂ − P₁ − (P₁ − P₀)·Δt₂/Δt₁, is the range acceleration times Δt² (below
// a metre for Δt ≤ 10 s), noise, and the change of the common clock term: a jump shows as
// x ≈ k·c·1 ms on every satellite. When the median of x over the epoch is within `tolerance` of
// k·c·1 ms for an integer k ≠ 0 and at least minSatellites signals agree within tolerance, the
// jump is recorded, the accumulated offset is removed from this and every later epoch (codes
// and phases each by their own offset: P − n·c·1 ms, Φ − n·c·1 ms/λ) and one warning names it
// ("rover: receiver clock jump of +1 ms in the pseudoranges at 2381 581852.250 (corrected)").
// The removal keeps the stream continuous; the clock a user estimates is then the receiver
// clock minus the removed milliseconds, which no position or velocity depends on.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include "gvins/base/gnss_time.hpp"
#include "gvins/base/observation.hpp"

namespace gvins {

struct ClockJumpOptions {
  bool enabled = true;
  int minSatellites = 3;    ///< signals that must agree on the jump
  double maxGap = 10.0;     ///< s, longest epoch interval used
  double tolerance = 100.0; ///< m, |x − k·c·1 ms| accepted (noise, range acceleration, multipath)
};

class ClockJumpRepair {
 public:
  /// `label` names the receiver in warnings.
  explicit ClockJumpRepair(std::string label = "rover", ClockJumpOptions options = {});

  /// Takes one epoch (increasing time) and removes the accumulated jumps in place.
  void apply(ObsEpoch& epoch, const GlonassChannels& channels = {});

  /// One line per jump found, in order.
  const std::vector<std::string>& warnings() const { return warnings_; }
  /// Milliseconds removed so far from the pseudoranges and from the carrier phases.
  std::int64_t codeOffsetMs() const { return codeMs_; }
  std::int64_t phaseOffsetMs() const { return phaseMs_; }
  int jumps() const { return jumps_; }

 private:
  struct History {  // the last two corrected values (m) of one signal
    GpsTime t[2];
    double v[2] = {0.0, 0.0};
    int n = 0;
  };
  using Key = std::tuple<int, int, char, char>;  // system, prn, band, attribute
  // The jump (integer ms) shown by the samples' second differences, or 0.
  std::int64_t detect(std::vector<double>& samples) const;
  void warn(const char* what, std::int64_t ms, const GpsTime& t);

  std::string label_;
  ClockJumpOptions options_;
  std::map<Key, History> code_, phase_;
  std::int64_t codeMs_ = 0, phaseMs_ = 0;
  int jumps_ = 0;
  std::vector<std::string> warnings_;
};

}  // namespace gvins
