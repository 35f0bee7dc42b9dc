// NMEA 0183 (v4.11) output of position solutions: GGA (fix data) and RMC (recommended minimum)
// sentences, as receivers and RTKLIB write them and as NTRIP VRS casters expect the rover's
// position. Facts from NMEA 0183 v4.11:
//   - a sentence is "$" + talker (2) + type (3) + ",fields" + "*" + two upper-case hex digits of
//     the XOR of every character between '$' and '*', then CR LF (5.2.1, 5.3);
//   - latitude "ddmm.mmmmmmm",N|S and longitude "dddmm.mmmmmmm",E|W (here 7 decimals of a
//     minute: 0.19 mm);
//   - times are UTC "hhmmss.ss", RMC dates "ddmmyy";
//   - GGA quality indicator: 0 invalid, 1 autonomous (SPP), 2 differential (DGNSS, SBAS), 4 RTK
//     fixed, 5 RTK float; RMC mode indicator: N, A, D, R (fixed), F (float); RMC status A/V and
//     the v4.1 navigational status S (safe) / V (not valid).
// Heights: without a geoid model the GGA altitude is the ellipsoidal height and the geoid
// separation 0.0, so that altitude + separation is the ellipsoidal height in any reader.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <optional>
#include <string>
#include <string_view>

#include "gvins/gnss/position_solution.hpp"

namespace gvins {

/// What a sentence needs beyond the PositionSolution.
struct NmeaExtras {
  std::optional<double> hdop;      ///< horizontal dilution of precision (empty field if unknown)
  std::optional<int> stationId;    ///< differential reference station id, 0-1023
};

struct NmeaOptions {
  std::string talker = "GN";  ///< "GN": several constellations (NMEA 4.x); "GP": GPS only
  bool gga = true;
  bool rmc = true;
};

/// XOR of the characters of `body` (the text between '$' and '*').
unsigned nmeaChecksum(std::string_view body);
/// "$" + body + "*HH\r\n".
std::string nmeaSentence(std::string_view body);
/// GGA quality indicator of a solution quality (0, 1, 2, 4, 5; PPP counts as float, 5).
int nmeaGgaQuality(SolutionQuality q);
/// RMC/GNS mode indicator letter (N, A, D, R, F).
char nmeaModeIndicator(SolutionQuality q);
/// The GGA sentence of a solution (CR LF included). Age and station id are written only for
/// differential qualities (2, 4, 5). An invalid solution (quality None) gives the
/// time and empty position fields with quality 0.
std::string nmeaGga(const PositionSolution& s, const NmeaExtras& extras = {}, std::string_view talker = "GN");
/// The RMC sentence of a solution (CR LF included): speed over ground (knots) and course over
/// ground (degrees true) from the velocity when present, else empty.
std::string nmeaRmc(const PositionSolution& s, std::string_view talker = "GN");

/// Writes GGA and/or RMC per solution and flushes after each epoch (live outputs).
class NmeaWriter {
 public:
  explicit NmeaWriter(std::ostream& out, NmeaOptions options = {});
  void write(const PositionSolution& s, const NmeaExtras& extras = {});
  std::int64_t sentences() const { return sentences_; }

 private:
  std::ostream& out_;
  NmeaOptions opt_;
  std::int64_t sentences_ = 0;
};

}  // namespace gvins
