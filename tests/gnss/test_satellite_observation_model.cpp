// The shared per-satellite observation model (satellite_observation_model.hpp, troposphere.hpp,
// zero_difference.hpp) against ICD formulas evaluated by hand, published zenith delays and real
// broadcast data.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "gvins/base/constants.hpp"
#include "gvins/base/geodetic.hpp"
#include "gvins/base/signal.hpp"
#include "gvins/ephemeris/rinex_nav.hpp"
#include "gvins/gnss/klobuchar.hpp"
#include "gvins/gnss/sagnac.hpp"
#include "gvins/gnss/satellite_observation_model.hpp"
#include "gvins/gnss/troposphere.hpp"
#include "gvins/gnss/zero_difference.hpp"

using namespace gvins;
using constants::kDegToRad;
using constants::kPi;
using constants::kSpeedOfLight;

namespace {

const std::string kData = GVINS_TEST_DATA;

// Kamakura 2021-03-19 (tests/data/gnss/kamakura_static_2021/SEPT078M.21P header): GPSA/GPSB and
// QZSA/QZSB ionospheric parameters as broadcast.
KlobucharParameters kamakuraGps() {
  KlobucharParameters p;
  p.alpha = {0.1118e-07, 0.7451e-08, -0.5960e-07, -0.5960e-07};
  p.beta = {0.9011e+05, 0.0, -0.1966e+06, -0.6554e+05};
  return p;
}
KlobucharParameters kamakuraQzss() {
  KlobucharParameters p;
  p.alpha = {0.1118e-07, -0.1490e-07, -0.3576e-06, -0.5364e-06};
  p.beta = {0.9011e+05, -0.4915e+05, -0.8520e+06, -0.2163e+07};
  return p;
}
// The station's ECEF position (GSI F5, data README).
const Eigen::Vector3d kKamakura(-3962108.673, 3381309.574, 3668678.638);

/// IS-GPS-200N figure 20-4 for a satellite at the zenith (azimuth 0: no longitude offset of the
/// pierce point), written out by hand: psi = 0.0137/0.61 - 0.022, phi_i = phi_u + psi clamped to
/// +-0.416, lambda_i = lambda_u, phi_m = phi_i + 0.064 cos((lambda_i - 1.617) pi),
/// t = 43200 lambda_i + tow (mod 86400), x = 2 pi (t - 50400) / PER, F = 1 + 16 (0.53 - 0.5)^3.
double zenithKlobucharByHand(const KlobucharParameters& p, const Geodetic& rx, double tow) {
  const double psi = 0.0137 / 0.61 - 0.022;
  const double phiI = std::clamp(rx.lat / kPi + psi, -0.416, 0.416);
  const double lamI = rx.lon / kPi;
  const double phiM = phiI + 0.064 * std::cos((lamI - 1.617) * kPi);
  const double t = std::fmod(43200.0 * lamI + tow, 86400.0);
  const double amp = std::max(0.0, p.alpha[0] + p.alpha[1] * phiM + p.alpha[2] * phiM * phiM +
                                       p.alpha[3] * phiM * phiM * phiM);
  const double per = std::max(72000.0, p.beta[0] + p.beta[1] * phiM + p.beta[2] * phiM * phiM +
                                           p.beta[3] * phiM * phiM * phiM);
  const double x = 2.0 * kPi * (t - 50400.0) / per;
  const double f = 1.0 + 16.0 * 0.03 * 0.03 * 0.03;
  const double night = 5e-9;
  return kSpeedOfLight * f * (std::abs(x) < 1.57 ? night + amp * (1.0 - x * x / 2.0 + x * x * x * x / 24.0) : night);
}

}  // namespace

