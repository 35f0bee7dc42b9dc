// Atmosphere, geometry and statistics models of the gnss module, against ICD formulas evaluated
// by hand, published tables, exact geometry and finite differences.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <Eigen/Geometry>

#include "gvins/base/constants.hpp"
#include "gvins/base/geodetic.hpp"
#include "gvins/base/signal.hpp"
#include "gvins/gnss/dop.hpp"
#include "gvins/gnss/ionosphere_free.hpp"
#include "gvins/gnss/klobuchar.hpp"
#include "gvins/gnss/measurement_weighting.hpp"
#include "gvins/gnss/meteo_climatology.hpp"
#include "gvins/gnss/niell_mapping.hpp"
#include "gvins/gnss/sagnac.hpp"
#include "gvins/gnss/saastamoinen.hpp"
#include "gvins/gnss/troposphere.hpp"

using namespace gvins;
using constants::kDegToRad;

TEST(Troposphere, StandardAtmosphereAndSaastamoinenAtSeaLevel) {
  const SurfaceMeteo m = standardAtmosphere(0.0, 0.5);
  EXPECT_DOUBLE_EQ(m.pressure, 1013.25);
  EXPECT_DOUBLE_EQ(m.temperature, 288.15);
  // e = 0.5 * 6.108 * exp((17.15*288.15 - 4684)/(288.15 - 38.45)) = 8.5744 hPa (evaluated by hand).
  EXPECT_NEAR(m.waterVapour, 8.5744, 1e-4);
  // Davis et al. (1985): ZHD = 0.0022768 * 1013.25 / (1 - 0.00266 cos 90 deg) = 2.306968 m at 45 deg.
  EXPECT_NEAR(saastamoinenZenithHydrostatic(1013.25, 45.0 * kDegToRad, 0.0), 2.306968, 1e-6);
  // At the equator: / (1 - 0.00266) -> 2.313121 m.
  EXPECT_NEAR(saastamoinenZenithHydrostatic(1013.25, 0.0, 0.0), 2.313121, 1e-6);
  // ZWD = 0.002277 * (1255/288.15 + 0.05) * 8.5744 = 0.086010 m.
  EXPECT_NEAR(saastamoinenZenithWet(288.15, m.waterVapour), 0.086010, 1e-6);
  // Pressure falls by ~12 % per km near sea level.
  EXPECT_NEAR(standardAtmosphere(1000.0, 0.5).pressure / 1013.25, 0.8870, 5e-4);
}

TEST(Troposphere, NiellMappingIsOneAtZenithAndApproachesCosecant) {
  const Geodetic st = geodeticFromDegrees(45.0, 10.0, 0.0);
  const MappingFactors z = niellMapping(st, 90.0 * kDegToRad, 100.0);
  EXPECT_NEAR(z.hydrostatic, 1.0, 1e-12);
  EXPECT_NEAR(z.wet, 1.0, 1e-12);
  for (double el : {60.0, 30.0, 15.0}) {
    const MappingFactors m = niellMapping(st, el * kDegToRad, 100.0);
    const double csc = 1.0 / std::sin(el * kDegToRad);
    EXPECT_LT(m.hydrostatic, csc);  // the curvature of the atmosphere shortens the path
    EXPECT_NEAR(m.hydrostatic, csc, 0.02 * csc);
    EXPECT_NEAR(m.wet, csc, 0.02 * csc);
  }
  // Niell (1996) fig./table values near 5 deg: hydrostatic ~10.1, wet ~10.7 (mid latitude).
  const MappingFactors low = niellMapping(st, 5.0 * kDegToRad, 28.0);
  EXPECT_NEAR(low.hydrostatic, 10.15, 0.1);
  EXPECT_NEAR(low.wet, 10.7, 0.15);
  EXPECT_GT(low.wet, low.hydrostatic);
  // The hydrostatic height correction increases the factor with station height.
  const MappingFactors high = niellMapping(geodeticFromDegrees(45.0, 10.0, 3000.0), 5.0 * kDegToRad, 28.0);
  EXPECT_GT(high.hydrostatic, low.hydrostatic);
  EXPECT_DOUBLE_EQ(high.wet, low.wet);
}

