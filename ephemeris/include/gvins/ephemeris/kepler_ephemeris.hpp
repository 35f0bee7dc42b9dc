// Broadcast Keplerian ephemeris of GPS/QZSS LNAV, Galileo I/NAV and F/NAV and BeiDou D1/D2.
// Field names follow the ICDs (IS-GPS-200 table 20-III, Galileo OS SIS ICD table 60, BDS-SIS-ICD
// B1I 5.2.4); units are SI (s, m, rad, rad/s), never semi-circles.
#pragma once

#include <array>
#include <cstdint>

#include "gvins/base/gnss_time.hpp"
#include "gvins/base/satellite.hpp"

namespace gvins {

/// Which navigation message a Keplerian record came from. Galileo I/NAV and F/NAV carry
/// different clock parameters (E1-E5b vs E1-E5a) and are kept apart.
enum class NavMessage : std::uint8_t {
  GpsLnav,
  QzssLnav,
  GalileoInav,
  GalileoFnav,
  BeiDouD1,  ///< MEO/IGSO
  BeiDouD2,  ///< GEO
};

struct KeplerEphemeris {
  SatId sat;
  NavMessage message = NavMessage::GpsLnav;

  // Reference times as GPST instants (BeiDou's are converted from BDT: BDT + 14 s).
  GpsTime toe;  ///< ephemeris reference time
  GpsTime toc;  ///< clock reference time
  GpsTime ttr;  ///< transmission time of the message (RINEX "transmission time of message")
  double toeSeconds = 0.0;  ///< toe as seconds of the system's own week (GPS/GST/BDT)
  int week = 0;             ///< full week number in the system's own week count (GPS, GST, BDT)

  // Issue of data.
  int iode = 0;  ///< GPS/QZSS IODE; Galileo IODnav; BeiDou AODE
  int iodc = 0;  ///< GPS/QZSS IODC; BeiDou AODC; Galileo: unused (= iode)

  // Health and accuracy.
  int health = 0;       ///< SV health word as broadcast (GPS 6 bits; Galileo: RINEX bit field of
                        ///< E1B/E5a/E5b DVS+HS; BeiDou SatH1)
  double ura = 0.0;     ///< user range accuracy / SISA, m (RINEX "SV accuracy")
  int codesOnL2 = 0;    ///< GPS: codes on L2; Galileo: data sources bit field (RINEX)
  int l2pDataFlag = 0;  ///< GPS only
  double fitInterval = 0.0;  ///< hours (GPS/QZSS fit interval; 0 = unknown/4 h)

  // Orbit.
  double sqrtA = 0.0;     ///< m^(1/2)
  double e = 0.0;
  double i0 = 0.0;        ///< rad
  double omega0 = 0.0;    ///< rad, longitude of ascending node at weekly epoch
  double omega = 0.0;     ///< rad, argument of perigee
  double m0 = 0.0;        ///< rad, mean anomaly at toe
  double deltaN = 0.0;    ///< rad/s
  double omegaDot = 0.0;  ///< rad/s
  double iDot = 0.0;      ///< rad/s
  double cuc = 0.0, cus = 0.0;  ///< rad
  double crc = 0.0, crs = 0.0;  ///< m
  double cic = 0.0, cis = 0.0;  ///< rad

  // Clock.
  double af0 = 0.0;  ///< s
  double af1 = 0.0;  ///< s/s
  double af2 = 0.0;  ///< s/s^2

  /// Group delays, s. GPS/QZSS: [0] = TGD (L1 P(Y)/L1 C/A). Galileo: [0] = BGD E1/E5a,
  /// [1] = BGD E1/E5b. BeiDou: [0] = TGD1 (B1I/B3I), [1] = TGD2 (B2I/B3I).
  std::array<double, 2> tgd{0.0, 0.0};
};

/// Whether the record's health word allows use of the satellite for the signals the message serves:
/// GPS all six LNAV health bits zero (IS-GPS-200N 20.3.3.3.1.4); QZSS the five bits other than
/// the L1C/B flag (LSB) zero (IS-QZSS-PNT-005, LNAV SV health);
/// Galileo I/NAV: E1-B and E5b DVS/HS bits zero, F/NAV: E5a DVS/HS bits zero (RINEX 3.04 table A8
/// bit layout, OS SIS ICD 2.1 5.1.9.3); BeiDou SatH1 = 0 (BDS-SIS-ICD-B1I 3.0, 5.2.4).
bool isHealthy(const KeplerEphemeris& eph);

/// Galileo message type implied by a RINEX "data sources" bit field (RINEX 3.04 table A8):
/// bit 9 (clock for E5b,E1) or bits 0/2 (I/NAV E1-B / E5b-I) mean I/NAV; bit 8 (clock for
/// E5a,E1) or bit 1 (F/NAV E5a-I) mean F/NAV. Bit 9 wins over bit 8 when a writer sets both;
/// an empty field (0) is taken as I/NAV, the message every Galileo receiver decodes.
NavMessage galileoMessageFromDataSources(int dataSources);

}  // namespace gvins
