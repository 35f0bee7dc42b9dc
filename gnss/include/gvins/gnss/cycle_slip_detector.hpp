// Cycle-slip detection on the carrier phases of one receiver, epoch by epoch.
//
// Tests per phase signal (satellite + RINEX code):
//   - loss-of-lock indicator (RINEX LLI bit 0, or the lock-time indicator an RTCM decoder turned
//     into it);
//   - data gap: a phase not seen for longer than `maxGap` starts a new arc;
//   - geometry-free combination GF = λ_a φ_a − λ_b φ_b (m) between the signal and the satellite's
//     first phase signal: geometry, clocks and troposphere cancel, only the slowly changing
//     ionosphere and the ambiguities remain, so a jump larger than `geometryFreeThreshold` +
//     `geometryFreeRate`·Δt is a slip on one of the two (both are flagged; e.g. Blewitt 1990,
//     "An automatic editing algorithm for GPS data", GRL 17(3));
//   - Doppler versus phase: the phase change over the interval must equal −(D₀ + D₁)/2·Δt (the
//     trapezoid integral of the Doppler, RINEX sign convention). The difference, in metres, has the
//     receiver clock jump/drift change in common to all signals, which is removed with the median
//     of the epoch; a remainder above `dopplerThreshold` + `dopplerJerk`·Δt³/12 (the trapezoid
//     error of a range with that third derivative) is a slip.
// Epochs may come backward in time (setDirection): gaps and allowances then use the elapsed time
// in processing order, the Doppler prediction the signed time difference, and a loss-of-lock
// indicator, which marks a slip between the flagged epoch and the one before it in time, flags the
// next epoch processed (the one before it in time) instead of its own.
// A half-cycle flag (LLI bit 1) is reported separately: such a phase may still be used, but its
// ambiguity must not be fixed to an integer.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "gvins/base/observation.hpp"
#include "gvins/gnss/time_direction.hpp"

namespace gvins {

/// Why a phase was flagged (bit set).
enum SlipFlag : std::uint8_t {
  kSlipNone = 0,
  kSlipNewArc = 1,        ///< first observation of the signal (or after reset())
  kSlipLli = 2,           ///< loss-of-lock indicator
  kSlipGap = 4,           ///< not observed for longer than maxGap
  kSlipGeometryFree = 8,  ///< geometry-free jump
  kSlipDoppler = 16,      ///< Doppler-phase disagreement
  kSlipHalfCycle = 32,    ///< half-cycle ambiguity unresolved (not a slip; no integer fixing)
};
/// Flags that mean the ambiguity must be reset.
inline constexpr std::uint8_t kSlipResetMask = kSlipNewArc | kSlipLli | kSlipGap | kSlipGeometryFree | kSlipDoppler;

struct CycleSlipOptions {
  bool useLli = true;
  double maxGap = 60.0;                  ///< s
  bool geometryFree = true;
  double geometryFreeThreshold = 0.05;   ///< m
  double geometryFreeRate = 0.0005;      ///< m/s (ionosphere change allowance)
  bool doppler = true;
  double dopplerThreshold = 0.6;         ///< m
  double dopplerJerk = 1.0;              ///< m/s³, allowance for receiver dynamics
};

/// Counts of flagged phase signals by test (a signal can count under several).
struct CycleSlipCounts {
  std::int64_t checked = 0;
  std::int64_t newArcs = 0;
  std::int64_t lli = 0;
  std::int64_t gaps = 0;
  std::int64_t geometryFree = 0;
  std::int64_t doppler = 0;
  std::int64_t halfCycle = 0;
};

class CycleSlipDetector {
 public:
  explicit CycleSlipDetector(CycleSlipOptions options = {});

  /// Order of the epochs given to process() (default forward); set before the first epoch (it
  /// forgets the history).
  void setDirection(TimeDirection d);
  TimeDirection direction() const { return direction_; }
  /// Tests every phase signal of the epoch (epochs in increasing time, or decreasing when the
  /// direction is backward). GLONASS wavelengths need
  /// the FDMA channels; GLONASS signals without a channel are only checked by LLI and gaps.
  void process(const ObsEpoch& epoch, const GlonassChannels& channels = {});
  /// Flags of a signal in the last processed epoch (kSlipNone if it was not in that epoch).
  std::uint8_t flags(SatId sat, ObsCode code) const;
  /// Start of the signal's current continuous arc (the epoch of its last reset flag): an
  /// ambiguity estimated since then is still valid. nullopt if the signal was never seen.
  std::optional<GpsTime> arcStart(SatId sat, ObsCode code) const;
  /// Forgets all history (every signal starts a new arc).
  void reset();
  /// Forces a new arc for one signal (e.g. after the caller rejected its ambiguity).
  void restart(SatId sat, ObsCode code);

  const CycleSlipCounts& counts() const { return counts_; }
  const CycleSlipOptions& options() const { return options_; }

 private:
  struct Track {
    ObsCode code;
    bool valid = false;
    GpsTime last;
    double phase = 0.0;   // cycles
    double doppler = 0.0;  // Hz
    bool hasDoppler = false;
    double gf = 0.0;       // m, against gfRef
    ObsCode gfRef;
    bool hasGf = false;
    std::uint8_t flags = 0;
    bool lliPending = false;  // backward: the last epoch's loss of lock, for the next one processed
    GpsTime flagsTime;
    GpsTime arcStart;
  };
  Track* find(SatId sat, ObsCode code);
  const Track* find(SatId sat, ObsCode code) const;

  CycleSlipOptions options_;
  TimeDirection direction_ = TimeDirection::Forward;
  std::vector<std::vector<Track>> tracks_;  // by satIndex
  CycleSlipCounts counts_;
  GpsTime lastEpoch_;
  // Work space of process().
  struct Pending {
    Track* track;
    double wavelength;
    double dopplerResidual;  // m, NaN if not testable
  };
  std::vector<Pending> pending_;
  std::vector<double> work_;
};

}  // namespace gvins