TEST(Troposphere, SlantDelayCombinesZenithDelaysAndMapping) {
  const Geodetic st = geodeticFromDegrees(35.0, 137.0, 100.0);
  const GpsTime t = GpsTime::fromCalendar({2024, 6, 24, 8, 0, 0.0});
  const TroposphereDelay d = slantTroposphereDelay(st, 20.0 * kDegToRad, t, 0.5);
  EXPECT_NEAR(d.slant, d.zenithHydrostatic * d.mapHydrostatic + d.zenithWet * d.mapWet, 1e-12);
  EXPECT_NEAR(d.zenithHydrostatic, 2.28, 0.03);
  EXPECT_GT(d.slant, 6.0);
  EXPECT_LT(d.slant, 8.0);
  // No delay for an unconverged position far below the surface, or below the horizon.
  EXPECT_EQ(slantTroposphereDelay(geodeticFromDegrees(0, 0, -6e6), 0.5, t).slant, 0.0);
  EXPECT_EQ(slantTroposphereDelay(st, -0.1, t).slant, 0.0);
}

TEST(Troposphere, ClimatologyFollowsTheDo229TableAndSeason) {
  // At 45 deg and the DOY of minimum (28) the values are average - seasonal (DO-229 table A-2):
  // T = 283.15 - 11.0, P = 1015.75 + 2.25, e = 11.66 - 7.24 at sea level.
  const SurfaceMeteo w = climatologicalMeteo(45.0 * kDegToRad, 0.0, 28.0);
  EXPECT_NEAR(w.temperature, 272.15, 1e-9);
  EXPECT_NEAR(w.pressure, 1018.0, 1e-9);
  EXPECT_NEAR(w.waterVapour, 4.42, 1e-9);
  // Half a year later the seasonal term has the opposite sign.
  const SurfaceMeteo s = climatologicalMeteo(45.0 * kDegToRad, 0.0, 28.0 + 365.25 / 2.0);
  EXPECT_NEAR(s.temperature, 294.15, 1e-9);
  // Southern hemisphere: minimum at DOY 211.
  const SurfaceMeteo south = climatologicalMeteo(-45.0 * kDegToRad, 0.0, 211.0);
  EXPECT_NEAR(south.temperature, 272.15, 1e-9);
  // Height reduction: the temperature falls with the lapse rate beta.
  const SurfaceMeteo up = climatologicalMeteo(45.0 * kDegToRad, 1000.0, 28.0);
  EXPECT_NEAR(w.temperature - up.temperature, 1000.0 * (5.58e-3 - 0.32e-3), 1e-9);
  EXPECT_LT(up.pressure, w.pressure);
}

TEST(Ionosphere, KlobucharAtLocalAfternoonPeakMatchesTheIcdFormula) {
  // Receiver at 0/0, satellite at zenith, GPS time of week chosen so that the local time at the
  // pierce point is 14:00 (x = 0, cosine term 1). IS-GPS-200N figure 20-4 evaluated by hand:
  // psi = 0.0137/(0.5+0.11) - 0.022; phi_i = psi (azimuth 0); lambda_i = 0;
  // phi_m = phi_i + 0.064 cos(-1.617 pi); F = 1 + 16 (0.53 - 0.5)^3;
  // T = F (5 ns + sum alpha_n phi_m^n).
  KlobucharParameters p;
  p.alpha = {1.1176e-8, 7.4506e-9, -5.9605e-8, -5.9605e-8};
  p.beta = {90112.0, 0.0, -196608.0, -65536.0};
  const double psi = 0.0137 / 0.61 - 0.022;
  const double phiM = psi + 0.064 * std::cos(-1.617 * constants::kPi);
  const double amp = p.alpha[0] + p.alpha[1] * phiM + p.alpha[2] * phiM * phiM + p.alpha[3] * phiM * phiM * phiM;
  const double f = 1.0 + 16.0 * std::pow(0.03, 3);
  const double expected = constants::kSpeedOfLight * f * (5e-9 + amp);
  const GpsTime t = GpsTime::fromWeekTow(2000, 50400.0);
  const double d = klobucharDelayL1(p, geodeticFromDegrees(0.0, 0.0, 0.0), AzEl{0.0, 0.5 * constants::kPi}, t);
  EXPECT_NEAR(d, expected, 1e-9);
  EXPECT_GT(d, 4.0);  // ~ 15 ns near the afternoon peak
}

