// Reference (base) station data for relative positioning: a short buffer of base epochs modelled
// at the known base antenna position, and their alignment to a rover epoch.
//
// Each base signal is reduced to "observed minus computed" (OMC) values at the base epoch's own
// time tag: OMC = observation − (|r_s − r_b| + Sagnac − c·dt_s + T_b), in metres, with the
// satellite state at the base signal's transmit time. What remains is c·dt_b (common to every
// signal of the epoch), the ambiguity (phase), atmosphere errors and noise: quantities that change
// slowly, so the OMC of a base epoch some seconds older than the rover epoch still differences
// well (the "age of differential"), and the OMC of two base epochs that bracket the rover epoch
// can be interpolated linearly. Because c·dt_b differs between base epochs and only cancels when
// every signal of a rover epoch uses the same base time (or the same interpolation weights), one
// alignment is chosen per rover epoch:
//   - a base epoch within `kSyncTolerance` of the rover time (synchronous data);
//   - otherwise, with interpolation enabled, the two base epochs around the rover time if they are
//     at most maxInterpolationGap apart (signals continuous across both only);
//   - otherwise the newest earlier base epoch if it is at most maxAge old (held). Held phases keep
//     changing at the rover with the satellite-specific part of their rate (ionosphere, satellite
//     clock and orbit errors: at solar maximum several mm/s on L2 for low satellites, a cycle in
//     under a minute), so with `extrapolateBase` each held phase is moved to the rover time with
//     its own rate (least-squares slope over the buffered base epochs of the same arc up to
//     maxInterpolationGap before, spanning at least kMinRateSpan), minus the median rate of all
//     signals: the common part is c·ḋt_b, which cancels in double differences, and leaving it
//     out keeps extrapolated and merely held signals consistent. Codes are held (their noise
//     dwarfs the effect).
//
// Backward processing (setDirection, the backward pass of post-processing): "earlier", "newest",
// ages and gaps are taken in processing order (time_direction.hpp), so a held epoch is the
// nearest later one in time and extrapolation uses the rates of the epochs after it.
//
// Cycle slips of the base are detected here (its own CycleSlipDetector); every signal carries the
// start of its continuous arc so that the rover side can tell when its single-difference
// ambiguity must be reset.
#pragma once

#include <array>
#include <cstdint>
#include <deque>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "gvins/base/observation.hpp"
#include "gvins/ephemeris/ephemeris_store.hpp"
#include "gvins/gnss/cycle_slip_detector.hpp"
#include "gvins/gnss/doppler_consistency.hpp"
#include "gvins/gnss/rtk_config.hpp"
#include "gvins/gnss/time_direction.hpp"

namespace gvins {

/// One signal of a modelled base epoch.
struct BaseSignal {
  SatId sat;
  ObsCode code;
  bool hasPhase = false;
  bool hasCode = false;
  double phaseOmc = 0.0;  ///< m
  double codeOmc = 0.0;   ///< m
  double wavelength = 0.0;  ///< m (0 if unknown, e.g. GLONASS without channel)
  GpsTime arcStart;       ///< start of the phase arc (base cycle-slip detector)
  std::uint8_t slipFlags = 0;
  double elevation = 0.0;  ///< rad, at the base
  double snr = 0.0;        ///< C/N0, dB-Hz (0 unknown)
};

/// Base values aligned to one rover epoch.
struct BaseSnapshot {
  GpsTime time;     ///< base time the values refer to (the rover time when interpolated)
  double age = 0.0;  ///< s, rover time minus the nearest base epoch used
  bool interpolated = false;
  bool extrapolated = false;        ///< held phases moved to the rover time (see above)
  std::vector<BaseSignal> signals;  ///< sorted by satellite, then code
  /// The signal of a satellite with this code, or nullptr.
  const BaseSignal* find(SatId sat, ObsCode code) const;
  /// Whether the satellite has any signal.
  bool has(SatId sat) const;
};

enum class BaseAvailability {
  Ok,
  NoPosition,  ///< base antenna position unknown (no header position, 1005/1006 or option)
  NoData,      ///< no base epoch yet
  TooOld,      ///< newest usable base epoch older than maxAge
};
const char* toString(BaseAvailability a);

struct BaseStationStats {
  std::int64_t epochs = 0;          ///< base epochs added
  std::int64_t outOfOrder = 0;      ///< dropped: not after the previous one in processing order
  std::int64_t noEphemeris = 0;     ///< satellite-epochs without a usable ephemeris
  std::int64_t positionChanges = 0; ///< base position changed (buffer cleared)
};

class BaseStation {
 public:
  /// Seconds within which base and rover time tags count as the same epoch.
  static constexpr double kSyncTolerance = 0.05;
  /// Shortest span of base epochs a phase rate for extrapolation is estimated from, s.
  static constexpr double kMinRateSpan = 5.0;
  /// Most base epochs buffered.
  static constexpr std::size_t kMaxEpochs = 256;

  /// `nav` must outlive the station.
  BaseStation(const EphemerisStore& nav, const RtkConfig& config);

  /// Antenna reference point (ECEF, m). A change of more than 1 mm clears the buffered epochs
  /// (their OMC values refer to the old position) and is counted.
  void setPosition(const Eigen::Vector3d& arp);
  const std::optional<Eigen::Vector3d>& position() const { return position_; }
  /// GLONASS FDMA channels of the base (RINEX header, RTCM 1020/MSM); the navigation data fill gaps.
  void setGlonassChannels(const GlonassChannels& channels);

  /// Order of the epochs (default forward); changing it clears the buffer and the slip history.
  void setDirection(TimeDirection d);
  TimeDirection direction() const { return direction_; }
  /// Adds a base epoch; epochs must come in increasing time, or decreasing when the direction is
  /// backward (others are dropped and counted).
  void addEpoch(const ObsEpoch& epoch);
  /// Aligns the buffered base data to a rover time (see the file comment).
  BaseAvailability snapshot(const GpsTime& roverTime, BaseSnapshot& out);
  /// Time of the newest base epoch (the last added), if any.
  std::optional<GpsTime> latestTime() const;
  /// Drops all buffered epochs and slip history.
  void clear();

  const BaseStationStats& stats() const { return stats_; }
  const CycleSlipCounts& slipCounts() const { return slips_.counts(); }
  /// Doppler sanity of the base stream (applied to every added epoch before slip detection).
  const DopplerConsistency& doppler() const { return doppler_; }

 private:
  struct Epoch {
    GpsTime time;
    ObsEpoch raw;
    bool modelled = false;
    std::vector<BaseSignal> signals;
    // Phase rates for extrapolating this epoch (aligned with `signals`, NaN where none), minus
    // their median, computed once per rate window (first epoch time and count) and reused for
    // every rover epoch that holds this one; cleared when `signals` are modelled again.
    bool ratesValid = false;
    bool ratesUsable = false;
    GpsTime ratesFirst;
    int ratesCount = 0;
    std::vector<double> rates;
  };
  void model(Epoch& e);
  /// Moves the phases of a held epoch `b` to `t` with their satellite-specific rates.
  void extrapolate(int b, const GpsTime& t, BaseSnapshot& out);

  const EphemerisStore& nav_;
  RtkConfig config_;
  std::optional<Eigen::Vector3d> position_;
  TimeDirection direction_ = TimeDirection::Forward;
  GlonassChannels channels_;
  CycleSlipDetector slips_;
  DopplerConsistency doppler_{"base"};
  std::deque<Epoch> epochs_;
  BaseStationStats stats_;
};

}  // namespace gvins
