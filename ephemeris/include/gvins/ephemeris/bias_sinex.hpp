// GNSS code and phase biases in the Bias-SINEX format (S. Schaer, "SINEX BIAS - Solution
// (Software/technique) INdependent EXchange Format for GNSS Biases, Version 1.00", IGS, 2016): the
// observable-specific biases (OSB) and differential biases (DSB) that go with precise satellite
// clocks (e.g. CODE/CAS/DLR MGEX products, *.BIA / *.BSX).
//
// Convention (the format's): a bias is what the observable carries, so the corrected observable is
// observed − bias; for code OSBs the IGS clocks refer to the ionosphere-free combination of the
// reference signals (GPS C1W/C2W, Galileo C1C/C5Q, ...) whose OSBs combine to zero. Values are
// converted to seconds (unit "ns") or cycles (unit "cyc", phase biases).
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "gvins/base/gnss_time.hpp"
#include "gvins/base/parse_error.hpp"
#include "gvins/base/satellite.hpp"
#include "gvins/base/signal.hpp"

namespace gvins {

enum class BiasType : std::uint8_t { kOsb, kDsb, kIsb };

/// One line of the +BIAS/SOLUTION block.
struct BiasEntry {
  BiasType type = BiasType::kOsb;
  std::string svn;                 ///< e.g. "G063" (may be empty)
  std::optional<SatId> satellite;  ///< PRN column; nullopt for station-only entries
  std::string station;             ///< 9-character station id, empty for satellite biases
  ObsCode obs1;                    ///< e.g. C1W (the RINEX 3 code without the observation type letter)
  bool phase = false;              ///< OBS1 is a phase observable (L..), value in cycles if unit cyc
  std::optional<ObsCode> obs2;     ///< DSB/ISB: the second observable
  GpsTime start, end;              ///< validity [start, end); a zero end (0000:000:00000) = open
  bool openEnd = false;
  std::string unit;                ///< "ns" or "cyc"
  double value = 0.0;              ///< s for ns entries, cycles for cyc entries
  double sigma = 0.0;              ///< same unit as value; 0 if not given
};

struct BiasSinexData {
  std::string agency;                 ///< from the %=BIA header line
  std::string timeSystem = "G";       ///< BIAS/DESCRIPTION TIME_SYSTEM (G = GPST, default)
  std::vector<BiasEntry> entries;     ///< in file order

  /// Satellite code OSB (s) of `sat` on `code` valid at t (the last matching entry), or nullopt.
  std::optional<double> codeOsb(SatId sat, ObsCode code, const GpsTime& t) const;
  /// Satellite code DSB (s) obs1 − obs2 valid at t; from a DSB entry, else the difference of two
  /// OSBs; nullopt if neither exists.
  std::optional<double> codeDsb(SatId sat, ObsCode obs1, ObsCode obs2, const GpsTime& t) const;
};

/// Parses Bias-SINEX text held in memory; `name` is used in errors. Throws ParseError naming file,
/// line and field for any malformed input (bad header line, a bias line outside +BIAS/SOLUTION,
/// unknown bias type, bad PRN or observable codes, impossible YYYY:DDD:SSSSS times, end before
/// start, unknown units, non-numeric values, a missing -BIAS/SOLUTION or %=END).
BiasSinexData parseBiasSinex(std::string_view text, const std::string& name);
/// Reads a Bias-SINEX file (plain or gzip).
BiasSinexData readBiasSinex(const std::string& path);

}  // namespace gvins
