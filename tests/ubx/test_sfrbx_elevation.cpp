// Internal consistency where neither convbin nor pseudoranges help: the X20P log has no RAWX and
// convbin 2.4.3 decodes none of its Galileo and BeiDou navigation data. Its NAV-SAT messages give
// the elevation and azimuth (integer degrees) the receiver computed for every satellite from its
// own ephemerides. The receiver's position is found from the GPS satellites alone (whose records
// equal convbin's); the Galileo and BeiDou satellites computed from our records must then appear
// where the receiver saw them, within its 1-degree resolution plus the position's uncertainty.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iostream>
#include <map>

#include "gvins/base/constants.hpp"
#include "gvins/base/geodetic.hpp"
#include "gvins/base/local_frame.hpp"
#include "gvins/ephemeris/ephemeris_store.hpp"
#include "sfrbx_log.hpp"

namespace gvins::ubx {
namespace {

struct Seen {
  GpsTime time;
  SatId sat;
  double elevation, azimuth;  // deg
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // from our record (ECEF, m)
  bool have = false;
};

/// Angle (deg) between the direction NAV-SAT gives and the one computed from `sat` at `receiver`.
double angleOff(const Seen& s, const Eigen::Vector3d& satPos, double lat, double lon) {
  const Eigen::Vector3d receiver = geodeticToEcef({lat, lon, 0.0});
  const Eigen::Vector3d los = ecefToEnuRotation(lat, lon) * (satPos - receiver).normalized();
  const double el = s.elevation * constants::kDegToRad, az = s.azimuth * constants::kDegToRad;
  const Eigen::Vector3d seen(std::cos(el) * std::sin(az), std::cos(el) * std::cos(az), std::sin(el));
  return std::acos(std::clamp(los.dot(seen), -1.0, 1.0)) / constants::kDegToRad;
}

TEST(SfrbxElevation, X20pGalileoAndBeidouWhereTheReceiverSawThem) {
  const auto path = testing::dataDir() / "ubx" / "gpsd_ublox-x20p.log";
  const auto log = testing::decodeLog(path);
  EphemerisStore store;
  for (const NavDataUpdate& u : log.updates) u.addTo(store);
  // NAV-SAT (0x0135): iTOW U4 ms, version, numSvs U1 at 5; 12-byte blocks from 8: gnssId, svId,
  // cno, elev I1, azim I2. The week from NAV-TIMEGPS (week I2 at 8).
  const auto bytes = testing::readBytes(path);
  Framer framer;
  framer.feed(bytes);
  framer.finish();
  Frame f;
  int week = 0;
  std::vector<Seen> seen;
  while (framer.next(f)) {
    const std::uint8_t* p = f.payload.data();
    if (f.type() == 0x0120 && f.payload.size() >= 16) week = p[8] | (p[9] << 8);
    if (f.type() != 0x0135 || week == 0 || f.payload.size() < 8) continue;
    std::uint32_t itow;
    std::memcpy(&itow, p, 4);
    const GpsTime t = GpsTime::fromWeekTow(week, itow * 1e-3);
    for (int k = 0; k < p[5] && 8 + 12 * (k + 1) <= static_cast<int>(f.payload.size()); ++k) {
      const std::uint8_t* b = p + 8 + 12 * k;
      const System sys = b[0] == 0 ? System::Gps : b[0] == 2 ? System::Galileo : b[0] == 3 ? System::BeiDou : System::Sbas;
      std::int16_t az;
      std::memcpy(&az, b + 4, 2);
      const auto el = static_cast<std::int8_t>(b[3]);
      if (sys == System::Sbas || el < 5 || el > 85) continue;  // azimuth meaningless near zenith
      seen.push_back({t, SatId(sys, b[1]), static_cast<double>(el), static_cast<double>(az), {}, false});
    }
  }
  for (Seen& s : seen) {
    const auto st = store.satelliteState(s.sat, s.time);
    s.have = st.has_value();
    if (st) s.position = st->position;
  }
  auto rms = [&](System sys, double lat, double lon, int* n = nullptr, double* worst = nullptr) {
    double sum = 0.0;
    int count = 0;
    for (const Seen& s : seen) {
      if (s.sat.system != sys || !s.have) continue;
      const double a = angleOff(s, s.position, lat, lon);
      sum += a * a;
      ++count;
      if (worst) *worst = std::max(*worst, a);
    }
    if (n) *n = count;
    return count ? std::sqrt(sum / count) : 1e9;
  };
  // Receiver position from GPS: a 2-degree grid, then 0.05-degree refinement.
  double bestLat = 0.0, bestLon = 0.0, best = 1e9;
  for (double la = -88.0; la <= 88.0; la += 2.0)
    for (double lo = -180.0; lo < 180.0; lo += 2.0) {
      const double r = rms(System::Gps, la * constants::kDegToRad, lo * constants::kDegToRad);
      if (r < best) best = r, bestLat = la, bestLon = lo;
    }
  const double la0 = bestLat, lo0 = bestLon;
  for (double la = la0 - 2.0; la <= la0 + 2.0; la += 0.05)
    for (double lo = lo0 - 2.0; lo <= lo0 + 2.0; lo += 0.05) {
      const double r = rms(System::Gps, la * constants::kDegToRad, lo * constants::kDegToRad);
      if (r < best) best = r, bestLat = la, bestLon = lo;
    }
  const double lat = bestLat * constants::kDegToRad, lon = bestLon * constants::kDegToRad;
  int nGps = 0, nGal = 0, nBds = 0;
  double wGps = 0.0, wGal = 0.0, wBds = 0.0;
  const double gps = rms(System::Gps, lat, lon, &nGps, &wGps);
  const double gal = rms(System::Galileo, lat, lon, &nGal, &wGal);
  const double bds = rms(System::BeiDou, lat, lon, &nBds, &wBds);
  std::cout << "receiver from GPS: lat " << bestLat << " lon " << bestLon << " deg; direction RMS (max), deg: GPS "
            << gps << " (" << wGps << ", " << nGps << " looks), Galileo " << gal << " (" << wGal << ", " << nGal
            << "), BeiDou " << bds << " (" << wBds << ", " << nBds << ")\n";
  ASSERT_GT(nGps, 50);
  ASSERT_GT(nGal, 20);
  ASSERT_GT(nBds, 50);
  EXPECT_LT(gps, 1.0);
  EXPECT_LT(gal, 1.5);
  EXPECT_LT(bds, 1.5);
  EXPECT_LT(wGal, 3.0);
  EXPECT_LT(wBds, 3.0);
}

}  // namespace
}  // namespace gvins::ubx
