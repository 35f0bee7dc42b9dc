// RINEX navigation files: reader for versions 2.10/2.11 (GPS n, GLONASS g, other letters),
// 3.0x mixed and 4.0x, and a RINEX 3.04 writer.
#pragma once

#include <iosfwd>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "gvins/base/observation.hpp"
#include "gvins/base/parse_error.hpp"
#include "gvins/ephemeris/glonass_ephemeris.hpp"
#include "gvins/ephemeris/ionosphere_parameters.hpp"
#include "gvins/ephemeris/kepler_ephemeris.hpp"

namespace gvins {

/// Everything a navigation file holds.
struct NavData {
  double version = 3.04;
  std::vector<KeplerEphemeris> kepler;
  std::vector<GlonassEphemeris> glonass;
  IonosphereParameters iono;
  std::vector<TimeSystemCorrection> timeCorrections;
  std::optional<int> leapSeconds;  ///< GPST - UTC from the header, s
  /// Records the reader skipped without error (unsupported systems such as SBAS/NavIC, RINEX 4
  /// message types it does not decode), with a reason each, for the caller's summary.
  std::vector<std::string> skipped;
};

/// Reads a navigation file. Throws ParseError (file, line, field) on malformed content, and for
/// empty files and unknown versions.
NavData readRinexNav(const std::string& path);
/// Parses navigation file text already in memory; `name` is used in error messages.
NavData parseRinexNav(std::string_view text, std::string_view name);
/// Merges b into a (records appended, header values kept where a has them).
void mergeNavData(NavData& a, const NavData& b);

/// Writes a RINEX 3.04 mixed navigation file (GPS, Galileo, BeiDou, QZSS, GLONASS records and
/// the header's ionosphere, time-correction and leap-second lines).
void writeRinexNav(std::ostream& out, const NavData& nav, std::string_view programName = "SRI-GVINS");

}  // namespace gvins
