#include "gvins/rtcm/msm_signals.hpp"

#include <array>

namespace gvins::rtcm {
namespace {

// Attribute letters per signal ID 1..32 (index 0 = ID 1); ' ' = reserved. Band digit alongside.
struct Entry {
  char band;
  char attr;
};
using Table = std::array<Entry, 32>;

constexpr Entry R{' ', ' '};

// RTCM 10403.3 table 3.5-91: GPS. 2 L1 C/A, 3 L1 P, 4 L1 Z-tracking, 8 L2 C/A, 9 L2 P,
// 10 L2 Z-tracking, 15 L2C(M), 16 L2C(L), 17 L2C(M+L), 22 L5 I, 23 L5 Q, 24 L5 I+Q,
// 30 L1C-D, 31 L1C-P, 32 L1C-D+P.
constexpr Table kGps = {R,        {'1', 'C'}, {'1', 'P'}, {'1', 'W'}, R, R, R, {'2', 'C'},
                        {'2', 'P'}, {'2', 'W'}, R, R, R, R, {'2', 'S'}, {'2', 'L'},
                        {'2', 'X'}, R, R, R, R, {'5', 'I'}, {'5', 'Q'}, {'5', 'X'},
                        R, R, R, R, R, {'1', 'S'}, {'1', 'L'}, {'1', 'X'}};
// Table 3.5-96: GLONASS. 2 G1 C/A, 3 G1 P, 8 G2 C/A, 9 G2 P.
constexpr Table kGlonass = {R, {'1', 'C'}, {'1', 'P'}, R, R, R, R, {'2', 'C'}, {'2', 'P'}, R,
                            R, R, R, R, R, R, R, R, R, R, R, R, R, R, R, R, R, R, R, R, R, R};
// Table 3.5-99: Galileo. 2 E1 C, 3 E1 A, 4 E1 B, 5 E1 B+C, 6 E1 A+B+C, 8 E6 C, 9 E6 A, 10 E6 B,
// 11 E6 B+C, 12 E6 A+B+C, 14 E5b I, 15 E5b Q, 16 E5b I+Q, 18 E5(a+b) I, 19 E5 Q, 20 E5 I+Q,
// 22 E5a I, 23 E5a Q, 24 E5a I+Q.
constexpr Table kGalileo = {R,          {'1', 'C'}, {'1', 'A'}, {'1', 'B'}, {'1', 'X'},
                            {'1', 'Z'}, R,          {'6', 'C'}, {'6', 'A'}, {'6', 'B'},
                            {'6', 'X'}, {'6', 'Z'}, R,          {'7', 'I'}, {'7', 'Q'},
                            {'7', 'X'}, R,          {'8', 'I'}, {'8', 'Q'}, {'8', 'X'},
                            R,          {'5', 'I'}, {'5', 'Q'}, {'5', 'X'}, R, R, R, R, R, R, R, R};
// Table 3.5-102: SBAS. 2 L1 C/A, 22 L5 I, 23 L5 Q, 24 L5 I+Q.
constexpr Table kSbas = {R, {'1', 'C'}, R, R, R, R, R, R, R, R, R, R, R, R, R, R, R, R, R, R, R,
                         {'5', 'I'}, {'5', 'Q'}, {'5', 'X'}, R, R, R, R, R, R, R, R};
// Table 3.5-105: QZSS. 2 L1 C/A, 9 LEX S, 10 LEX L, 11 LEX S+L, 15 L2C(M), 16 L2C(L),
// 17 L2C(M+L), 22 L5 I, 23 L5 Q, 24 L5 I+Q, 30 L1C-D, 31 L1C-P, 32 L1C-D+P.
constexpr Table kQzss = {R,          {'1', 'C'}, R,          R,          R,          R,
                         R,          R,          {'6', 'S'}, {'6', 'L'}, {'6', 'X'}, R,
                         R,          R,          {'2', 'S'}, {'2', 'L'}, {'2', 'X'}, R,
                         R,          R,          R,          {'5', 'I'}, {'5', 'Q'}, {'5', 'X'},
                         R,          R,          R,          R,          R,          {'1', 'S'},
                         {'1', 'L'}, {'1', 'X'}};
// Table 3.5-108: BeiDou. 2 B1I, 3 B1Q, 4 B1 I+Q, 8 B3I, 9 B3Q, 10 B3 I+Q, 14 B2I, 15 B2Q,
// 16 B2 I+Q; amendment 1: 22 B2a data, 23 B2a pilot, 24 B2a D+P, 25 B2b data, 30 B1C data,
// 31 B1C pilot, 32 B1C D+P. RINEX 3.04 numbering: B1I band 2, B3 band 6, B2I/B2b band 7,
// B2a band 5, B1C band 1.
constexpr Table kBeiDou = {R,          {'2', 'I'}, {'2', 'Q'}, {'2', 'X'}, R,          R,
                           R,          {'6', 'I'}, {'6', 'Q'}, {'6', 'X'}, R,          R,
                           R,          {'7', 'I'}, {'7', 'Q'}, {'7', 'X'}, R,          R,
                           R,          R,          R,          {'5', 'D'}, {'5', 'P'}, {'5', 'X'},
                           {'7', 'D'}, R,          R,          R,          R,          {'1', 'D'},
                           {'1', 'P'}, {'1', 'X'}};
// NavIC MSM (1131-1137) is not decoded: no signal is mapped.
constexpr Table kNavic = {R, R, R, R, R, R, R, R, R, R, R, R, R, R, R, R,
                          R, R, R, R, R, R, R, R, R, R, R, R, R, R, R, R};

const Table& tableOf(System s) {
  switch (s) {
    case System::Gps: return kGps;
    case System::Glonass: return kGlonass;
    case System::Galileo: return kGalileo;
    case System::Sbas: return kSbas;
    case System::Qzss: return kQzss;
    case System::BeiDou: return kBeiDou;
    case System::Navic: return kNavic;
  }
  return kGps;
}

}  // namespace

std::optional<ObsCode> msmSignalCode(System system, int signalId) {
  if (signalId < 1 || signalId > 32) return std::nullopt;
  const Entry e = tableOf(system)[static_cast<std::size_t>(signalId - 1)];
  if (e.band == ' ') return std::nullopt;
  return ObsCode{e.band, e.attr};
}

std::optional<int> msmSignalId(System system, ObsCode code) {
  const Table& t = tableOf(system);
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (t[i].band == code.band && t[i].attr == code.attr) return static_cast<int>(i) + 1;
  }
  return std::nullopt;
}

std::optional<SatId> msmSatellite(System system, int satId) {
  if (satId < 1 || satId > 64) return std::nullopt;
  SatId s;
  switch (system) {
    case System::Sbas: s = SatId(System::Sbas, satId + 19); break;  // PRN 120 + ID - 1 = S(20 + ID - 1)
    default: s = SatId(system, satId); break;
  }
  if (!s.valid()) return std::nullopt;
  return s;
}

int msmSatelliteId(SatId sat) {
  return sat.system == System::Sbas ? sat.prn - 19 : sat.prn;
}

}  // namespace gvins::rtcm