TEST(Ionosphere, KlobucharAtNightIsTheFiveNanosecondFloorTimesObliquity) {
  KlobucharParameters p;
  p.alpha = {1.8626e-08, 2.2352e-08, -1.1921e-07, -5.9605e-08};
  p.beta = {1.2902e+05, 1.6384e+05, -1.9661e+05, -2.6214e+05};
  const Geodetic rx = geodeticFromDegrees(35.0, 0.0, 0.0);
  // 01:30 local at longitude 0; with these (solar-maximum) parameters PER ~ 1.5e5 s and the
  // cosine term spans 03:20-24:40, so the pierce points (within +-1 h) are all on the night side.
  const GpsTime t = GpsTime::fromWeekTow(2000, 1.5 * 3600.0);
  for (double elDeg : {90.0, 45.0, 15.0}) {
    const double e = elDeg / 180.0;  // semicircles
    const double f = 1.0 + 16.0 * std::pow(0.53 - e, 3);
    const double d = klobucharDelayL1(p, rx, AzEl{1.0, elDeg * kDegToRad}, t);
    EXPECT_NEAR(d, constants::kSpeedOfLight * 5e-9 * f, 1e-9) << elDeg;
  }
  // BeiDou variant at night: 5 ns times the thin-shell slant factor 1/sqrt(1 - (R cos E/(R+h))^2).
  const double el = 30.0 * kDegToRad;
  const double k = 6378.0 / (6378.0 + 375.0) * std::cos(el);
  const double b = beidouKlobucharDelayB1I(p, rx, AzEl{0.5, el}, GpsTime::fromWeekTow(2000, 1.5 * 3600.0 + 14.0));
  EXPECT_NEAR(b, constants::kSpeedOfLight * 5e-9 / std::sqrt(1.0 - k * k), 1e-9);
  // Frequency scaling (f_L1/f_L2)^2 = (77/60)^2.
  EXPECT_NEAR(ionosphereFrequencyScale(*carrierFrequency(System::Gps, '1'), *carrierFrequency(System::Gps, '2')),
              (77.0 / 60.0) * (77.0 / 60.0), 1e-12);
}

TEST(Ionosphere, IonosphereFreeCombinationRemovesFirstOrderDelay) {
  const double f1 = *carrierFrequency(System::Gps, '1');
  const double f2 = *carrierFrequency(System::Gps, '2');
  const double rho = 21234567.891, i1 = 7.5;
  const double p1 = rho + i1, p2 = rho + i1 * (f1 / f2) * (f1 / f2);
  EXPECT_NEAR(ionosphereFree(p1, p2, f1, f2), rho, 1e-7);
  const auto c = ionosphereFreeCoefficients(f1, f2);
  EXPECT_NEAR(c.a1 + c.a2, 1.0, 1e-15);
  EXPECT_NEAR(c.a1, 2.5457, 1e-4);  // 154^2/(154^2-120^2)
  EXPECT_NEAR(c.noiseFactor(), 2.978, 1e-3);
}

