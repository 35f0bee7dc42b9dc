// Broadcast group delays per signal.
#include "gvins/base/signal.hpp"
#include "gvins/ephemeris/satellite_state.hpp"

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

}  // namespace

double broadcastGroupDelay(const KeplerEphemeris& eph, ObsCode code) {
  switch (eph.message) {
    case NavMessage::GpsLnav:
    case NavMessage::QzssLnav: {
      // The LNAV clock refers to the L1/L2 P(Y) ionosphere-free combination: L1 removes T_GD and
      // L2 γ12 T_GD (IS-GPS-200N 20.3.3.3.3.2; L2C as L2 P(Y), without CNAV's ISC_L2C). L5 removes
      // T_GD − ISC_L5 (IS-GPS-705J 20.3.3.3.1.2.1: ISC_L5 = t_L1P(Y) − t_L5 is a measured
      // hardware offset, not a frequency scaling of T_GD), so without CNAV's ISC it removes T_GD,
      // and the L1/L5 ionosphere-free pair removes T_GD as IS-GPS-705J 20.3.3.3.1.2.3 writes it.
      // L1C likewise (IS-GPS-800J 3.5.3.9: T_GD − ISC_L1C). QZSS LNAV follows the same rules
      // (IS-QZSS-PNT-005).
      const System sys = eph.sat.system;
      if (code.band == '1' || code.band == '5') return eph.tgd[0];
      if (code.band == '2') return gammaOf(sys, '1', '2') * eph.tgd[0];
      return 0.0;
    }
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