TEST(BroadcastIonosphere, OneParameterSetForGpsAndQzssLinesOfSightGpsFirst) {
  const Geodetic rx = ecefToGeodetic(kKamakura);
  // 14:00 local time at the pierce point (lambda ~ 0.775 semicircles): the afternoon maximum,
  // where the two parameter sets differ (at night both give the 5 ns floor).
  const double tow = 5 * 86400.0 + std::fmod(50400.0 - 43200.0 * rx.lon / kPi + 86400.0, 86400.0);
  const GpsTime t = GpsTime::fromWeekTow(2149, tow);
  const AzEl zenith{0.0, 0.5 * kPi};
  const double fL1 = *carrierFrequency(System::Gps, '1');
  const double gpsByHand = zenithKlobucharByHand(kamakuraGps(), rx, tow);
  const double qzssByHand = zenithKlobucharByHand(kamakuraQzss(), rx, tow);
  // The two sets disagree by decimetres here: which one a QZSS satellite gets matters.
  std::printf("Kamakura zenith L1 Klobuchar at 14:00 local: GPS set %.3f m, QZSS set %.3f m\n", gpsByHand, qzssByHand);
  EXPECT_GT(std::abs(gpsByHand - qzssByHand), 0.1);

  IonosphereParameters both;
  both.gps = kamakuraGps();
  both.qzss = kamakuraQzss();
  // A QZSS satellite is given the GPS set, as the GPS satellite beside it (SPP used to give it
  // the QZSS set, the fusion the GPS set).
  for (System s : {System::Gps, System::Qzss, System::Galileo, System::Glonass}) {
    EXPECT_NEAR(broadcastIonosphereDelay(both, s, rx, zenith, t, fL1).slant, gpsByHand, 1e-9) << static_cast<int>(s);
  }
  // Without GPS parameters the QZSS set serves every line of sight (SPP's fallback; the fusion
  // had no model then).
  IonosphereParameters qzssOnly;
  qzssOnly.qzss = kamakuraQzss();
  for (System s : {System::Gps, System::Qzss}) {
    EXPECT_NEAR(broadcastIonosphereDelay(qzssOnly, s, rx, zenith, t, fL1).slant, qzssByHand, 1e-9) << static_cast<int>(s);
  }
  // No parameters: no model.
  EXPECT_EQ(broadcastIonosphereDelay(IonosphereParameters{}, System::Gps, rx, zenith, t, fL1).slant, 0.0);
  // Frequency scaling to L5 (f_L1/f_L5)^2 = (154/115)^2 and the L1 partial F (f_L1/f)^2.
  const double fL5 = *carrierFrequency(System::Qzss, '5');
  const IonosphereDelay l5 = broadcastIonosphereDelay(both, System::Qzss, rx, zenith, t, fL5);
  EXPECT_NEAR(l5.slant, gpsByHand * (154.0 / 115.0) * (154.0 / 115.0), 1e-9);
  EXPECT_NEAR(l5.mapL1, (1.0 + 16.0 * 0.03 * 0.03 * 0.03) * (154.0 / 115.0) * (154.0 / 115.0), 1e-12);
}

TEST(BroadcastIonosphere, BeidouUsesItsOwnModelOnB1IWhenBroadcast) {
  const Geodetic rx = ecefToGeodetic(kKamakura);
  IonosphereParameters p;
  p.gps = kamakuraGps();
  p.beidou = kamakuraGps();
  // BDS-SIS-ICD-B1I 3.0 5.2.4.7 at night (BDT 01:30 local at the pierce point, well outside the
  // cosine term): 5 ns times the thin-shell factor 1/sqrt(1 - (R cos E / (R + h))^2), R = 6378 km,
  // h = 375 km, scaled from B1I (1561.098 MHz) to B3I (1268.52 MHz).
  const double el = 40.0 * kDegToRad;
  const double bdtLocal = 1.5 * 3600.0 - 43200.0 * rx.lon / kPi;  // about the station's longitude
  const GpsTime t = GpsTime::fromWeekTow(2149, 3 * 86400.0 + std::fmod(bdtLocal + 86400.0, 86400.0) + 14.0);
  const double k = 6378.0 / (6378.0 + 375.0) * std::cos(el);
  const double fB3 = *carrierFrequency(System::BeiDou, '6');
  const double expected = kSpeedOfLight * 5e-9 / std::sqrt(1.0 - k * k) * std::pow(1561.098 / 1268.52, 2);
  EXPECT_NEAR(broadcastIonosphereDelay(p, System::BeiDou, rx, AzEl{0.3, el}, t, fB3).slant, expected, 1e-6);
  // Without BeiDou parameters a BeiDou satellite gets the GPS model on its frequency.
  IonosphereParameters gpsOnly;
  gpsOnly.gps = kamakuraGps();
  const double fL1 = *carrierFrequency(System::Gps, '1');
  EXPECT_DOUBLE_EQ(broadcastIonosphereDelay(gpsOnly, System::BeiDou, rx, AzEl{0.3, el}, t, fB3).slant,
                   klobucharDelayL1(*gpsOnly.gps, rx, AzEl{0.3, el}, t) * std::pow(fL1 / fB3, 2));
}

