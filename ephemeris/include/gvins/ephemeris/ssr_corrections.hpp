// Store of SSR corrections (ssr_message.hpp) and their application to broadcast satellite states:
// the real-time counterpart of precise products. Corrections are kept per satellite as a time
// series, so a whole recorded stream can be loaded first and every epoch still sees only the
// corrections that a real-time receiver would have had (epoch time <= t, not older than maxAge).
//
// Application (RTCM 10403.3, 3.5.12.3; the same formulas as RTKLIB's satpos_ssr): with
// Δt = t − (t_SSR + updateInterval/2),
//   e_a = v/|v|, e_c = (r × v)/|r × v|, e_r = e_a × e_c   (r, v of the broadcast record, ECEF)
//   r_corrected = r − [e_r e_a e_c] (δO + δȮ Δt)
//   clock_corrected = clock_broadcast + (C0 + C1 Δt + C2 Δt² [+ high-rate C]) / c.
// The orbit correction refers to the broadcast record whose issue of data it names; orbit and
// clock must carry the same IOD SSR. The result is the ionosphere-free antenna phase centre and a
// clock in the broadcast clock's datum: group delays still apply, unless SSR code biases for the
// signal are present.
#pragma once

#include <array>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "gvins/base/gnss_time.hpp"
#include "gvins/base/satellite.hpp"
#include "gvins/base/signal.hpp"
#include "gvins/ephemeris/satellite_state.hpp"
#include "gvins/ephemeris/ssr_message.hpp"

namespace gvins {

struct SsrOptions {
  /// Longest age (s) of an orbit or clock correction, measured from its SSR epoch time. 90 s as
  /// RTKLIB's MAXAGESSR; IGS real-time streams update clocks every 5 s and orbits every 60 s.
  double maxAge = 90.0;
  /// Longest age of a high-rate clock correction (s).
  double maxHighRateAge = 10.0;
  /// Longest age of code biases (s); they change slowly.
  double maxCodeBiasAge = 3600.0;
};

/// The corrections valid for one satellite at one time.
struct SsrSelection {
  SsrHeader orbitHeader;
  SsrOrbitCorrection orbit;
  SsrHeader clockHeader;
  SsrClockCorrection clock;
  std::optional<double> highRateClock;  ///< m
  std::optional<int> uraIndex;
};

class SsrCorrections {
 public:
  explicit SsrCorrections(SsrOptions options = {}) : options_(options) {}
  const SsrOptions& options() const { return options_; }
  void setOptions(const SsrOptions& options) { options_ = options; }

  /// Adds every satellite's part of a message. Messages may arrive in any order.
  void add(const SsrMessage& message);
  bool empty() const { return count_ == 0; }
  /// Satellite records held (one per satellite and message).
  std::size_t size() const { return count_; }

  /// The orbit and clock corrections a receiver would use at time t (GPST): the newest orbit with
  /// SSR epoch <= t and age <= maxAge, the newest clock of the same IOD SSR under the same limits
  /// (a combined message counts as both), the newest high-rate clock of that IOD SSR within
  /// maxHighRateAge. nullopt if orbit or clock is missing.
  std::optional<SsrSelection> select(SatId sat, const GpsTime& t) const;
  /// True if some orbit correction of `system` is valid at t (epoch <= t, age <= maxAge): the
  /// stream covers that system, and its satellites without a correction of their own should not be
  /// mixed in from the broadcast clocks (their clock datum differs).
  bool coversSystem(System system, const GpsTime& t) const;
  /// Code bias (m, RTCM sign: added to the measured pseudorange) of the signal at t, from the
  /// newest code-bias message with epoch <= t and age <= maxCodeBiasAge; nullopt if none.
  std::optional<double> codeBias(SatId sat, ObsCode code, const GpsTime& t) const;

 private:
  template <class T>
  struct Timed {
    SsrHeader header;
    T value;
  };
  struct PerSatellite {
    std::vector<Timed<SsrOrbitCorrection>> orbits;  // sorted by header.epoch
    std::vector<Timed<SsrClockCorrection>> clocks;
    std::vector<Timed<double>> highRateClocks;
    std::vector<Timed<std::vector<std::pair<ObsCode, double>>>> codeBiases;
    std::vector<Timed<int>> uras;
  };
  PerSatellite* slot(SatId sat);
  const PerSatellite* find(SatId sat) const;

  SsrOptions options_;
  std::vector<PerSatellite> sats_;  // by satIndex
  std::array<std::vector<GpsTime>, kNumSystems> orbitEpochs_;  // sorted, per system
  std::size_t count_ = 0;
};

/// The radial / along-track / cross-track frame of SSR orbit corrections as columns
/// [e_r e_a e_c] (ECEF): e_a = v/|v|, e_c = r × v/|r × v|, e_r = e_a × e_c, from a broadcast
/// state's position and velocity. nullopt if the velocity is degenerate.
std::optional<Eigen::Matrix3d> ssrOrbitFrame(const SatelliteState& broadcast);

/// Applies a selection to the broadcast state of the record the orbit correction refers to (see
/// the file comment). The result has ssr = true; accuracy from the URA when given. nullopt if the
/// broadcast velocity is degenerate.
std::optional<SatelliteState> applySsr(const SatelliteState& broadcast, const SsrSelection& ssr,
                                       const GpsTime& t);

/// The issue of data that SSR orbit corrections use to name a broadcast record
/// (SsrOrbitCorrection::issueOfData): GPS/QZSS IODE, Galileo IODnav, GLONASS the tb index, BeiDou
/// DF470 = (toe mod 8192) / 8 (toe in BDT seconds of the week).
int ssrIssueOfData(const KeplerEphemeris& eph);
int ssrIssueOfData(const GlonassEphemeris& eph);
/// BeiDou DF471 (SsrOrbitCorrection::iodCrc): (toe / 720) mod 240.
int ssrBeidouIod(const KeplerEphemeris& eph);

}  // namespace gvins