TEST(Statistics, IonosphereFreeCodeVarianceComesFromBothSignals) {
  // The sample variance of the ionosphere-free combination of two independent simulated code
  // errors, each with the sigma the weighting model gives its signal (L2 10 dB weaker in C/N0),
  // against the model's variance of the combination. Equal C/N0: 2.978^2 = 8.87 times one code's.
  const double f1 = *carrierFrequency(System::Gps, '1');
  const double f2 = *carrierFrequency(System::Gps, '2');
  const auto c = ionosphereFreeCoefficients(f1, f2);
  MeasurementWeighting w;
  const double el = 40.0 * kDegToRad;
  const double one = w.codeVariance(System::Gps, el, 45.0);
  EXPECT_NEAR(w.combinationCodeVariance(System::Gps, el, c.a1, 45.0, c.a2, 45.0) / one, 8.87, 0.01);
  w.scheme = WeightingScheme::ElevationSnr;
  const double s1 = std::sqrt(w.codeVariance(System::Gps, el, 45.0));
  const double s2 = std::sqrt(w.codeVariance(System::Gps, el, 35.0));
  std::mt19937 rng(3);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const int n = 200000;
  double sum = 0.0, sum2 = 0.0;
  for (int i = 0; i < n; ++i) {
    const double e = ionosphereFree(s1 * gauss(rng), s2 * gauss(rng), f1, f2);
    sum += e;
    sum2 += e * e;
  }
  const double sample = sum2 / n - (sum / n) * (sum / n);
  const double model = w.combinationCodeVariance(System::Gps, el, c.a1, 45.0, c.a2, 35.0);
  EXPECT_NEAR(sample / model, 1.0, 0.01);  // sampling sigma of the ratio: sqrt(2 / n) = 0.003
  // Taking the first signal's variance for both would be 1.7x too small here.
  EXPECT_GT(model / (s1 * s1 * c.noiseFactor() * c.noiseFactor()), 1.6);
}

TEST(Geometry, SagnacTermMatchesExactEarthRotationDuringTravel) {
  // Exact: rotate the satellite position (transmit-time frame) into the receive-time frame by the
  // travel time, iterating tau = |R r_s - r_r| / c.
  const Eigen::Vector3d rx = geodeticToEcef(geodeticFromDegrees(35.0, 137.0, 100.0));
  const Eigen::Vector3d sats[] = {{-12402137.2, 16340379.2, 21337964.9},
                                  {-19780675.0, -7520892.8, 20692588.4},
                                  {1270599.4, 28706777.5, 7115428.6}};
  for (const auto& s : sats) {
    double tau = (s - rx).norm() / constants::kSpeedOfLight;
    for (int i = 0; i < 5; ++i) tau = (rotateEarth(s, tau) - rx).norm() / constants::kSpeedOfLight;
    const double exact = (rotateEarth(s, tau) - rx).norm();
    const double approx = (s - rx).norm() + sagnacRangeCorrection(s, rx);
    EXPECT_NEAR(approx, exact, 2e-3);
    EXPECT_GT(std::abs(exact - (s - rx).norm()), 1.0);  // the effect itself is tens of metres
  }
  // Range-rate term: derivative of the range term along straight-line motion (central difference).
  const Eigen::Vector3d s = sats[0], vs(1200.0, -2500.0, 1800.0), vr(10.0, -5.0, 2.0);
  const double h = 1e-3;
  const double fd = (sagnacRangeCorrection(s + h * vs, rx + h * vr) - sagnacRangeCorrection(s - h * vs, rx - h * vr)) / (2 * h);
  EXPECT_NEAR(sagnacRangeRateCorrection(s, vs, rx, vr), fd, 1e-9);
}

TEST(Geometry, ShapiroDelayOfMeoSatellitesIsOneToTwoCentimetres) {
  // IERS Conventions 2010 eq. 11.17 (Earth term): 2GM/c² = 8.870 mm times the logarithm.
  const Eigen::Vector3d rx = geodeticToEcef(geodeticFromDegrees(35.0, 137.0, 100.0));
  const Eigen::Vector3d up = rx.normalized();
  const double rs = 26560e3, rr = rx.norm();
  const Eigen::Vector3d zenith = up * rs;
  const double rho = rs - rr;
  EXPECT_NEAR(shapiroDelay(zenith, rx), 8.870056e-3 * std::log((rs + rr + rho) / (rs + rr - rho)), 1e-8);
  EXPECT_NEAR(shapiroDelay(zenith, rx), 0.0127, 3e-4);
  // Near the horizon: a satellite at 26560 km seen tangentially from the receiver.
  const Eigen::Vector3d east = Eigen::Vector3d::UnitZ().cross(up).normalized();
  const double d = std::sqrt(rs * rs - rr * rr);
  const double horizon = shapiroDelay(rx + d * east, rx);
  EXPECT_GT(horizon, 0.018);
  EXPECT_LT(horizon, 0.020);
}