TEST(StationTroposphereModel, ZenithDelaysAreSaastamoinenOfTheStandardAtmosphere) {
  // 45 deg, sea level, relative humidity 0.5: ZHD 2.306968 m, ZWD 0.086010 m (Davis et al. 1985
  // and Saastamoinen evaluated by hand, test_gnss_models.cpp); the Niell factors are 1 at the zenith.
  const Geodetic st = geodeticFromDegrees(45.0, 10.0, 0.0);
  const StationTroposphere s = StationTroposphere::at(st, 100.0, TroposphereMeteo::StandardAtmosphere, 0.5);
  ASSERT_TRUE(s.valid());
  EXPECT_NEAR(s.zenithHydrostatic, 2.306968, 1e-6);
  EXPECT_NEAR(s.zenithWet, 0.086010, 1e-6);
  EXPECT_NEAR(s.slant(0.5 * kPi).slant, 2.306968 + 0.086010, 2e-6);
  // Lower elevations: slant = ZHD m_h + ZWD m_w, between the zenith delay and its cosecant.
  const TroposphereDelay d = s.slant(20.0 * kDegToRad);
  EXPECT_DOUBLE_EQ(d.slant, d.zenithHydrostatic * d.mapHydrostatic + d.zenithWet * d.mapWet);
  EXPECT_GT(d.slant, 2.39 * 2.8);
  EXPECT_LT(d.slant, 2.40 / std::sin(20.0 * kDegToRad));
  // The climatology changes the meteorology, not the formulas; off / implausible heights: none.
  EXPECT_NE(StationTroposphere::at(st, 100.0, TroposphereMeteo::Climatology).zenithWet, s.zenithWet);
  EXPECT_FALSE(StationTroposphere::at(st, 100.0, TroposphereMeteo::Off).valid());
  EXPECT_FALSE(StationTroposphere::at(geodeticFromDegrees(45.0, 10.0, 25000.0), 100.0,
                                      TroposphereMeteo::StandardAtmosphere).valid());
  // slantTroposphereDelay is the same model: bit for bit, and zero at or below the horizon.
  const GpsTime t = GpsTime::fromCalendar({2024, 6, 24, 8, 22, 0.0});
  const TroposphereDelay a = slantTroposphereDelay(st, 0.3, t);
  const TroposphereDelay b = StationTroposphere::at(st, fractionalDayOfYear(t), TroposphereMeteo::StandardAtmosphere).slant(0.3);
  EXPECT_EQ(a.slant, b.slant);
  EXPECT_EQ(a.mapWet, b.mapWet);
  EXPECT_EQ(slantTroposphereDelay(st, -0.01, t).slant, 0.0);
  // Day of year: 24 June 08:22 = day 176 + 8.3667 h.
  EXPECT_NEAR(fractionalDayOfYear(t), 176.0 + (8.0 + 22.0 / 60.0) / 24.0, 1e-12);
}

