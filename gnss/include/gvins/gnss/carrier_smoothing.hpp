// Carrier-smoothed pseudoranges (Hatch filter): the code is averaged over a window while the
// carrier phase, which is millimetre-precise but ambiguous, carries the range change between
// epochs (Hatch 1982, "The synergism of GPS code and carrier measurements", 3rd Int. Geodetic
// Symposium on Satellite Doppler Positioning; RTCA DO-229E 2.1.4.1.1 uses a 100 s window):
//
//   P̂_k = w P_k + (1 − w) (P̂_{k−1} + λ(φ_k − φ_{k−1})),   w = max(1/n, Δt/T),
//
// n the number of epochs since the arc start and T the window. White code noise drops by
// sqrt(2T/Δt − 1) in steady state, multipath with a correlation time τ ≪ T by about sqrt(T/2τ).
//
// All code signals of a satellite are smoothed over the same arc (every signal restarts when one
// of them does), so that an ionosphere-free combination of smoothed codes equals the smoothed
// ionosphere-free code: the ionospheric code-carrier divergence, 2 dI/dt per band, cancels in the
// combination exactly. A single-frequency smoothed code keeps a lag error of about 2 T dI/dt
// (DO-229E: hence the 100 s window there).
//
// An arc restarts on a cycle slip of any of the satellite's phases (CycleSlipDetector: LLI, gap,
// geometry-free and Doppler tests), when its set of signals changes, and when a code departs from
// the carrier-predicted smoothed value by more than `maxCodeCarrierJump` (an undetected slip or a
// code outlier such as a multipath jump). A code without its own phase is carried by the best
// phase on its band (GPS C1W by L1C); satellites with a code on a band without any phase (or
// without a known wavelength, GLONASS without its channel) keep their raw codes.
#pragma once

#include <cstdint>
#include <vector>

#include "gvins/base/observation.hpp"
#include "gvins/gnss/cycle_slip_detector.hpp"

namespace gvins {

struct CarrierSmoothingOptions {
  double window = 100.0;              ///< s (T above); the smoothing time constant
  double maxCodeCarrierJump = 20.0;   ///< m; a larger code-minus-prediction restarts the arc
  CycleSlipOptions slips;             ///< arc breaks (maxGap there bounds the gap between epochs)
};

/// Counts over all processed epochs, per satellite and epoch.
struct CarrierSmoothingCounts {
  std::int64_t smoothed = 0;    ///< satellite epochs whose codes were replaced (n ≥ 2)
  std::int64_t raw = 0;         ///< satellite epochs left raw (no phase, arc start)
  std::int64_t slipRestarts = 0;   ///< arcs restarted by a cycle slip flag
  std::int64_t jumpRestarts = 0;   ///< arcs restarted by the code-carrier test
  std::int64_t signalRestarts = 0; ///< arcs restarted because the set of signals changed
};

class CarrierSmoother {
 public:
  explicit CarrierSmoother(CarrierSmoothingOptions options = {});

  /// Replaces the pseudoranges of `epoch` (epochs in increasing time) by carrier-smoothed ones,
  /// in place; phases, Dopplers and C/N0 are unchanged. GLONASS phases need the FDMA channels.
  void apply(ObsEpoch& epoch, const GlonassChannels& channels = {});

  /// Epochs in the satellite's current arc at the last applied epoch (1 = raw code; 0 = not seen).
  int samples(SatId sat) const;
  /// Seconds from the arc start to the last applied epoch (0 for a raw code).
  double arcLength(SatId sat) const;
  /// Standard deviation of the smoothed code's white noise relative to the raw code's, for a
  /// satellite at the last applied epoch: sqrt(w/(2 − w)) in steady state, 1/sqrt(n) while the
  /// arc is shorter than the window (1 when raw).
  double noiseFactor(SatId sat) const;

  void reset();
  const CarrierSmoothingCounts& counts() const { return counts_; }
  const CarrierSmoothingOptions& options() const { return options_; }

 private:
  struct Signal {
    ObsCode code;
    double smoothed = 0.0;  // m; in work_ (this epoch's inputs): the raw code
    double phase = 0.0;     // m (λ φ of the carrying phase)
  };
  struct Arc {
    std::vector<Signal> signals;
    int n = 0;  // epochs in the arc, 0 = none
    double weight = 1.0;  // w of the last epoch
    GpsTime start;
    GpsTime last;
  };
  CarrierSmoothingOptions options_;
  CycleSlipDetector slips_;
  std::vector<Arc> arcs_;  // by satIndex
  GpsTime lastEpoch_;
  CarrierSmoothingCounts counts_;
  std::vector<Signal> work_;
};

}  // namespace gvins
