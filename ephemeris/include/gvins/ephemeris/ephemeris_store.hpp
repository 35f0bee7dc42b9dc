// Ephemeris store: keeps every broadcast record received (from RINEX or RTCM) and picks the right
// one for a satellite and time.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "gvins/base/observation.hpp"
#include "gvins/ephemeris/glonass_ephemeris.hpp"
#include "gvins/ephemeris/ionosphere_parameters.hpp"
#include "gvins/ephemeris/kepler_ephemeris.hpp"
#include "gvins/ephemeris/antex.hpp"
#include "gvins/ephemeris/bias_sinex.hpp"
#include "gvins/ephemeris/cnav_group_delays.hpp"
#include "gvins/ephemeris/precise_ephemeris.hpp"
#include "gvins/ephemeris/rinex_nav.hpp"
#include "gvins/ephemeris/satellite_state.hpp"
#include "gvins/ephemeris/ssr_corrections.hpp"

namespace gvins {

/// A selected record (nullptr: none) with a span of times [from, until] around the time asked
/// for in which the same satellite and policy select the same record again: no selection rule
/// flips for any record inside it (validity window, transmission time, search range, nearest toe),
/// with a margin of kEphemerisSpanMargin to the nearest flip. It allows caching the selection.
template <class Record>
struct EphemerisChoice {
  const Record* record = nullptr;
  GpsTime from, until;
};
/// Margin (s) kept between a choice's span and the times at which a selection rule flips: far above
/// the rounding of the time differences (< 1e-9 s), far below the spacing of broadcast records.
inline constexpr double kEphemerisSpanMargin = 1e-3;

/// Selection policy knobs.
struct EphemerisSelection {
  bool allowUnhealthy = false;
  /// Galileo: which message's clock to use (I/NAV: E1-E5b; F/NAV: E1-E5a). With `preferInav` the
  /// store falls back to the other message type when the preferred one is missing.
  bool preferGalileoInav = true;
  /// Use a record whose transmission time (ttr) is after t only if t is within this many seconds
  /// of toe (real-time processing never has records from the future; post-processing with a
  /// nav file of the whole day may). Negative: never use records transmitted after t.
  double futureTolerance = 7200.0;
};

class EphemerisStore {
 public:
  /// Adds a record; exact duplicates (same satellite, message, toe and issue of data) are ignored.
  void add(const KeplerEphemeris& eph);
  void add(const GlonassEphemeris& eph);
  /// Adds all records and header parameters of a navigation file.
  void add(const NavData& nav);

  /// The record for a satellite at time t: within the system's validity window around toe
  /// (per-system windows documented in the implementation, e.g. GPS the fit interval, GLONASS
  /// +-15 min around tb), healthy unless allowed, newest issue of data, nearest toe.
  /// nullptr if none.
  const KeplerEphemeris* selectKepler(SatId sat, const GpsTime& t,
                                      const EphemerisSelection& policy = {}) const;
  const GlonassEphemeris* selectGlonass(SatId sat, const GpsTime& t,
                                        const EphemerisSelection& policy = {}) const;
  /// The same selections with the span in which they stay the same (see EphemerisChoice).
  EphemerisChoice<KeplerEphemeris> chooseKepler(SatId sat, const GpsTime& t,
                                                const EphemerisSelection& policy = {}) const;
  EphemerisChoice<GlonassEphemeris> chooseGlonass(SatId sat, const GpsTime& t,
                                                  const EphemerisSelection& policy = {}) const;
  /// Changes whenever records are added: choices made before are then out of date.
  std::uint64_t revision() const { return revision_; }

