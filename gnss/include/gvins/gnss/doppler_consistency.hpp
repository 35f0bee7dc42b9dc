// Doppler sanity per receiver and signal: checks the Doppler of each signal (system + RINEX code)
// of one receiver stream against its carrier-phase rate (or, for a signal without phase, its
// pseudorange rate) and corrects or drops it before any user sees it.
//
// RINEX convention (RINEX 3.04, section 3 "Basic definitions", Doppler: the Doppler shift is
// positive for an approaching satellite; phase has the sign of the range): the range rate is −λ·D, so between two epochs the phase change is ΔL ≈ −(D₀ + D₁)/2·Δt cycles (phase
// grows with the range). Some receivers break it (e.g. a u-blox M8P's RTCM MSM7 Doppler has the
// opposite sign to its phase rate); a user of such a Doppler gets km/s velocities and Doppler
// "cycle slips" on every epoch.
//
// Per signal, every continuous arc interval (both epochs with Doppler and phase, no loss of lock,
// no gap longer than maxGap) gives, in m/s with v_D = −λ(D₀ + D₁)/2 and v_L = λ·ΔL/Δt:
//   r_consistent = v_D − v_L,  r_flipped = v_D + v_L,  and the ratio v_D / v_L.
// The receiver clock drift is in both v_D and v_L alike (one oscillator drives the carrier
// tracking and the phase count), so it cancels in r_consistent and, for a flipped Doppler, in
// r_flipped; what remains is noise and the trapezoid error of the Doppler integral
// (Δt²/12 times the range jerk). Signals without phase use v_P = ΔP/Δt with a looser tolerance.
// Residuals are divided by their tolerance; the verdict comes from medians over all samples of
// the signal (several satellites, a few epochs), so cycle slips and receiver clock jumps that
// reach the phase or code but not the Doppler (single intervals of a few satellites or epochs)
// cannot move it:
//   - Consistent:   median |r_consistent| ≤ 1 and median |r_flipped| > 3 — Doppler kept;
//   - SignFlipped:  median |r_flipped| ≤ 1 and median |r_consistent| > 3 — Doppler negated;
//   - Scaled:       both > 3, but v_D = k·v_L within tolerance for the median ratio k (a wrong
//                   wavelength or unit) — Doppler dropped;
//   - Inconsistent: both > 3 otherwise — Doppler dropped.
// While neither hypothesis is clearly rejected (small range rates) the signal stays undecided;
// after maxPendingIntervals it takes the better one within tolerance (geostationary satellites:
// their range rates stay small, and so does the error of a wrong choice), else Inconsistent.
// Until a signal is decided its Doppler is withheld (absent), so no user ever sees an unchecked
// value; a verdict is final for the stream. Each verdict other than Consistent produces one
// warning naming the receiver label and the signal (e.g. "rover: Doppler sign flipped on G L1C
// (corrected)").
#pragma once

#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "gvins/base/observation.hpp"
#include "gvins/gnss/time_direction.hpp"

namespace gvins {

enum class DopplerVerdict : std::uint8_t { Pending, Consistent, SignFlipped, Scaled, Inconsistent };
const char* toString(DopplerVerdict v);

struct DopplerConsistencyOptions {
  bool enabled = true;             ///< false: every Doppler passes unchecked
  int minSamples = 12;             ///< arc intervals needed for a verdict
  int minSatellites = 3;           ///< distinct satellites among them ...
  int minIntervals = 3;            ///< ... over at least this many epoch intervals (one
                                   ///< interval with a receiver clock jump stays a minority)
  int patientIntervals = 10;       ///< after this many intervals minSatellites is waived
  int maxPendingIntervals = 60;    ///< still undecided after this many: the better-fitting
                                   ///< hypothesis within tolerance, else inconsistent
  double maxGap = 60.0;            ///< s, longest interval used
  double phaseTolerance = 0.5;     ///< m/s, |v_D − v_L| allowed (noise, Doppler time tag)
  double dopplerJerk = 1.0;        ///< m/s³, range jerk allowance: + jerk·Δt²/12
  double codeSigma = 3.0;          ///< m, pseudorange noise: code tolerance 2√2·σ/Δt + phaseTolerance
  double scaleTolerance = 0.01;    ///< |k − 1| and |k + 1| above this count as a scale error
};

/// What was decided about one signal.
struct DopplerSignalReport {
  System system = System::Gps;
  ObsCode code;
  DopplerVerdict verdict = DopplerVerdict::Pending;
  bool fromPhase = true;        ///< most samples against the phase rate (else the pseudorange rate)
  int samples = 0;              ///< arc intervals the verdict used
  int satellites = 0;
  double medianConsistent = 0.0;  ///< m/s, median |v_D − v_L|
  double medianFlipped = 0.0;     ///< m/s, median |v_D + v_L|
  double factor = 1.0;            ///< median v_D / v_L (Scaled)
  /// "G L1C": system letter and the signal's RINEX band/attribute.
  std::string name() const;
};

struct DopplerConsistencyCounts {
  std::int64_t epochs = 0;
  std::int64_t passed = 0;     ///< Doppler values passed unchanged
  std::int64_t corrected = 0;  ///< negated (sign flip)
  std::int64_t dropped = 0;    ///< removed (scaled / inconsistent)
  std::int64_t withheld = 0;   ///< removed while their signal was undecided
};

class DopplerConsistency {
 public:
  /// `label` names the receiver in warnings ("rover", "base", a station name).
  explicit DopplerConsistency(std::string label = "rover", DopplerConsistencyOptions options = {});

