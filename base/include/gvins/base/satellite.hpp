// Satellite systems and satellite identifiers (RINEX 3 style: G05, R12, E07, C23, J02, S27, I03).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace gvins {

enum class System : std::uint8_t { Gps = 0, Glonass, Galileo, BeiDou, Qzss, Sbas, Navic };
inline constexpr int kNumSystems = 7;

/// RINEX system letter: G R E C J S I.
char systemLetter(System s);
/// Inverse of systemLetter; std::nullopt for an unknown letter.
std::optional<System> systemFromLetter(char c);
/// "GPS", "GLONASS", "Galileo", "BeiDou", "QZSS", "SBAS", "NavIC".
std::string_view systemName(System s);
/// Index 0..kNumSystems-1.
constexpr int systemIndex(System s) { return static_cast<int>(s); }

/// Highest satellite number per system in RINEX 3 numbering (SBAS: PRN - 100, i.e. S20..S58;
/// QZSS: PRN - 192, i.e. J01..J10; BeiDou up to C63 per BDS ICD; GLONASS slots R01..R27
/// leave room for spares beyond the nominal 24).
constexpr int maxPrn(System s) {
  switch (s) {
    case System::Gps: return 32;
    case System::Glonass: return 27;
    case System::Galileo: return 36;
    case System::BeiDou: return 63;
    case System::Qzss: return 10;
    case System::Sbas: return 58;
    case System::Navic: return 14;
  }
  return 0;
}
/// Lowest satellite number per system (1, except SBAS which starts at S20 = PRN 120).
constexpr int minPrn(System s) { return s == System::Sbas ? 20 : 1; }

/// A satellite: system and RINEX 3 satellite number.
struct SatId {
  System system = System::Gps;
  std::uint8_t prn = 0;

  constexpr SatId() = default;
  constexpr SatId(System s, int n) : system(s), prn(static_cast<std::uint8_t>(n)) {}

  constexpr bool valid() const {
    return prn >= minPrn(system) && prn <= maxPrn(system);
  }
  /// "G05".
  std::string str() const;
  /// Parses "G05", "G 5", "E11"; a bare number (RINEX 2 GPS files: " 5") is GPS, and RINEX 2's
  /// 'M' mixed letter is not a system. Returns std::nullopt for anything else or out-of-range
  /// numbers.
  static std::optional<SatId> parse(std::string_view text);

  friend constexpr bool operator==(SatId a, SatId b) { return a.system == b.system && a.prn == b.prn; }
  friend constexpr bool operator<(SatId a, SatId b) {
    return a.system != b.system ? a.system < b.system : a.prn < b.prn;
  }
};

/// Dense index over all satellites of all systems, for fixed-size per-satellite tables.
int satIndex(SatId s);
/// Inverse of satIndex.
SatId satFromIndex(int index);
/// Number of entries a satIndex table needs.
int numSatIndices();

/// BeiDou orbit classes. Per BDS-SIS-ICD-B1I 3.0 (5.2.4.12) GEO satellites need a different
/// position computation; the PRN allocation follows the BDS ICDs and the CSNO constellation
/// status: GEO C01-C05 and C59-C63; IGSO C06-C10, C13, C16, C31, C38-C40, C56; MEO otherwise.
enum class BeiDouOrbit { Geo, Igso, Meo };
BeiDouOrbit beidouOrbit(int prn);
inline bool isBeiDouGeo(SatId s) {
  return s.system == System::BeiDou && beidouOrbit(s.prn) == BeiDouOrbit::Geo;
}

}  // namespace gvins

template <>
struct std::hash<gvins::SatId> {
  std::size_t operator()(gvins::SatId s) const noexcept {
    return (static_cast<std::size_t>(s.system) << 8) | s.prn;
  }
};
