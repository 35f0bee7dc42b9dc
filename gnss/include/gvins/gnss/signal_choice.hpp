// The primary code signal of a satellite, with fallback across bands: SPP, the fusion and (through
// the same band order) RTK take a satellite's first tracked band of the user's preference list,
// and when none of those is tracked the next band of the system's fallback order, so that a
// receiver without the usual primary signal (e.g. a u-blox X20P: BeiDou B1C/B2a/B3I, no B1I)
// still contributes every satellite it tracks.
//
// Fallback order per system (after the user's list; bands already in it are skipped). Bands
// whose group delay the broadcast records in use give come first:
//   GPS, QZSS  L1, L5, L2    LNAV T_GD: L1 T_GD, L2 γ12 T_GD (IS-GPS-200N 20.3.3.3.3.2), L5 T_GD
//                            without its ISC, which only CNAV carries (IS-GPS-705J 20.3.3.3.1.2)
//   GLONASS    G1, G2, G3    Δτ_n on G2 (GLONASS ICD 5.1, 4.4); the CDMA G3 has none in the FDMA record
//   Galileo    E1, E5a, E5b, E5, E6   BGD of I/NAV or F/NAV (OS SIS ICD 2.1, 5.1.5); E5 AltBOC and
//                            E6 have none there
//   BeiDou     B1I, B3I, B2I, B1C, B2a, B2b/B2   D1/D2 clocks refer to B3I (zero delay), T_GD1 on B1I,
//                            T_GD2 on B2I (BDS-SIS-ICD-B1I 3.0, 5.2.4.8); the B1C and B2a delays
//                            (T_GDB1Cp, T_GDB2ap) are only in B-CNAV1/2 (BDS-SIS-ICD-B1C 1.0, 7.6.x;
//                            B2a 1.0, 6.2.x), so with D1/D2 records they stay uncorrected (a few
//                            metres) and come after B3I and B2I
//   SBAS L1, L5;  NavIC L5, S
// Group delays themselves are applied per signal by transmitGroupDelay (zero_difference.hpp);
// this file only decides which signal is used.
#pragma once

#include <cstddef>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "gvins/base/observation.hpp"
#include "gvins/base/satellite.hpp"
#include "gvins/base/signal.hpp"
#include "gvins/gnss/satellite_observation_model.hpp"

namespace gvins {

/// The system's fallback band order for the primary signal (see the table above).
std::string_view fallbackBands(System sys);

/// `preferred` followed by the bands of fallbackBands(sys) it does not list (the order in which
/// RTK's double differences look for bands).
std::string bandsWithFallback(std::string_view preferred, System sys);

/// The usual name of a band of a system ("L1", "E5a", "B1I", "B3I", ...), or "band N".
std::string bandName(System sys, char band);

/// The primary code signal of `so`: the first usable code (usableCode) on `preferred[0 .. count)`,
/// else on the rest of `preferred`, else on fallbackBands(system) not in `preferred`. nullopt when
/// the satellite has no usable code on any of them.
std::optional<CodeSignal> primaryCode(const SatObs& so, std::string_view preferred, std::size_t count,
                                      std::optional<int> glonassChannel);

/// One notice per system and fallback signal: record() returns a message the first time a
/// system's primary signal is taken from a band other than its preferred first band (naming the
/// system, the preferred band and the signal used), nullopt afterwards and for the preferred band.
class SignalFallbackNotices {
 public:
  std::optional<std::string> record(System sys, char preferredBand, ObsCode used);
  const std::vector<std::string>& messages() const { return messages_; }

 private:
  std::set<std::pair<int, std::string>> seen_;
  std::vector<std::string> messages_;
};

}  // namespace gvins
