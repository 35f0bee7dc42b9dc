// Internal consistency of the ephemerides decoded from RXM-SFRBX where convbin gives no reference
// (Galileo of the walk log: RTKLIB 2.4.3 decodes none of it): fed to an EphemerisStore as they
// arrive (cold start), they give satellite positions and clocks whose ranges to the receiver
// (its own NAV-PVT fix) match the RAWX pseudoranges within tens of metres once the receiver clock
// (the median over the GPS satellites, whose records equal convbin's) is removed. A wrong scale
// factor or bit position moves a satellite by kilometres.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iostream>
#include <map>
#include <set>

#include "gvins/base/constants.hpp"
#include "gvins/base/geodetic.hpp"
#include "gvins/ephemeris/ephemeris_store.hpp"
#include "sfrbx_log.hpp"

namespace gvins::ubx {
namespace {

template <class T>
T le(const std::uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof v);  // little-endian host assumed (x86, ARM)
  return v;
}

struct Residual {
  SatId sat;
  double metres;
};

TEST(SfrbxRanges, WalkLogOrbitsMatchPseudoranges) {
  const auto bytes = testing::readBytes(testing::dataDir() / "ubx" / "gnss_1730.ubx");
  Framer framer;
  framer.feed(bytes);
  framer.finish();
  NavigationAssembler assembler;
  EphemerisStore store;
  GpsTime receiveTime;
  Eigen::Vector3d receiver = Eigen::Vector3d::Zero();
  std::map<System, std::vector<double>> offsets;  // residual minus receiver clock, per system
  std::map<System, std::set<int>> satellites;
  Frame f;
  while (framer.next(f)) {
    const std::uint8_t* p = f.payload.data();
    if (f.type() == 0x0107 && f.payload.size() >= 92) {  // NAV-PVT: lon, lat (1e-7 deg), height (mm)
      Geodetic g;
      g.lon = le<std::int32_t>(p + 24) * 1e-7 * constants::kPi / 180.0;
      g.lat = le<std::int32_t>(p + 28) * 1e-7 * constants::kPi / 180.0;
      g.height = le<std::int32_t>(p + 32) * 1e-3;
      receiver = geodeticToEcef(g);
    } else if (f.type() == 0x0213) {
      assembler.add(parseSfrbx(f.payload), receiveTime).addTo(store);
    } else if (f.type() == 0x0215 && f.payload.size() >= 16) {  // RXM-RAWX
      receiveTime = GpsTime::fromWeekTow(le<std::uint16_t>(p + 8), le<double>(p));
      if (receiver.norm() < 6e6) continue;
      const int n = p[11];
      std::vector<Residual> res;
      std::set<SatId> seen;
      for (int k = 0; k < n && 16 + 32 * (k + 1) <= static_cast<int>(f.payload.size()); ++k) {
        const std::uint8_t* m = p + 16 + 32 * k;
        const int gnss = m[20];
        const System sys = gnss == 0 ? System::Gps : gnss == 2 ? System::Galileo : gnss == 3 ? System::BeiDou : System::Sbas;
        if (sys == System::Sbas || !(m[30] & 1)) continue;  // prValid
        const SatId sat(sys, m[21]);
        if (!sat.valid() || !seen.insert(sat).second) continue;  // first signal of each satellite
        const double pr = le<double>(m);
        GpsTime tx = receiveTime - pr / constants::kSpeedOfLight;
        auto st = store.satelliteState(sat, tx);
        if (!st) continue;
        tx -= st->clockBias;
        st = store.satelliteState(sat, tx);
        if (!st) continue;
        const double tau = (st->position - receiver).norm() / constants::kSpeedOfLight;
        const double a = constants::kGpsOmegaE * tau;  // Earth rotation during the signal's flight
        const Eigen::Vector3d rot(std::cos(a) * st->position.x() + std::sin(a) * st->position.y(),
                                  -std::sin(a) * st->position.x() + std::cos(a) * st->position.y(),
                                  st->position.z());
        res.push_back({sat, pr - (rot - receiver).norm() + constants::kSpeedOfLight * st->clockBias});
      }
      std::vector<double> gps;
      for (const auto& r : res)
        if (r.sat.system == System::Gps) gps.push_back(r.metres);
      if (gps.size() < 4) continue;
      std::nth_element(gps.begin(), gps.begin() + static_cast<long>(gps.size() / 2), gps.end());
      const double clock = gps[gps.size() / 2];
      for (const auto& r : res) {
        offsets[r.sat.system].push_back(r.metres - clock);
        satellites[r.sat.system].insert(r.sat.prn);
      }
    }
  }
  for (System sys : {System::Gps, System::Galileo, System::BeiDou}) {
    SCOPED_TRACE(std::string(systemName(sys)));
    const auto& v = offsets[sys];
    ASSERT_FALSE(v.empty());
    double worst = 0.0;
    for (double d : v) worst = std::max(worst, std::fabs(d));
    std::cout << systemName(sys) << ": " << satellites[sys].size() << " satellites, " << v.size()
              << " ranges, largest |range residual - receiver clock| " << worst << " m\n";
    EXPECT_LT(worst, 40.0);  // measured: GPS 10.0, Galileo 13.8, BeiDou 19.7 m (ionosphere, troposphere, TGDs)
  }
  EXPECT_GE(satellites[System::Galileo].size(), 5u);
}

}  // namespace
}  // namespace gvins::ubx
