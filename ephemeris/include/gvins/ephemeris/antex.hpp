// ANTEX antenna phase-centre files (IGS "ANTEX: The Antenna Exchange Format, Version 1.4",
// R. Schmid, 2010; e.g. igs20.atx): phase-centre offsets (PCO) and variations (PCV) of satellite
// and receiver antennas per frequency.
//
// Satellite antennas: the PCO is given in the satellite body frame (x, y, z; z towards the Earth's
// centre, y along the solar-panel axis, x completing the right-handed frame towards the Sun-lit
// half-plane, IGS convention), from the centre of mass, which is what SP3 orbits give. Receiver
// antennas: north, east, up from the antenna reference point. Values are mm in the file and metres
// here; PCVs are kept per zenith (nadir for satellites) angle on the ZEN1..ZEN2 grid, the
// non-azimuth-dependent row (NOAZI) and, when DAZI > 0, one row per azimuth.
#pragma once

#include <iosfwd>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "gvins/base/gnss_time.hpp"
#include "gvins/base/parse_error.hpp"
#include "gvins/base/satellite.hpp"

namespace gvins {

/// One frequency block (START OF FREQUENCY .. END OF FREQUENCY) of an antenna.
struct AntexFrequency {
  System system = System::Gps;  ///< from the frequency code, e.g. "G01" -> GPS
  char band = '1';              ///< RINEX band digit of the code, e.g. "G01" -> '1', "E05" -> '5'
  /// PCO in metres: satellite x/y/z (body frame), receiver north/east/up.
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  /// PCV in metres on the zenith/nadir grid ZEN1, ZEN1 + DZEN, ..., ZEN2 (the NOAZI row).
  std::vector<double> noAzimuth;
  /// Azimuth-dependent rows (only when DAZI > 0): azimuths 0, DAZI, ..., 360 deg, each with the
  /// same grid as noAzimuth.
  std::vector<std::vector<double>> byAzimuth;
};

struct AntexAntenna {
  std::string type;                ///< TYPE / SERIAL NO columns 1-20, trailing blanks removed
  std::string serial;              ///< columns 21-40 trimmed (satellites: e.g. "G01")
  std::optional<SatId> satellite;  ///< satellite antennas: the PRN/slot of the serial field
  std::string svn;                 ///< columns 41-50 trimmed (satellites: e.g. "G063")
  std::string cospar;              ///< columns 51-60 trimmed
  double dazi = 0.0;               ///< deg, 0 = no azimuth dependence
  double zen1 = 0.0, zen2 = 0.0, dzen = 0.0;  ///< deg (nadir angles for satellites)
  std::optional<GpsTime> validFrom, validUntil;  ///< satellites: the time the PRN assignment holds
  std::string sinexCode;
  std::vector<AntexFrequency> frequencies;

  bool isSatellite() const { return satellite.has_value(); }
  /// The block of a system and band, or nullptr.
  const AntexFrequency* frequency(System system, char band) const;
  /// Whether `t` lies in [validFrom, validUntil) (open ends when not given).
  bool validAt(const GpsTime& t) const;
};

struct AntexData {
  double version = 1.4;
  char system = 'M';   ///< ANTEX VERSION / SYST: G, R, E, C, J, S, I or M (mixed)
  char pcvType = 'A';  ///< PCV TYPE / REFANT: A absolute, R relative
  std::string referenceAntenna;
  std::vector<std::string> comments;
  std::vector<AntexAntenna> antennas;  ///< in file order

  /// The satellite antenna valid for `sat` at `t` (latest VALID FROM if several), or nullptr.
  const AntexAntenna* satellite(SatId sat, const GpsTime& t) const;
  /// The receiver antenna of a type ("TRM59800.00     NONE": 20 columns with radome as in RINEX;
  /// trailing blanks ignored), or nullptr. Without an exact match, the same antenna with radome
  /// "NONE" is returned.
  const AntexAntenna* receiver(std::string_view typeAndRadome) const;
};

/// Parses ANTEX 1.3/1.4 text held in memory; `name` is used in error messages. Throws ParseError
/// naming file, line and field for any malformed input (unknown record order, bad numbers, a PCV
/// row whose length does not match the ZEN1/ZEN2/DZEN grid, a frequency count that differs from
/// "# OF FREQUENCIES", a missing END OF ANTENNA, ...).
AntexData parseAntex(std::string_view text, const std::string& name);
/// Reads an ANTEX file (plain or gzip).
AntexData readAntex(const std::string& path);

/// Writes ANTEX 1.4 (offsets and PCVs to 0.01 mm; validity times as given, GPST). What
/// parseAntex reads back equals `data` to that rounding.
void writeAntex(std::ostream& out, const AntexData& data);

}  // namespace gvins