  /// Satellite state at transmit time t: from the precise products where they are set and cover
  /// the satellite at t (SatelliteState::precise), else from the selected broadcast record;
  /// std::nullopt when there is neither.
  std::optional<SatelliteState> satelliteState(SatId sat, const GpsTime& t,
                                               const EphemerisSelection& policy = {}) const;
  /// Precise orbit/clock products (SP3, RINEX clock) preferred over the broadcast records for the
  /// satellite states; the broadcast records still give group delays, GLONASS channels and the
  /// ionosphere parameters. nullptr: broadcast only. Changes revision().
  void setPrecise(std::shared_ptr<const PreciseEphemeris> precise);
  const PreciseEphemeris* precise() const { return precise_.get(); }
  /// The precise state alone (std::nullopt without products or coverage).
  std::optional<SatelliteState> preciseState(SatId sat, const GpsTime& t) const;
  /// Satellite antenna phase-centre offsets (ANTEX) for the precise products: SP3 positions are the
  /// centre of mass (IGS), the ranges refer to the antenna phase centre, metres apart. With them
  /// set, preciseState adds the offset of the reference ionosphere-free pair
  /// (satellite_antenna.hpp), and satellites without a valid ANTEX entry fall back to their
  /// broadcast records. Without them the product positions are taken as phase-centre positions
  /// (right for gvins-sim products, metres off for IGS ones). Changes revision().
  void setSatelliteAntennas(std::shared_ptr<const AntexData> antex);
  const AntexData* satelliteAntennas() const { return antex_.get(); }
  /// Code biases (Bias-SINEX OSBs) that go with the precise clocks. Changes revision().
  void setCodeBiases(std::shared_ptr<const BiasSinexData> biases);
  const BiasSinexData* codeBiases() const { return biases_.get(); }
  /// Delay (s) of the code `code` of `sat` against the clock of `state`: the code OSB of the
  /// biases when the state is precise and they have one for the signal (IGS convention: the OSBs of
  /// the clock's reference pair combine to zero); for an SSR state the SSR code bias of the signal
  /// (−bias/c: RTCM biases are added to the measurement); else the broadcast group delay
  /// (groupDelay()).
  double codeDelay(const SatelliteState& state, SatId sat, ObsCode code, const GpsTime& t,
                   const EphemerisSelection& policy = {}) const;
  /// The correction-service part of codeDelay alone: the code OSB (s) when `state` is precise and
  /// the biases have one for the signal, −(SSR code bias)/c when `state` is SSR-corrected and the
  /// stream has one, else nullopt (for callers that hold their broadcast record already).
  std::optional<double> preciseCodeBias(const SatelliteState& state, SatId sat, ObsCode code,
                                        const GpsTime& t) const;
  /// SSR corrections (real-time streams; ssr_corrections.hpp). Where no precise products cover a
  /// satellite, satelliteState corrects the broadcast record that the SSR orbit correction names;
  /// satellites of a system the stream covers at t but without a valid correction of their own
  /// get no state (their clocks would be in another datum). Changes revision().
  void addSsr(const SsrMessage& message);
  void setSsrOptions(const SsrOptions& options);
  const SsrCorrections& ssr() const { return ssr_; }
  /// The SSR-corrected state alone (std::nullopt without a valid correction or matching record).
  std::optional<SatelliteState> ssrState(SatId sat, const GpsTime& t,
                                         const EphemerisSelection& policy = {}) const;

  /// Group delay (s) for a pseudorange on `code` from the record selected at t and, for GPS/QZSS,
  /// the CNAV group delays at t (cnavGroupDelays) (0 if no record).
  double groupDelay(SatId sat, ObsCode code, const GpsTime& t,
                    const EphemerisSelection& policy = {}) const;

  /// Adds the group delays of a GPS/QZSS CNAV message type 30. A message that repeats the
  /// corrections of the one before it (same satellite) only extends how long those are known.
  /// Does not change revision(): no record choice depends on it.
  void add(const CnavGroupDelays& cnav);
  /// The latest CNAV message type 30 of a satellite at or before t (its time <= t), unless its
  /// corrections were last seen more than kCnavGroupDelayMaxAge before t; nullptr if none.
  const CnavGroupDelays* cnavGroupDelays(SatId sat, const GpsTime& t) const;

  /// Satellites with at least one record.
  std::vector<SatId> satellites() const;
  std::size_t size() const;

  /// All Keplerian / GLONASS records of a satellite, sorted by toe (empty for none).
  const std::vector<KeplerEphemeris>& keplerRecords(SatId sat) const;
  const std::vector<GlonassEphemeris>& glonassRecords(SatId sat) const;

  /// Half-width (s) of the window around toe in which a record is used; see the implementation
  /// for the per-system values and their sources.
  static double validityHalfWindow(const KeplerEphemeris& eph);
  static double validityHalfWindow(const GlonassEphemeris& eph);

  IonosphereParameters& ionosphere() { return iono_; }
  const IonosphereParameters& ionosphere() const { return iono_; }
  /// GLONASS FDMA channels learned from the GLONASS records.
  const GlonassChannels& glonassChannels() const { return channels_; }
  std::optional<int> leapSeconds() const { return leapSeconds_; }

 private:
  std::vector<std::vector<KeplerEphemeris>> kepler_;   // indexed by satIndex, sorted by toe
  std::vector<std::vector<GlonassEphemeris>> glonass_;
  struct CnavRun {
    CnavGroupDelays first;  // the first message with these corrections
    GpsTime lastSeen;       // the last message that repeated them
  };
  std::vector<std::vector<CnavRun>> cnav_;  // indexed by satIndex, sorted by time
  IonosphereParameters iono_;
  GlonassChannels channels_;
  std::optional<int> leapSeconds_;
  std::shared_ptr<const PreciseEphemeris> precise_;
  std::shared_ptr<const AntexData> antex_;
  std::shared_ptr<const BiasSinexData> biases_;
  SsrCorrections ssr_;
  std::uint64_t revision_ = 0;
};

}  // namespace gvins