TEST(SatelliteObservationModelTerms, GeometryAndTheTermsAskedFor) {
  const GpsTime t = GpsTime::fromWeekTow(2149, 5 * 86400.0 + 17000.0);
  IonosphereParameters iono;
  iono.gps = kamakuraGps();
  ObservationModelOptions o;
  o.broadcastIonosphere = true;
  o.shapiro = true;
  const SatelliteObservationModel model(kKamakura, t, o, &iono);
  const Geodetic& g = model.geodetic();
  const Eigen::Vector3d up(std::cos(g.lat) * std::cos(g.lon), std::cos(g.lat) * std::sin(g.lon), std::sin(g.lat));
  const Eigen::Vector3d east(-std::sin(g.lon), std::cos(g.lon), 0.0);
  // A satellite 20000 km along the ellipsoid normal is at the zenith; one 30 deg above the
  // eastern horizon has azimuth 90 deg.
  const Eigen::Vector3d zenithSat = kKamakura + 2.0e7 * up;
  const Eigen::Vector3d eastSat = kKamakura + 2.0e7 * (std::cos(30.0 * kDegToRad) * east + std::sin(30.0 * kDegToRad) * up);
  const double fL1 = *carrierFrequency(System::Gps, '1');
  const SatelliteModelTerms z = model.terms(zenithSat, System::Gps, fL1);
  EXPECT_NEAR(z.azel.elevation, 0.5 * kPi, 1e-7);  // asin near 1: ~sqrt(eps) resolution
  const SatelliteModelTerms e = model.terms(eastSat, System::Gps, fL1);
  EXPECT_NEAR(e.azel.elevation, 30.0 * kDegToRad, 1e-9);
  EXPECT_NEAR(e.azel.azimuth, 90.0 * kDegToRad, 1e-9);
  // Each term is the model's own function at the station.
  EXPECT_EQ(e.troposphere.slant, model.troposphere().slant(e.azel.elevation).slant);
  EXPECT_EQ(e.ionosphere.slant, broadcastIonosphereDelay(iono, System::Gps, g, e.azel, t, fL1).slant);
  EXPECT_EQ(e.shapiro, shapiroDelay(eastSat, kKamakura));
  EXPECT_GT(e.shapiro, 0.012);
  // An ionosphere-free observation (frequency 0) gets no ionosphere; below the horizon no troposphere.
  EXPECT_EQ(model.terms(eastSat, System::Gps, 0.0).ionosphere.slant, 0.0);
  EXPECT_EQ(model.terms(kKamakura - 2.0e7 * up, System::Gps, fL1).troposphere.slant, 0.0);
  // Terms not asked for are zero.
  const SatelliteObservationModel bare(kKamakura, t, ObservationModelOptions{TroposphereMeteo::Off}, &iono);
  const SatelliteModelTerms b = bare.terms(eastSat, System::Gps, fL1);
  EXPECT_EQ(b.troposphere.slant, 0.0);
  EXPECT_EQ(b.ionosphere.slant, 0.0);
  EXPECT_EQ(b.shapiro, 0.0);
}

TEST(IonosphereFreePairing, SecondBandIsTheFirstOtherUsableOneOfTheList) {
  SatObs so;
  so.sat = SatId(System::Gps, 5);
  auto add = [&](char band, char attr, double pr) {
    SignalObs s;
    s.code = ObsCode(band, attr);
    s.setCode(pr);
    so.signals.push_back(s);
  };
  add('1', 'C', 2.2e7);
  add('2', 'W', 2.2e7 + 3.0);
  add('5', 'Q', 5.0);  // implausible pseudorange: not usable
  ASSERT_TRUE(usableCode(so, '1', std::nullopt));
  EXPECT_FALSE(usableCode(so, '5', std::nullopt));
  EXPECT_EQ(usableCode(so, '2', std::nullopt)->frequency, *carrierFrequency(System::Gps, '2'));
  // Order "152": L5 first but unusable, so L2.
  const auto second = secondCode(so, "152", 3, '1', std::nullopt);
  ASSERT_TRUE(second);
  EXPECT_EQ(second->signal->code.band, '2');
  // Only the first two bands of the list considered (SPP's frequencies = 2): none.
  EXPECT_FALSE(secondCode(so, "152", 2, '1', std::nullopt));
  // The first band is never its own pair.
  EXPECT_FALSE(secondCode(so, "11", 2, '1', std::nullopt));
}