TEST(Statistics, DopOfASymmetricGeometryIsAnalytic) {
  // Zenith plus four horizon satellites at N/E/S/W, one clock: G^T G = diag(2,2,[1 -1; -1 5]):
  // HDOP = 1, VDOP = sqrt(5/4), TDOP = 1/2, PDOP = 1.5, GDOP = sqrt(2.5).
  std::vector<Eigen::Vector3d> los = {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, -1, 0}};
  const Dop d = computeDop(los, {0, 0, 0, 0, 0}, 1);
  ASSERT_TRUE(d.valid);
  EXPECT_NEAR(d.hdop, 1.0, 1e-12);
  EXPECT_NEAR(d.vdop, std::sqrt(1.25), 1e-12);
  EXPECT_NEAR(d.tdop, 0.5, 1e-12);
  EXPECT_NEAR(d.pdop, 1.5, 1e-12);
  EXPECT_NEAR(d.gdop, std::sqrt(2.5), 1e-12);
  // Too few measurements or coplanar geometry: invalid.
  EXPECT_FALSE(computeDop({{0, 0, 1}, {1, 0, 0}, {0, 1, 0}}, {0, 0, 0}, 1).valid);
  EXPECT_FALSE(computeDop({{1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, -1, 0}}, {0, 0, 0, 0}, 1).valid);
}

TEST(Statistics, WeightingModels) {
  MeasurementWeighting w;
  w.a = 0.3;
  w.b = 0.4;
  EXPECT_NEAR(w.codeVariance(System::Gps, 0.5 * constants::kPi, 0.0), 0.09 + 0.16, 1e-12);
  EXPECT_NEAR(w.codeVariance(System::Gps, 30.0 * kDegToRad, 0.0), 0.09 + 0.16 / 0.25, 1e-12);
  EXPECT_NEAR(w.codeVariance(System::Glonass, 30.0 * kDegToRad, 0.0), 2.25 * (0.09 + 0.64), 1e-12);
  w.scheme = WeightingScheme::Snr;
  EXPECT_NEAR(w.codeVariance(System::Gps, 0.2, 45.0), 0.25, 1e-12);          // at the reference C/N0
  EXPECT_NEAR(w.codeVariance(System::Gps, 0.2, 35.0), 2.5, 1e-12);           // 10 dB less: x10
  EXPECT_NEAR(w.codeVariance(System::Gps, 0.5, 0.0), 0.09 + 0.16 / std::pow(std::sin(0.5), 2), 1e-12);  // no C/N0
  w.scheme = WeightingScheme::Elevation;
  EXPECT_NEAR(w.dopplerVariance(System::Gps, 0.5 * constants::kPi, 0.0), w.dopplerSigma * w.dopplerSigma, 1e-15);
  // One zenith sigma split evenly (the fusion's code model): sigma² (1/2 + 1/2 / sin² el) for
  // every system, and with C/N0 sigma²/2 (10^((45 - C/N0)/10) + 1 / sin² el).
  const MeasurementWeighting e = MeasurementWeighting::evenSplit(WeightingScheme::Elevation, 0.6);
  EXPECT_NEAR(e.codeVariance(System::Glonass, 30.0 * kDegToRad, 0.0), 0.36 * (0.5 + 0.5 / 0.25), 1e-12);
  const MeasurementWeighting es = MeasurementWeighting::evenSplit(WeightingScheme::ElevationSnr, 0.6);
  EXPECT_NEAR(es.codeVariance(System::Sbas, 30.0 * kDegToRad, 35.0), 0.18 * (10.0 + 4.0), 1e-12);
}
