// Precise product files among a tool's inputs: told apart by name (as RTKLIB's tools do) and read
// into one PreciseEphemeris, and the ANTEX files that go with them.
#pragma once

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "gvins/ephemeris/antex.hpp"
#include "gvins/ephemeris/bias_sinex.hpp"
#include "gvins/ephemeris/precise_ephemeris.hpp"

namespace gvins {

enum class PreciseFileKind { kOrbit, kClock, kAntenna, kBias, kOther };

/// By the file name, case-insensitive, a trailing ".gz" ignored: "*.sp3" (also the IGS long names
/// "*_ORB.SP3") orbits, "*.clk" / "*.clk_30s" clocks, "*.atx" ANTEX antenna files, "*.bia" /
/// "*.bsx" Bias-SINEX code biases, anything else kOther.
PreciseFileKind preciseFileKind(std::string_view path);

/// Product files sorted by kind (preciseFileKind), in the order given.
struct PreciseProductFiles {
  std::vector<std::string> orbits, clocks, antennas, biases;
  /// Files a tool was given: a product file goes into its list (true); anything else is left to
  /// the caller (false).
  bool add(const std::string& path);
};

/// Reads the orbit files, then the clock files (which take precedence over SP3 clocks) into one
/// PreciseEphemeris. Throws ParseError (file, line, field) for a malformed file.
std::shared_ptr<PreciseEphemeris> readPreciseProducts(const std::vector<std::string>& orbitFiles,
                                                      const std::vector<std::string>& clockFiles);

/// Reads ANTEX files into one AntexData (antennas in file order; for EphemerisStore::
/// setSatelliteAntennas). Throws ParseError for a malformed file.
std::shared_ptr<AntexData> readAntennaFiles(const std::vector<std::string>& files);

/// Reads Bias-SINEX files into one BiasSinexData (entries in file order; for EphemerisStore::
/// setCodeBiases). Throws ParseError for a malformed file.
std::shared_ptr<BiasSinexData> readCodeBiasFiles(const std::vector<std::string>& files);

}  // namespace gvins
