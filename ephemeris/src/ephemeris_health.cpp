// Health interpretation of broadcast records and the Galileo message type of a RINEX record.
#include "gvins/ephemeris/glonass_ephemeris.hpp"
#include "gvins/ephemeris/kepler_ephemeris.hpp"

namespace gvins {

bool isHealthy(const KeplerEphemeris& eph) {
  switch (eph.message) {
    case NavMessage::GalileoInav:
      // RINEX 3.04 table A8 health bits: 0 E1-B DVS, 1-2 E1-B HS, 6 E5b DVS, 7-8 E5b HS.
      return (eph.health & 0x1C7) == 0;
    case NavMessage::GalileoFnav:
      // Bits 3 E5a DVS, 4-5 E5a HS.
      return (eph.health & 0x038) == 0;
    case NavMessage::QzssLnav:
      // The least significant of the six LNAV health bits flags the L1C/B signal
      // (IS-QZSS-PNT-005, LNAV SV health); QZS-2/3/4 broadcast L1C/A with that bit set (health = 1) while
      // fully usable, so only the other five bits count.
      return (eph.health & 0x3E) == 0;
    default:
      return eph.health == 0;
  }
}

NavMessage galileoMessageFromDataSources(int dataSources) {
  if (dataSources & (1 << 9)) return NavMessage::GalileoInav;
  if (dataSources & (1 << 8)) return NavMessage::GalileoFnav;
  if (dataSources & ((1 << 0) | (1 << 2))) return NavMessage::GalileoInav;
  if (dataSources & (1 << 1)) return NavMessage::GalileoFnav;
  return NavMessage::GalileoInav;
}

bool isHealthy(const GlonassEphemeris& eph) { return eph.health == 0; }

}  // namespace gvins