TEST(SignalPairing, GpsL2CBeforeL5AndL2PYAfterIt) {
  // The default GPS order "125": L2C pairs with L1 (the LNAV clock's own L1/L2 reference), L5
  // when L2 is only P(Y) (semi-codeless), L2 P(Y) only without L5.
  auto sat = [](std::initializer_list<ObsCode> codes) {
    SatObs so;
    so.sat = SatId(System::Gps, 23);
    for (ObsCode c : codes) {
      SignalObs s;
      s.code = c;
      s.setCode(2.2e7);
      so.signals.push_back(s);
    }
    return so;
  };
  const SatObs civil = sat({ObsCode('1', 'C'), ObsCode('2', 'L'), ObsCode('5', 'Q')});
  EXPECT_EQ(secondCode(civil, "125", 3, '1', std::nullopt)->signal->code, ObsCode('2', 'L'));
  const SatObs py = sat({ObsCode('1', 'C'), ObsCode('2', 'W'), ObsCode('5', 'Q')});
  EXPECT_EQ(secondCode(py, "125", 3, '1', std::nullopt)->signal->code, ObsCode('5', 'Q'));
  EXPECT_EQ(secondCode(py, "125", 2, '1', std::nullopt)->signal->code, ObsCode('2', 'W'));  // L5 not in range
  const SatObs noL5 = sat({ObsCode('1', 'C'), ObsCode('2', 'W')});
  EXPECT_EQ(secondCode(noL5, "125", 3, '1', std::nullopt)->signal->code, ObsCode('2', 'W'));
  EXPECT_TRUE(semiCodelessL2(System::Qzss, ObsCode('2', 'P')));
  EXPECT_FALSE(semiCodelessL2(System::Gps, ObsCode('2', 'X')));
  EXPECT_FALSE(semiCodelessL2(System::Glonass, ObsCode('2', 'P')));
}

TEST(SatelliteSource, TransmitTimeStateAndGroupDelayFromOneBroadcastRecord) {
  EphemerisStore nav;
  nav.add(readRinexNav(kData + "/gnss/nagoya_static_2024/base.nav.gz"));
  const GpsTime trx = GpsTime::fromCalendar({2024, 6, 24, 8, 22, 0.0});
  EphemerisCache cache(nav);
  int n = 0;
  for (const SatId sat : nav.satellites()) {
    const double pr = 2.2e7;
    const auto tx = satelliteAtTransmit(nav, sat, trx, pr);
    if (!tx) continue;
    ++n;
    // t_tx = t_rx - P/c - dt_s, with dt_s the clock at t_tx (to first order, < 1e-15 s).
    EXPECT_NEAR((trx - tx->transmitTime) - pr / kSpeedOfLight - tx->state.clockBias, 0.0, 1e-12) << sat.str();
    // The state is that of the selected record at t_tx (first-order move: < 1 mm).
    const SatelliteState direct = tx->glonass ? glonassSatelliteState(*tx->glonass, tx->transmitTime)
                                              : keplerSatelliteState(*tx->kepler, tx->transmitTime);
    EXPECT_LT((direct.position - tx->state.position).norm(), 1e-3) << sat.str();
    EXPECT_NEAR(direct.clockBias, tx->state.clockBias, 1e-15) << sat.str();
    // The record is the store's choice; the cache makes the same one, bit for bit.
    const auto cached = satelliteAtTransmit(nav, sat, trx, pr, {}, &cache);
    ASSERT_TRUE(cached);
    EXPECT_EQ(cached->state.position, tx->state.position);
    EXPECT_EQ(cached->kepler, tx->kepler);
    // Broadcast group delay of that record (GPS L1C: T_GD; IS-GPS-200N 20.3.3.3.3.2).
    if (sat.system == System::Gps) {
      EXPECT_EQ(transmitGroupDelay(nav, *tx, sat, ObsCode('1', 'C')), tx->kepler->tgd[0]) << sat.str();
      EXPECT_EQ(transmitGroupDelay(nav, *tx, sat, ObsCode('1', 'C')), nav.groupDelay(sat, ObsCode('1', 'C'), trx));
    }
  }
  EXPECT_GT(n, 40);
  // Implausible pseudoranges and unknown satellites give nothing.
  EXPECT_FALSE(satelliteAtTransmit(nav, SatId(System::Gps, 5), trx, 10.0));
  EXPECT_FALSE(satelliteAtTransmit(nav, SatId(System::Gps, 31), trx, 2.2e7));
}
