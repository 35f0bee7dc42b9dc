// What each u-blox gnssId/sigId of RXM-SFRBX carries (u-blox F9 HPG 1.32 and X20 HPG 2.00
// interface descriptions, "Signal identifiers"; the message of each signal from the system ICDs)
// and which decoder of NavigationAssembler takes it. The assembler routes by this table.
#include "gvins/ubx/navigation_assembler.hpp"

namespace gvins::ubx {
namespace {

struct SourceEntry {
  const char* message;
  NavigationDecoder decoder;
};

SourceEntry decoded(const char* message, NavigationDecoder decoder) { return {message, decoder}; }
SourceEntry notDecoded(const char* message) { return {message, NavigationDecoder::None}; }

SourceEntry sourceEntry(const NavigationSource& s) {
  using D = NavigationDecoder;
  switch (s.gnssId) {
    case 0:  // GPS: L1 C/A LNAV; L2 CL/CM (sigId 3, 4) and L5 I/Q (6, 7) CNAV
      if (s.sigId == 0) return decoded("LNAV", D::Lnav);
      if (s.sigId == 3 || s.sigId == 4) return decoded("CNAV (L2C)", D::Cnav);
      if (s.sigId == 6 || s.sigId == 7) return decoded("CNAV (L5)", D::Cnav);
      break;
    case 1: return notDecoded("SBAS");
    case 2:  // Galileo: I/NAV on E1-B (sigId 1) and E5b-I (5)
      if (s.sigId == 1 || s.sigId == 5) return decoded("I/NAV", D::GalileoInav);
      if (s.sigId == 3 || s.sigId == 4) return notDecoded("F/NAV");
      if (s.sigId >= 8 && s.sigId <= 10) return notDecoded("E6 C/NAV");
      break;
    case 3:  // BeiDou B1I, B2I, B3I: D1 on MEO/IGSO, D2 on GEO satellites, whatever the sigId says
      if (s.sigId <= 4 || s.sigId == 10) return s.beidouGeo ? decoded("D2 (GEO)", D::BeidouD2) : decoded("D1 (MEO/IGSO)", D::BeidouD1);
      if (s.sigId == 5 || s.sigId == 6) return notDecoded("B-CNAV1");
      if (s.sigId == 7 || s.sigId == 8) return notDecoded("B-CNAV2");
      break;
    case 5:  // QZSS: L1 C/A LNAV; L2 CM/CL (sigId 4, 5) and L5 I/Q (8, 9) CNAV
      if (s.sigId == 0) return decoded("LNAV", D::Lnav);
      if (s.sigId == 1) return notDecoded("L1S SLAS");
      if (s.sigId == 4 || s.sigId == 5) return decoded("CNAV (L2C)", D::Cnav);
      if (s.sigId == 8 || s.sigId == 9) return decoded("CNAV (L5)", D::Cnav);
      break;
    case 6:  // GLONASS L1 OF, L2 OF
      if (s.sigId == 0 || s.sigId == 2) return decoded("strings", D::GlonassStrings);
      break;
    case 7: return notDecoded("NavIC");
    default: return notDecoded("unknown gnssId");
  }
  return notDecoded("unknown signal");
}

}  // namespace

NavigationDecoder navigationDecoder(const NavigationSource& source) { return sourceEntry(source).decoder; }

NavigationSourceInfo navigationSourceInfo(const NavigationSource& source) {
  const SourceEntry e = sourceEntry(source);
  if (e.decoder == NavigationDecoder::None) return {std::string(e.message) + " (not decoded)", false};
  return {e.message, true};
}

}  // namespace gvins::ubx
