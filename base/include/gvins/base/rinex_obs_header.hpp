// RINEX observation file header (versions 2.10/2.11 and 3.0x), shared by the streaming reader
// and the RINEX 3 writer. Observation columns are always named with RINEX 3 codes ("C1C", "L2W");
// RINEX 2 types are mapped when a file is read (rinex2ObsDescriptor).
#pragma once

#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "gvins/base/gnss_time.hpp"
#include "gvins/base/observation.hpp"
#include "gvins/base/satellite.hpp"
#include "gvins/base/signal.hpp"

namespace gvins {

/// One observation column as RINEX 3 names it: the type letter (C, L, D, S) and the signal code,
/// e.g. "C1C" = pseudorange on L1 C/A, "L2W" = carrier phase on L2 P(Y) semi-codeless.
struct ObsDescriptor {
  ObsType type = ObsType::Code;
  ObsCode code;

  constexpr ObsDescriptor() = default;
  constexpr ObsDescriptor(ObsType t, ObsCode c) : type(t), code(c) {}
  /// Parses a three-character RINEX 3 observation code; nullopt for anything that is not one of
  /// the four value types C/L/D/S followed by band digit and attribute letter (so "X1" channel
  /// numbers and "I1" ionosphere columns are not descriptors).
  static std::optional<ObsDescriptor> parse(std::string_view three);
  std::string str() const { return std::string{static_cast<char>(type), code.band, code.attr}; }

  friend constexpr bool operator==(ObsDescriptor a, ObsDescriptor b) {
    return a.type == b.type && a.code == b.code;
  }
};

/// Maps a RINEX 2.10/2.11 observation type ("C1", "P2", "L1", "D2", "S5", ...) of a satellite
/// system to the RINEX 3 descriptor it denotes. `allTypes` is the file's whole type list: it
/// decides which tracking attribute a phase/Doppler/SNR column belongs to (GPS L1 goes with C/A
/// "1C" when C1 is observed, with P(Y) "1W" when only P1 is; GPS L2 with "2W" when P2 is observed,
/// else with L2C "2X"; GLONASS analogous with C/P). Galileo types map to the combined attribute X
/// (RINEX 2.11 does not say which component was tracked). Returns nullopt for types a system does
/// not have (P1 for Galileo) and for non-measurement types (T1 transit Doppler, unknown letters).
std::optional<ObsDescriptor> rinex2ObsDescriptor(System sys, std::string_view type2,
                                                 const std::vector<std::string>& allTypes);

/// "SYS / PHASE SHIFT" record (RINEX 3.01+): kept so that a file can be rewritten faithfully.
struct PhaseShiftRecord {
  System system = System::Gps;
  std::optional<ObsDescriptor> obs;  ///< blank in the file: none
  std::optional<double> cycles;      ///< blank in the file: none
  std::vector<SatId> satellites;     ///< empty: all satellites of the system
};

/// "GLONASS COD/PHS/BIS" values (RINEX 3.02+), metres; blank fields are nullopt.
struct GlonassCodePhaseBias {
  ObsDescriptor obs;
  std::optional<double> bias;
};

/// Header of an observation file.
struct RinexObsHeader {
  double version = 3.04;
  /// Satellite system field of "RINEX VERSION / TYPE": 'G', 'R', 'E', 'C', 'J', 'S', 'I' or 'M'.
  char fileSystem = 'M';
  std::string program;  ///< "PGM / RUN BY / DATE"
  std::string runBy;
  std::string date;
  StationInfo station;  ///< marker, receiver, antenna, approximate position, antenna delta H/E/N
  std::string markerType;
  std::string observer;
  std::string agency;
  /// Observation columns per system (index systemIndex), in file order, as RINEX 3 descriptors.
  std::array<std::vector<ObsDescriptor>, kNumSystems> obsTypes;
  /// RINEX 2 files: the original type list ("C1", "L1", ...), empty for RINEX 3.
  std::vector<std::string> rinex2Types;
  /// Columns that name no measurement this library stores ("G X1" channel numbers, "R T1",
  /// unknown or duplicated codes); their values are skipped.
  std::vector<std::string> ignoredTypes;
  GlonassChannels glonassChannels;  ///< "GLONASS SLOT / FRQ #"
  std::vector<GlonassCodePhaseBias> glonassBiases;
  std::vector<PhaseShiftRecord> phaseShifts;
  /// Time system of the epochs in the file ("GPS", "GLO", "GAL", "BDT", "QZS", "IRN"); epochs
  /// returned by the reader are always converted to GPST.
  std::string timeSystem = "GPS";
  std::optional<GpsTime> firstObs;  ///< "TIME OF FIRST OBS", GPST
  std::optional<GpsTime> lastObs;   ///< "TIME OF LAST OBS", GPST
  std::optional<double> interval;   ///< s
  std::optional<int> leapSeconds;   ///< "LEAP SECONDS" (GPST - UTC, s)
  bool receiverClockOffsetApplied = false;  ///< "RCV CLOCK OFFS APPL"
  std::string signalStrengthUnit;           ///< e.g. "DBHZ"
  std::vector<std::string> comments;

  const std::vector<ObsDescriptor>& types(System s) const { return obsTypes[systemIndex(s)]; }
  std::vector<ObsDescriptor>& types(System s) { return obsTypes[systemIndex(s)]; }
  /// Whether any column is defined for the system.
  bool hasSystem(System s) const { return !types(s).empty(); }

  /// Adds the descriptors needed to store every value present in an epoch (helper for
  /// converters and simulators that build a header from data): for each signal, the types
  /// present among C, L, D, S, appended to the system's list if not already there.
  void addTypesFrom(const ObsEpoch& epoch);
};

}  // namespace gvins
