// State-space-representation (SSR) corrections to the broadcast ephemerides, as carried by the
// RTCM 3 SSR messages (RTCM 10403.3, section 3.5.12: GPS 1057-1062, GLONASS 1063-1068, Galileo
// 1240-1245, QZSS 1246-1251, SBAS 1252-1257, BeiDou 1258-1263) in engineering units. The RTCM
// decoder and encoder (gvins/rtcm) produce and take these; SsrCorrections (ssr_corrections.hpp)
// applies them to broadcast satellite states.
#pragma once

#include <algorithm>
#include <array>
#include <optional>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "gvins/base/gnss_time.hpp"
#include "gvins/base/satellite.hpp"
#include "gvins/base/signal.hpp"

namespace gvins {

/// What one SSR message carries.
enum class SsrKind {
  kOrbit,          ///< 1057/1063/1240/1246/1252/1258
  kClock,          ///< 1058/1064/1241/1247/1253/1259
  kCodeBias,       ///< 1059/1065/1242/1248/1254/1260
  kCombined,       ///< orbit and clock: 1060/1066/1243/1249/1255/1261
  kUra,            ///< 1061/1067/1244/1250/1256/1262
  kHighRateClock,  ///< 1062/1068/1245/1251/1257/1263
};

/// The SSR update intervals of DF391 (RTCM 10403.3), seconds, by their 4-bit index.
inline constexpr std::array<double, 16> kSsrUpdateIntervals{1,   2,   5,   10,   15,   30,   60,   120,
                                                            240, 300, 600, 900, 1800, 3600, 7200, 10800};
/// True if `seconds` is one of kSsrUpdateIntervals.
inline bool isSsrUpdateInterval(double seconds) {
  return std::find(kSsrUpdateIntervals.begin(), kSsrUpdateIntervals.end(), seconds) != kSsrUpdateIntervals.end();
}

/// Message header (RTCM 10403.3 tables 3.5-73 ... 3.5-78).
struct SsrHeader {
  int messageType = 0;
  System system = System::Gps;
  SsrKind kind = SsrKind::kOrbit;
  /// SSR epoch time (DF385 seconds of the GPS week, DF386 seconds of the GLONASS day; BeiDou in
  /// BDT), resolved to an absolute GPST instant.
  GpsTime epoch;
  /// SSR update interval in seconds (DF391 table: 1, 2, 5, 10, 15, 30, 60, 120, 240, 300, 600, 900,
  /// 1800, 3600, 7200, 10800). The reference time t0 of the correction polynomials is epoch +
  /// updateInterval / 2 (RTCM 10403.3, 3.5.12.3).
  double updateInterval = 1.0;
  bool multipleMessage = false;  ///< DF388: more messages of this type and epoch follow
  bool regionalDatum = false;    ///< DF375 (orbit, combined): false = ITRF, true = regional
  int iodSsr = 0;                ///< DF413
  int providerId = 0;            ///< DF414
  int solutionId = 0;            ///< DF415
};

/// Orbit correction of one satellite in the radial / along-track / cross-track frame of the
/// broadcast orbit (along = velocity direction, cross = r x v, radial = along x cross). The
/// corrected antenna phase centre is X_broadcast - [e_r e_a e_c] (rac + racRate (t - t0)).
struct SsrOrbitCorrection {
  /// Issue of data of the broadcast record the correction refers to: GPS/QZSS IODE (DF071/DF434,
  /// 8 bits), GLONASS IOD (DF392, 8 bits, = the record's tb index), Galileo IODnav (DF459, 10 bits),
  /// BeiDou toe modulo (DF470, 10 bits: (toe mod 8192) / 8).
  int issueOfData = 0;
  int iodCrc = 0;  ///< BeiDou: BDS IOD (DF471, 8 bits: (toe / 720) mod 240); 0 for other systems
  Eigen::Vector3d rac = Eigen::Vector3d::Zero();      ///< m (DF365/DF366/DF367)
  Eigen::Vector3d racRate = Eigen::Vector3d::Zero();  ///< m/s (DF368/DF369/DF370)
};

/// Clock correction δC = c0 + c1 (t - t0) + c2 (t - t0)², in metres: the corrected satellite clock
/// offset is the broadcast one plus δC / c (DF376-DF378; RTCM 10403.3, 3.5.12.3).
struct SsrClockCorrection {
  double c0 = 0.0;  ///< m
  double c1 = 0.0;  ///< m/s
  double c2 = 0.0;  ///< m/s²
};

/// One satellite's part of an SSR message; which members are set depends on the kind.
struct SsrSatellite {
  SatId sat;
  std::optional<SsrOrbitCorrection> orbit;  ///< kOrbit, kCombined
  std::optional<SsrClockCorrection> clock;  ///< kClock, kCombined
  /// kCodeBias: (signal, bias in m). RTCM sign: the bias is *added* to the measured pseudorange
  /// (the opposite of a Bias-SINEX OSB, which is subtracted).
  std::vector<std::pair<ObsCode, double>> codeBiases;
  std::optional<int> uraIndex;          ///< kUra: DF389 (3-bit class, 3-bit value), 0 = undefined
  std::optional<double> highRateClock;  ///< kHighRateClock: DF390, m (added to δC)
};

struct SsrMessage {
  SsrHeader header;
  std::vector<SsrSatellite> satellites;
};

/// SSR URA index (DF389) in metres, as the upper bound of its class/value range (RTCM 10403.3
/// DF389: URA = 3^class (1 + value/4) - 1 mm); nullopt for 0 (undefined) and 63 (> 5466.5 mm).
std::optional<double> ssrUraMetres(int uraIndex);

}  // namespace gvins
