// Carrier-phase alignment between the tracking modes of one band.
//
// The signals (tracking modes, RINEX attributes) of one band of a satellite share the carrier but
// not its phase: the components are transmitted in phase quadrature or opposition, so phases
// tracked on different components differ by a quarter or half cycle (e.g. GPS L2C against
// L2 P(Y), Galileo E1-C against E1-B, E5a-Q against E5a-I). A single difference between two
// receivers that tracked different modes carries that fraction of a cycle unless both phases
// refer to the same reference signal.
//
// Conventions of the data sources:
//   - RINEX 3.01 and later ("Phase Cycle Shifts", RINEX 3.04 Table A23 and the header record
//     "SYS / PHASE SHIFT"): the phases of all signals of a band in a file are consistent with the
//     band's reference signal (GPS L1C, L2P, L5I; Galileo E1B, E5aI, E5bI, ...); a converter that
//     shifted phases reports the correction it applied (cycles, aligned = tracked + correction) in
//     the header, and the record is mandatory. A file of version >= 3.01 with a SYS / PHASE SHIFT
//     record of a system is therefore aligned for that system, whatever the values (0.00000 from a
//     receiver that already outputs aligned phases, as Septentrio's sbf2rin states in its header).
//   - RINEX 2.x / 3.00 and 3.01+ files without the record: nothing is stated (Unknown).
//   - RTCM 3 MSM (10403.3, multiple signal messages): the phase ranges of the signals of a band
//     are to be aligned to a common reference, as in RINEX 3.01+ (Aligned); the legacy messages
//     1001-1012 state nothing that a decoder can rely on (Unknown).
//   - A source that delivers the receiver's tracking phases (Raw) is aligned here by adding the
//     Table A23 correction of its signal (alignmentShift).
// Same-code single differences need no correction (the shift is a property of the signal and
// cancels between the receivers; Raw phases are corrected anyway, which is harmless); single
// differences across modes are formed only when both sides are Aligned or Raw.
#pragma once

#include <array>
#include <cstdint>

#include "gvins/base/satellite.hpp"
#include "gvins/base/signal.hpp"

namespace gvins {

struct RinexObsHeader;

enum class PhaseAlignment : std::uint8_t {
  Unknown,  ///< the source does not say whether its phases are aligned across tracking modes
  Aligned,  ///< phases consistent with the band's reference signal (RINEX 3.01+, RTCM MSM)
  Raw,      ///< tracking phases: alignmentShift() must be added to refer them to the reference
};
const char* toString(PhaseAlignment a);

/// Phase alignment of a receiver's data per satellite system.
struct PhaseAlignments {
  std::array<PhaseAlignment, kNumSystems> bySystem{};  // all Unknown

  PhaseAlignment get(System s) const { return bySystem[systemIndex(s)]; }
  void set(System s, PhaseAlignment a) { bySystem[systemIndex(s)] = a; }
  /// Every system the same.
  static PhaseAlignments all(PhaseAlignment a);
};

/// The correction (cycles) that refers the phase tracked on a signal to the reference signal of
/// its band: RINEX 3.04 Table A23 (aligned = tracked + shift). 0 for reference signals and for
/// signals the table does not list.
///   GPS: L1 P/W/N and L1C (S,L,X) +1/4 (reference L1 C/A); L2 C/S/L/X -1/4 (reference L2P);
///        L5 Q -1/4 (reference L5I).
///   GLONASS: L1P, L2P +1/4 (references L1C, L2C); L3 Q +1/4 (reference L3I).
///   Galileo: E1 C +1/2 (reference E1B); E5a, E5b, E5 Q -1/4 (reference I); E6 C -1/2 (reference B).
///   QZSS: L1C S/L/X +1/4 (reference L1 C/A); L5 Q, P -1/4 (reference L5I / L5D).
///   BeiDou: B1I Q, B2I/B2b Q, B3I Q -1/4 (reference I); B1C, B2a, B2b pilots P +1/4 (reference
///           the data component D).
double alignmentShift(System sys, ObsCode code);

/// What a RINEX observation header states (see the file comment): Aligned for each system with a
/// SYS / PHASE SHIFT record in a file of version >= 3.01, else Unknown.
PhaseAlignments phaseAlignmentOf(const RinexObsHeader& header);

}  // namespace gvins
