// Broadcast group delays per signal.
#include "gvins/base/signal.hpp"
#include "gvins/ephemeris/satellite_state.hpp"

#include <optional>

namespace gvins {
namespace {

// (f_a / f_b)^2 for two bands of a system; 0 if either frequency is unknown.
double gammaOf(System sys, char bandA, char bandB) {
  const auto fa = carrierFrequency(sys, bandA);
  const auto fb = carrierFrequency(sys, bandB);
  if (!fa || !fb) return 0.0;
  const double r = *fa / *fb;
  return r * r;
}

// GPS/QZSS (IS-QZSS-PNT-005 follows the same rules). The LNAV and the CNAV clocks both refer to
// the L1/L2 P(Y) ionosphere-free pair (IS-GPS-200N 20.3.3.3.3.2, 30.3.3.2.3): L1 P(Y) removes T_GD
// and L2 P(Y) γ12 T_GD. Every other signal x is referred to L1 P(Y) by its inter-signal
// correction ISC_x = t_L1P(Y) − t_x of CNAV message type 30 (IS-GPS-200N 30.3.3.3.1.1.1,
// IS-GPS-705J 20.3.3.3.1.2.1), so it removes T_GD − ISC_x — L2C too: ISC_L2C is referred to
// L1 P(Y), not to L2 P(Y), and (Δt_SV)L2C = Δt_SV − T_GD + ISC_L2C:
//   L1 C/A: T_GD − ISC_L1C/A;  L2C: T_GD − ISC_L2C;  L5 I5: T_GD − ISC_L5I5;  L5 Q5: T_GD − ISC_L5Q5.
// An ionosphere-free pair combines these per-signal delays: (γ D1 − D2)/(γ − 1) =
// T_GD + (ISC_2 − γ ISC_L1C/A)/(γ − 1), which is the − c T_GD and c (ISC_2 − γ ISC_L1C/A)/(1 − γ)
// of the ICDs' pair formulas (IS-GPS-200N 30.3.3.3.1.1.2 with γ12 for L1 C/A + L2C,
// IS-GPS-705J 20.3.3.3.1.2.3 with γ15 for L1 C/A + L5).
// L5 I+Q tracking (5X) takes the mean of the I5 and Q5 corrections (a model choice: the two
// components are sent with equal power; the ICDs give no ISC for the sum).
// Without a CNAV message (or where it says "not available"): L1 C/A and L1C remove T_GD
// (IS-GPS-800J 3.5.3.9: T_GD − ISC_L1C, its ISC only in CNAV-2), L2C γ12 T_GD as L2 P(Y), and L5
// T_GD — not a frequency scaling of T_GD, as ISC_L5 is a measured hardware offset. T_GD: the CNAV
// message's own (2^-35 s steps against LNAV's 2^-31 s) when it has one.
double gpsGroupDelay(const KeplerEphemeris& eph, ObsCode code, const CnavGroupDelays* cnav) {
  if (cnav && cnav->sat != eph.sat) cnav = nullptr;
  const double tgd = cnav && cnav->tgd ? *cnav->tgd : eph.tgd[0];
  std::optional<double> isc;
  if (cnav) {
    const char a = code.attr;
    if (code.band == '1' && a == 'C') isc = cnav->iscL1ca;
    if (code.band == '2' && (a == 'S' || a == 'L' || a == 'X')) isc = cnav->iscL2c;
    if (code.band == '5' && a == 'I') isc = cnav->iscL5i5;
    if (code.band == '5' && a == 'Q') isc = cnav->iscL5q5;
    if (code.band == '5' && a == 'X' && cnav->iscL5i5 && cnav->iscL5q5) isc = 0.5 * (*cnav->iscL5i5 + *cnav->iscL5q5);
  }
  if (isc) return tgd - *isc;
  switch (code.band) {
    case '1':
    case '5': return tgd;
    case '2': return gammaOf(eph.sat.system, '1', '2') * tgd;
    default: return 0.0;
  }
}

}  // namespace

double broadcastGroupDelay(const KeplerEphemeris& eph, ObsCode code, const CnavGroupDelays* cnav) {
  switch (eph.message) {
    case NavMessage::GpsLnav:
    case NavMessage::QzssLnav:
      return gpsGroupDelay(eph, code, cnav);
    case NavMessage::GalileoInav:
    case NavMessage::GalileoFnav: {
      // Satellite hardware delays b1, b5 (E5a), b7 (E5b). BGD(E1,E5a) = (b5 - b1)/(g15 - 1),
      // BGD(E1,E5b) = (b7 - b1)/(g17 - 1) with gij = (fi/fj)^2 (OS SIS ICD 2.1 5.1.5). I/NAV
      // clocks refer to the E1/E5b and F/NAV clocks to the E1/E5a ionosphere-free combination, so
      // the delay on band k relative to the clock is T_k = b_k - (g b1 - b_ref)/(g - 1):
      //   I/NAV: E1 BGD17, E5b g17 BGD17, E5a BGD17 + (g15 - 1) BGD15;
      //   F/NAV: E1 BGD15, E5a g15 BGD15, E5b BGD15 + (g17 - 1) BGD17.
      const double bgd15 = eph.tgd[0], bgd17 = eph.tgd[1];
      const double g15 = gammaOf(System::Galileo, '1', '5');
      const double g17 = gammaOf(System::Galileo, '1', '7');
      const bool inav = eph.message == NavMessage::GalileoInav;
      switch (code.band) {
        case '1': return inav ? bgd17 : bgd15;
        case '5': return inav ? bgd17 + (g15 - 1.0) * bgd15 : g15 * bgd15;
        case '7': return inav ? g17 * bgd17 : bgd15 + (g17 - 1.0) * bgd17;
        default: return 0.0;  // E5 AltBOC, E6: no broadcast group delay in I/NAV or F/NAV
      }
    }
    case NavMessage::BeiDouD1:
    case NavMessage::BeiDouD2:
      // D1/D2 clocks refer to B3I; TGD1 is the B1I and TGD2 the B2I delay relative to B3I
      // (BDS-SIS-ICD-B1I 3.0, 5.2.4 and 5.3.3). B1I is band 2 (RINEX 3.03+; normalizeObsCode maps RINEX
      // 3.02 codes), or the unambiguous 3.02 codes 1I/1Q; 1X/1D/1P are B1C, whose delay is only in
      // CNAV1. B2I is band 7 with I/Q/X (B2b, 7D/7P/7Z, has no D1/D2 delay).
      if (code.band == '2') return eph.tgd[0];
      if (code.band == '1' && (code.attr == 'I' || code.attr == 'Q')) return eph.tgd[0];
      if (code.band == '7' && (code.attr == 'I' || code.attr == 'Q' || code.attr == 'X')) return eph.tgd[1];
      return 0.0;
  }
  return 0.0;
}

double broadcastGroupDelay(const GlonassEphemeris& eph, ObsCode code) {
  return code.band == '2' ? eph.deltaTauN : 0.0;
}

}  // namespace gvins
