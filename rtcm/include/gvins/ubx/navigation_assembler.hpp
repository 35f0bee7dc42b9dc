// Assembles broadcast ephemerides from UBX-RXM-SFRBX navigation data: keeps the partial
// subframes/pages/strings of each satellite and emits a record once all parts with matching issue
// of data have arrived. GPS/QZSS LNAV (IS-GPS-200), Galileo I/NAV (OS SIS ICD), BeiDou D1/D2
// (BDS-SIS-ICD B1I), GLONASS L1/L2 OF strings (GLONASS ICD 5.1); of GPS/QZSS CNAV on L2C and L5
// (IS-GPS-200 appendix III, IS-GPS-705) every message's CRC and message type 30 (group delays and
// inter-signal corrections). SBAS messages are counted and skipped. Records are filled exactly as the RTCM decoder and the RINEX reader fill them.
#pragma once

#include <array>
#include <compare>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "gvins/base/gnss_time.hpp"
#include "gvins/base/satellite.hpp"
#include "gvins/ephemeris/cnav_group_delays.hpp"
#include "gvins/ephemeris/glonass_ephemeris.hpp"
#include "gvins/ephemeris/ionosphere_parameters.hpp"
#include "gvins/ephemeris/kepler_ephemeris.hpp"
#include "gvins/ubx/sfrbx.hpp"

namespace gvins {
class EphemerisStore;
}

namespace gvins::ubx {

/// What one SFRBX message completed (usually nothing).
struct NavDataUpdate {
  std::vector<KeplerEphemeris> kepler;
  std::vector<GlonassEphemeris> glonass;
  /// GPS/QZSS CNAV message type 30 group delays and inter-signal corrections.
  std::vector<CnavGroupDelays> cnav;
  /// Ionosphere parameters completed by this message (only the systems set are new).
  IonosphereParameters ionosphere;

  bool empty() const;
  /// Adds the records and group delays to the store and sets the ionosphere parameters present here.
  void addTo(EphemerisStore& store) const;
};

/// Counters of one system.
struct NavigationCounts {
  std::uint64_t messages = 0;         ///< SFRBX messages of the system
  std::uint64_t parityFailures = 0;   ///< GPS/QZSS parity, BeiDou BCH, GLONASS Hamming failures
  std::uint64_t crcFailures = 0;      ///< Galileo I/NAV and GPS/QZSS CNAV CRC-24Q failures
  std::uint64_t incompleteSets = 0;   ///< partial sets dropped unused (another issue of data or frame came first)
  std::uint64_t unknownMessages = 0;  ///< unhandled pages/subframes/strings, bad layout, unknown signals
  std::uint64_t skipped = 0;          ///< messages not decoded: SBAS, NavIC, QZSS L1S,
                                      ///< Galileo F/NAV and E6, BeiDou B-CNAV1/2, GLONASS CDMA
  std::uint64_t ephemerides = 0;      ///< complete records emitted
  std::uint64_t ionosphere = 0;       ///< ionosphere parameter sets emitted
  std::uint64_t groupDelays = 0;      ///< CNAV message type 30 group delay sets emitted

  NavigationCounts& operator+=(const NavigationCounts& o);
};

/// Where SFRBX navigation data comes from, as the receiver tags it: gnssId and sigId and, for
/// BeiDou, whether the satellite is a GEO (C01-C05, C59-C63: D2 message) or not (D1).
struct NavigationSource {
  std::uint8_t gnssId = 0, sigId = 0;
  bool beidouGeo = false;
  friend auto operator<=>(const NavigationSource&, const NavigationSource&) = default;
};

/// The decoder of NavigationAssembler a source goes to (None: not decoded).
enum class NavigationDecoder : std::uint8_t { None, Lnav, Cnav, GalileoInav, BeidouD1, BeidouD2, GlonassStrings };

/// The one table of what each source carries: the decoder it goes to. NavigationAssembler routes
/// by it and navigationSourceInfo names it.
NavigationDecoder navigationDecoder(const NavigationSource& source);

/// The message a source carries and whether the assembler decodes it: "LNAV", "I/NAV",
/// "D1 (MEO/IGSO)", "D2 (GEO)", "strings" or e.g. "F/NAV (not decoded)", "B-CNAV1 (not decoded)".
struct NavigationSourceInfo {
  std::string message;
  bool decoded = false;
};
NavigationSourceInfo navigationSourceInfo(const NavigationSource& source);

class NavigationAssembler {
 public:
  NavigationAssembler();
  ~NavigationAssembler();
  NavigationAssembler(NavigationAssembler&&) noexcept;
  NavigationAssembler& operator=(NavigationAssembler&&) noexcept;

  /// receiveTime: time of the latest RAWX epoch (resolves week/day ambiguities; the message's own
  /// week numbers are used where they exist). A time before GPS week 1024 (e.g. GpsTime{}) means
  /// "not known yet": GPS/QZSS sets are then kept until a message arrives with a time; GLONASS
  /// sets are dated by NT/N4 once string 5 arrives.
  /// Returns the records completed by this message.
  /// Never throws on bad navigation data: bad parity/CRC and malformed parts are counted.
  NavDataUpdate add(const SfrbxMessage& msg, const GpsTime& receiveTime);

  const NavigationCounts& counts(System system) const {
    return counts_[static_cast<std::size_t>(systemIndex(system))];
  }
  /// Sum over all systems (messages of an unknown gnssId count as unknown messages).
  NavigationCounts total() const;
  /// The same counters per gnssId/sigId (and BeiDou GEO or not): what was decoded, what not.
  const std::map<NavigationSource, NavigationCounts>& countsBySource() const { return bySource_; }

 private:
  void dispatch(const SfrbxMessage& msg, const NavigationSource& source, System system, const GpsTime& receiveTime,
                NavDataUpdate& out, NavigationCounts& c);

  struct State;
  std::unique_ptr<State> state_;
  std::array<NavigationCounts, kNumSystems> counts_{};
  std::map<NavigationSource, NavigationCounts> bySource_;
  std::uint64_t unknownGnss_ = 0;
};

}  // namespace gvins::ubx