  /// Order of the epochs given to apply() (default forward). Backward, intervals are measured in
  /// processing order, rates with the signed time difference, and the loss of lock of the epoch
  /// processed before (later in time) breaks the interval. Set before the first epoch.
  void setDirection(TimeDirection d) { direction_ = d; }
  /// Takes one epoch of the stream (increasing time, or decreasing backward; an epoch with the time of the previous one
  /// is only corrected again, not sampled twice) and corrects it in place: Dopplers of
  /// consistent signals pass, flipped ones are negated, others are removed (present bit cleared,
  /// value zero). GLONASS FDMA wavelengths use the channels when known (channel 0 otherwise:
  /// < 0.3 % off, irrelevant to the verdict).
  void apply(ObsEpoch& epoch, const GlonassChannels& channels = {});

  /// Verdict of a signal (Pending if it was never seen or is undecided).
  DopplerVerdict verdict(System sys, ObsCode code) const;
  /// Every signal seen with Doppler, decided or not, in order of first appearance.
  std::vector<DopplerSignalReport> signals() const;
  /// One line per signal that was not judged consistent, in order of decision. A caller prints
  /// the new ones after each epoch (index from the previous size).
  const std::vector<std::string>& warnings() const { return warnings_; }
  /// Summary lines of the non-consistent and undecided signals ("rover: G L1C sign flipped
  /// (corrected), 24 samples ..."), empty when every Doppler was consistent or absent.
  std::vector<std::string> summary() const;
  const DopplerConsistencyCounts& counts() const { return counts_; }
  /// "N passed, N corrected, N dropped, N withheld (undecided)" for a tool's summary.
  std::string countsText() const;
  const std::string& label() const { return label_; }
  const DopplerConsistencyOptions& options() const { return options_; }

 private:
  struct Sample {
    double consistent;  // |r_consistent| / tolerance
    double flipped;     // |r_flipped| / tolerance
    double vd, vl;      // m/s
    double tolerance;   // m/s
    bool phase;         // against the phase rate (else the pseudorange rate)
  };
  struct SignalState {
    DopplerSignalReport report;
    std::vector<Sample> samples;
    std::vector<int> satellites;  // satIndex of the samples' satellites (distinct)
    int intervals = 0;
    std::optional<GpsTime> lastInterval;
  };
  struct Track {  // last values of one satellite signal
    ObsCode code;
    GpsTime time;
    bool hasPhase = false, hasCode = false;
    double phase = 0.0, pseudorange = 0.0, doppler = 0.0;
    bool lossOfLock = false;
  };
  SignalState& state(System sys, ObsCode code);
  void sample(const ObsEpoch& epoch, const GlonassChannels& channels);
  void decide(SignalState& s);
  void warn(const DopplerSignalReport& r);

  std::string label_;
  DopplerConsistencyOptions options_;
  std::deque<SignalState> states_;  // a deque: references stay valid as signals are added
  std::vector<std::vector<Track>> tracks_;    // by satIndex
  std::vector<std::string> warnings_;
  std::optional<GpsTime> lastEpoch_;
  TimeDirection direction_ = TimeDirection::Forward;
  DopplerConsistencyCounts counts_;
};

}  // namespace gvins
