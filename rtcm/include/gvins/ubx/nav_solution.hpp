// The receiver's own navigation outputs that the UBX input uses: UBX-NAV-PVT (0x01 0x07, position,
// velocity, time), UBX-NAV-CLOCK (0x01 0x22, receiver clock bias and drift) and UBX-NAV-TIMEGPS
// (0x01 0x20, GPS week and leap seconds). Field layouts from the u-blox ZED-F9P HPG 1.32 / X20
// HPG 2.00 interface descriptions. Used by `gvins-ubx info`, by `gvins-ubx to-pos` (the
// receiver's own solutions as a .pos file) and to learn the week and the leap seconds; never as a
// measurement.
#pragma once

#include <cstdint>
#include <optional>
#include <span>

#include "gvins/base/gnss_time.hpp"

namespace gvins::ubx {

inline constexpr std::uint8_t kClassNav = 0x01;
inline constexpr std::uint8_t kIdNavPvt = 0x07;
inline constexpr std::uint8_t kIdNavTimeGps = 0x20;
inline constexpr std::uint8_t kIdNavClock = 0x22;

struct NavPvt {
  std::uint32_t iTow = 0;  ///< GPS time of week of the navigation epoch, ms (rounded to the ms)
  int year = 0, month = 0, day = 0, hour = 0, minute = 0, second = 0;  ///< UTC
  std::int32_t nano = 0;   ///< fraction of the second, ns (-1e9..1e9)
  std::uint8_t valid = 0;  ///< bit 0 validDate, 1 validTime, 2 fullyResolved
  double tAcc = 0.0;       ///< time accuracy estimate, s
  std::uint8_t fixType = 0;  ///< 0 none, 1 dead reckoning, 2 2D, 3 3D, 4 GNSS+DR, 5 time only
  std::uint8_t flags = 0;    ///< bit 0 gnssFixOK, bit 1 diffSoln; bits 6-7 carrSoln (1 float, 2 fixed)
  std::uint8_t numSv = 0;
  double lonDeg = 0.0, latDeg = 0.0;  ///< degrees
  double height = 0.0;                ///< above the ellipsoid, m
  double hMsl = 0.0;                  ///< above mean sea level (the receiver's geoid model), m
  double hAcc = 0.0, vAcc = 0.0;      ///< horizontal and vertical accuracy estimates, m
  double velN = 0.0, velE = 0.0, velD = 0.0;  ///< m/s
  double sAcc = 0.0;                  ///< speed accuracy estimate, m/s
  double pDop = 0.0;
  bool fixOk() const { return flags & 1; }
  bool differential() const { return flags & 2; }
  int carrierSolution() const { return (flags >> 6) & 3; }
  bool timeValid() const { return (valid & 3) == 3; }
  bool fullyResolved() const { return valid & 4; }
};

/// What a NAV-PVT epoch claims to be, from fixType and flags.
enum class NavPvtSolution {
  None,          ///< gnssFixOK not set, or fixType 0 (no fix), 1 (dead reckoning only), 5 (time only)
  TwoD,          ///< fixType 2: the height is held, not measured
  Single,        ///< 3D fix (fixType 3, or 4 = GNSS + dead reckoning) without corrections
  Differential,  ///< 3D fix with differential corrections (diffSoln; RTCM code or SBAS)
  RtkFloat,      ///< carrSoln 1: carrier-phase solution with float ambiguities
  RtkFixed,      ///< carrSoln 2: carrier-phase solution with fixed ambiguities
};
NavPvtSolution navPvtSolution(const NavPvt& p);

/// GPST of a time of week (s) in the GPS week that puts it nearest to `near` (another GPST the
/// stream carries, e.g. the latest RXM-RAWX epoch), so that a week rollover between the two
/// still gives the right week. `tow` must be in [0, 604800).
GpsTime timeOfWeekNear(double tow, const GpsTime& near);

/// GPST from NAV-PVT's own UTC date and time (with the nanoseconds) through the leap-second
/// table, when validDate, validTime and fullyResolved are set; nullopt otherwise. Only a fallback
/// for picking the week of iTOW when the stream carries no RXM-RAWX and no NAV-TIMEGPS.
std::optional<GpsTime> navPvtUtcAsGpst(const NavPvt& p);

struct NavClock {
  std::uint32_t iTow = 0;  ///< ms
  double biasS = 0.0;      ///< receiver clock bias, s
  double driftSps = 0.0;   ///< receiver clock drift, s/s
  double timeAccS = 0.0, freqAccSps = 0.0;
};

struct NavTimeGps {
  std::uint32_t iTow = 0;  ///< ms
  std::int32_t fTow = 0;   ///< ns, -500000..500000
  std::int16_t week = 0;
  std::int8_t leapS = 0;
  std::uint8_t valid = 0;  ///< bit 0 towValid, 1 weekValid, 2 leapSValid
  bool weekValid() const { return valid & 2; }
  bool leapValid() const { return valid & 4; }
};

/// Parsers; each throws rtcm::MessageError naming the field if the payload is too short or a
/// field is out of range (NAV-PVT: iTOW not a time of week, a calendar field flagged valid but
/// impossible, latitude or longitude outside their ranges, the reserved carrSoln 3).
NavPvt parseNavPvt(std::span<const std::uint8_t> payload);
NavClock parseNavClock(std::span<const std::uint8_t> payload);
NavTimeGps parseNavTimeGps(std::span<const std::uint8_t> payload);

}  // namespace gvins::ubx
