// What each u-blox gnssId/sigId of RXM-SFRBX carries (u-blox F9 HPG 1.32 and X20 HPG 2.00
// interface descriptions, "Signal identifiers"; the message of each signal from the system ICDs)
// and whether NavigationAssembler decodes it.
#include "gvins/ubx/navigation_assembler.hpp"

namespace gvins::ubx {
namespace {

NavigationSourceInfo decoded(const char* message) { return {message, true}; }
NavigationSourceInfo notDecoded(const char* message) { return {std::string(message) + " (not decoded)", false}; }

}  // namespace

NavigationSourceInfo navigationSourceInfo(const NavigationSource& s) {
  switch (s.gnssId) {
    case 0:  // GPS
      if (s.sigId == 0) return decoded("LNAV");
      if (s.sigId == 3 || s.sigId == 4) return decoded("CNAV (L2C)");
      if (s.sigId == 6 || s.sigId == 7) return decoded("CNAV (L5)");
      break;
    case 1: return notDecoded("SBAS");
    case 2:  // Galileo
      if (s.sigId == 1 || s.sigId == 5) return decoded("I/NAV");
      if (s.sigId == 3 || s.sigId == 4) return notDecoded("F/NAV");
      if (s.sigId >= 8 && s.sigId <= 10) return notDecoded("E6 C/NAV");
      break;
    case 3:  // BeiDou: D1 on MEO/IGSO, D2 on GEO satellites, whatever the sigId says
      if (s.sigId <= 4 || s.sigId == 10) return s.beidouGeo ? decoded("D2 (GEO)") : decoded("D1 (MEO/IGSO)");
      if (s.sigId == 5 || s.sigId == 6) return notDecoded("B-CNAV1");
      if (s.sigId == 7 || s.sigId == 8) return notDecoded("B-CNAV2");
      break;
    case 5:  // QZSS
      if (s.sigId == 0) return decoded("LNAV");
      if (s.sigId == 1) return notDecoded("L1S SLAS");
      if (s.sigId == 4 || s.sigId == 5) return decoded("CNAV (L2C)");
      if (s.sigId == 8 || s.sigId == 9) return decoded("CNAV (L5)");
      break;
    case 6:  // GLONASS
      if (s.sigId == 0 || s.sigId == 2) return decoded("strings");
      break;
    case 7: return notDecoded("NavIC");
    default: return notDecoded("unknown gnssId");
  }
  return notDecoded("unknown signal");
}

}  // namespace gvins::ubx
