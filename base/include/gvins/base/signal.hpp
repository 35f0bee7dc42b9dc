// GNSS signals: RINEX 3 observation codes (band + tracking attribute, e.g. "1C", "2W", "5Q") and
// their carrier frequencies, including GLONASS FDMA channels.
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "gvins/base/satellite.hpp"

namespace gvins {

/// A RINEX 3 signal code without the observation type letter: band digit and attribute letter
/// ("1C" = L1 C/A, "2W" = L2 semi-codeless P(Y), "7I" = BeiDou B2I / Galileo E5b-I ...).
struct ObsCode {
  char band = '1';
  char attr = 'C';

  constexpr ObsCode() = default;
  constexpr ObsCode(char b, char a) : band(b), attr(a) {}
  /// Parses "1C" (two characters); nullopt if the band is not a digit or the attribute not a
  /// letter.
  static std::optional<ObsCode> parse(std::string_view two);
  std::string str() const { return std::string{band, attr}; }

  friend constexpr bool operator==(ObsCode a, ObsCode b) { return a.band == b.band && a.attr == b.attr; }
  friend constexpr bool operator<(ObsCode a, ObsCode b) {
    return a.band != b.band ? a.band < b.band : a.attr < b.attr;
  }
};

/// Observation types of RINEX 3: pseudorange, carrier phase, Doppler, signal strength.
enum class ObsType : char { Code = 'C', Phase = 'L', Doppler = 'D', Snr = 'S' };

/// Whether a band digit is defined for a system in RINEX 3.05 (table 9-16 ... 9-21).
bool isKnownBand(System sys, char band);

/// Carrier frequency in Hz of a system's band. GLONASS G1/G2 use the FDMA channel number k
/// (-7..+6): f = 1602 MHz + k*0.5625 MHz, 1246 MHz + k*0.4375 MHz (GLONASS ICD 5.1, 3.3.1.4).
/// Returns std::nullopt for a band the system does not have (or a GLONASS FDMA band without a
/// valid channel).
std::optional<double> carrierFrequency(System sys, char band, std::optional<int> glonassChannel = {});

/// Carrier wavelength c/f in metres; std::nullopt as carrierFrequency.
std::optional<double> carrierWavelength(System sys, char band, std::optional<int> glonassChannel = {});

/// RINEX 3.02 wrote BeiDou B1I as band 1 ("C1I"); RINEX 3.03+ uses band 2 ("C2I"). Maps a
/// code read from a file of the given version to current usage.
ObsCode normalizeObsCode(System sys, ObsCode code, double rinexVersion);

/// Preferred tracking attributes per system and band, best first (used to pick one signal per
/// band when a receiver reports several, e.g. GPS L1: C before W/P/X/L/S).
std::string_view attributePriority(System sys, char band);

/// Whether two codes of one band denote the same transmitted signal (its data or pilot component
/// or their combination, e.g. GPS L2C "2S"/"2L"/"2X", Galileo E1 OS "1B"/"1C"/"1X", E5a "5I"/"5Q"/
/// "5X") rather than different signals sharing the carrier (GPS L1 C/A "1C" against P(Y) "1W" or
/// L1C "1X"). Grouping from the RINEX 3.05 observation code tables 4-10. False for different bands.
bool sameSignal(System sys, ObsCode a, ObsCode b);

/// The usual primary frequency band per system for single-frequency processing:
/// GPS/QZSS/SBAS/Galileo '1', GLONASS '1', BeiDou '2' (B1I), NavIC '5'.
char primaryBand(System sys);

}  // namespace gvins
