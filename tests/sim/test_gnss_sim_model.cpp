// GNSS simulator, measurement model: every pseudorange, carrier phase and Doppler is rebuilt
// from truth with independent code (the broadcast ephemerides through EphemerisStore, the
// library's troposphere/Klobuchar/Sagnac functions, the trajectory itself) and what is left must
// equal the simulated error terms; ambiguities are integers; Doppler agrees with the phase rate.
#include <gtest/gtest.h>

#include <cstdio>

#include <cmath>
#include <map>

#include "gvins/base/constants.hpp"
#include "gvins/base/local_frame.hpp"
#include "gvins/gnss/klobuchar.hpp"
#include "gvins/gnss/sagnac.hpp"
#include "gvins/gnss/troposphere.hpp"
#include "gvins/sim/gnss_epoch_generator.hpp"
#include "gvins/sim/gnss_random_field.hpp"
#include "gvins/sim/gnss_receiver_clock.hpp"
#include "test_gnss_support.hpp"

namespace gvins::sim {
namespace {

using testing::CircleTrajectory;
using testing::nagoyaFrame;
using testing::nagoyaNav;
constexpr double kC = constants::kSpeedOfLight;

/// Broadcast truth (no signal-in-space error, one record per satellite) so that EphemerisStore
/// reproduces the satellite states exactly.
GnssSimConfig broadcastTruthConfig() {
  GnssSimConfig c;
  c.satelliteErrors.blendRecords = false;
  c.satelliteErrors.sisre.fill(0.0);
  return c;
}

struct Collected {
  std::vector<GnssSimEpoch> rover, base;
};

Collected collect(GnssEpochGenerator& gen) {
  Collected c;
  while (auto e = gen.next()) (e->role == GnssReceiverRole::Rover ? c.rover : c.base).push_back(std::move(*e));
  gen.finish();
  return c;
}

TEST(GnssSimModel, PseudorangeMinusGeometryAndModelsEqualsSimulatedErrors) {
  GnssSimConfig cfg = broadcastTruthConfig();
  cfg.rover.rate = 5.0;
  const LocalFrame frame = nagoyaFrame();
  const CircleTrajectory traj(20.0, 80.0, 40.0, 8.0);
  const Eigen::Vector3d lever(0.10, -0.05, 0.20);
  GnssEpochGenerator gen(cfg, nagoyaNav(), traj, frame, lever, 7);
  const Collected data = collect(gen);
  ASSERT_GE(data.rover.size(), 95u);
  ASSERT_GE(data.base.size(), 19u);

  EphemerisStore store;
  store.add(nagoyaNav());
  const KlobucharParameters& klob = *nagoyaNav().iono.gps;
  std::map<System, int> perSystem;
  int checked = 0;
  double maxSagnacFirstOrder = 0.0;
  for (const GnssSimEpoch& e : data.rover) {
    const GnssReceiverTruth& tr = e.truth;
    // Receiver time tag and true time.
    EXPECT_NEAR(tr.tag - tr.time, tr.clockBias, 1e-12);
    EXPECT_EQ(e.obs.time, tr.tag);
    // Antenna = trajectory + R lever, through the local frame (independent of the generator).
    const TrajectoryState s = traj.evaluate(tr.time - frame.startTime);
    const Eigen::Vector3d ant = frame.toEcef(s.p_WB + s.R_WB * lever);
    EXPECT_LT((ant - tr.antennaPosition).norm(), 1e-6);
    EXPECT_LT((frame.vectorToEcef(s.pointVelocity(lever)) - tr.antennaVelocity).norm(), 1e-9);
    const Geodetic geo = ecefToGeodetic(ant);
    ASSERT_EQ(e.obs.sats.size(), tr.sats.size());
    for (std::size_t i = 0; i < tr.sats.size(); ++i) {
      const GnssSatelliteTruth& st = tr.sats[i];
      const SatObs& so = e.obs.sats[i];
      ASSERT_EQ(so.sat, st.sat);
      ++perSystem[st.sat.system];
      // Satellite state from the broadcast record at the true transmit time.
      const auto bs = store.satelliteState(st.sat, st.transmitTime);
      ASSERT_TRUE(bs) << st.sat.str();
      EXPECT_LT((bs->position - st.satPosition).norm(), 1e-4) << st.sat.str();
      EXPECT_NEAR(bs->clockBias, st.satClock, 1e-13) << st.sat.str();
      // Light time: the range is c times the flight time, with the satellite rotated into the
      // frame of reception; and it agrees with the first-order Sagnac formula to < 1 mm.
      const double tau = tr.time - st.transmitTime;
      const Eigen::Vector3d satRx = rotateEarth(bs->position, tau);
      const double rho = (satRx - ant).norm();
      EXPECT_NEAR(rho, kC * tau, 1e-5) << st.sat.str();
      EXPECT_NEAR(rho, st.range, 2e-4) << st.sat.str();
      const double firstOrder = (bs->position - ant).norm() + sagnacRangeCorrection(bs->position, ant);
      maxSagnacFirstOrder = std::max(maxSagnacFirstOrder, std::abs(rho - firstOrder));
      // Models.
      const AzEl azel = azimuthElevation(geo, ant, satRx);
      EXPECT_NEAR(azel.elevation, st.azel.elevation, 1e-8);
      EXPECT_GE(azel.elevation, cfg.rover.elevationMaskDeg * constants::kDegToRad - 1e-9);
      const double tropoModel = slantTroposphereDelay(geo, azel.elevation, tr.time, 0.5).slant;
      EXPECT_NEAR(tropoModel, st.troposphereModel, 1e-6);
      const double ionoModel = klobucharDelayL1(klob, geo, azel, tr.time);
      EXPECT_NEAR(ionoModel, st.ionosphereModelL1, 1e-6);
      EXPECT_GT(st.troposphere, 0.0);
      EXPECT_GT(st.ionosphereL1, 0.0);
      const double shapiro = 2.0 * 3.986004418e14 / (kC * kC) *
                             std::log((bs->position.norm() + ant.norm() + rho) / (bs->position.norm() + ant.norm() - rho));
      EXPECT_NEAR(shapiro, st.shapiro, 1e-6);
      EXPECT_GT(shapiro, 0.01);
      EXPECT_LT(shapiro, 0.03);

      ASSERT_EQ(so.signals.size(), st.signals.size());
      const std::optional<int> ch = st.sat.system == System::Glonass ? store.glonassChannels().get(st.sat.prn)
                                                                      : std::optional<int>();
      for (std::size_t j = 0; j < so.signals.size(); ++j) {
        const SignalObs& o = so.signals[j];
        const GnssSignalTruth& g = st.signals[j];
        ASSERT_TRUE(o.code == g.code);
        const double lambda = *carrierWavelength(st.sat.system, o.code.band, ch);
        const double f = *carrierFrequency(st.sat.system, o.code.band, ch);
        EXPECT_NEAR(lambda, g.wavelength, 1e-12);
        const double gd = store.groupDelay(st.sat, o.code, st.transmitTime);
        EXPECT_NEAR(gd, g.groupDelay, 1e-15);
        // First-order ionosphere: 1/f^2, same size on code and phase.
        EXPECT_NEAR(g.ionosphere, st.ionosphereL1 * std::pow(1575.42e6 / f, 2), 1e-9);
        // Pseudorange minus geometry minus modelled terms = simulated errors.
        const double rxClock = kC * tr.systemClockBias[systemIndex(st.sat.system)];
        const double modelled = rho + rxClock - kC * (bs->clockBias - gd) + tropoModel + ionoModel * std::pow(1575.42e6 / f, 2);
        const double errors = (st.troposphere - st.troposphereModel) + (g.ionosphere - ionoModel * std::pow(1575.42e6 / f, 2)) +
                              shapiro + g.interFrequencyBias + g.multipathCode + st.nlosBias + g.codeNoise;
        EXPECT_NEAR(o.pseudorange - modelled, errors, 5e-4) << st.sat.str() << " " << o.code.str();
        // Carrier phase: the same terms with the ionosphere advancing, plus N whole cycles and the
        // wind-up (cycles, the same on every frequency).
        const double phaseModelled = rho + rxClock - kC * bs->clockBias + tropoModel - ionoModel * std::pow(1575.42e6 / f, 2);
        const double phaseErrors = (st.troposphere - st.troposphereModel) - (g.ionosphere - ionoModel * std::pow(1575.42e6 / f, 2)) +
                                   shapiro + g.multipathPhase + st.nlosBias + g.phaseNoise;
        EXPECT_NEAR((o.carrierPhase - static_cast<double>(g.ambiguity) - st.windup) * lambda - phaseModelled, phaseErrors,
                    5e-4)
            << st.sat.str() << " " << o.code.str();
        // Errors of a plausible size.
        EXPECT_LT(std::abs(g.codeNoise), 6.0 * g.codeSigma + 1e-12);
        EXPECT_LT(std::abs(g.phaseNoise), 6.0 * g.phaseSigma + 1e-12);
        EXPECT_LE(std::abs(g.multipathPhase), 0.25 * lambda + 1e-12);
        EXPECT_TRUE(o.hasCode() && o.hasPhase() && o.hasDoppler() && o.hasSnr());
        EXPECT_NEAR(o.snr, g.cn0, 1e-12);
        ++checked;
      }
    }
  }
  EXPECT_LT(maxSagnacFirstOrder, 1e-3);
  EXPECT_GT(checked, 5000);
  // All five systems of the navigation file are simulated.
  for (System s : {System::Gps, System::Glonass, System::Galileo, System::BeiDou, System::Qzss}) {
    EXPECT_GT(perSystem[s], 0) << systemName(s);
  }
}


/// Noise-free receivers with a deterministic clock (for rates and differences).
GnssSimConfig quietConfig() {
  GnssSimConfig c;
  for (GnssReceiverConfig* r : {&c.rover, &c.base.receiver}) {
    r->noise = {0.0, 0.0, 0.0};
    r->multipath = {0.0, 0.0, 10.0};
    r->nlos.ratePerMinute = 0.0;
    r->blockage.ratePerMinute = 0.0;
    r->slips.ratePerMinute = 0.0;
    r->clock.h0 = 0.0;
    r->clock.hMinus2 = 0.0;
    r->cn0.noise = 0.0;
  }
  return c;
}

/// Checks -(L_k - L_k-1) / dt against the mean Doppler of the two epochs for every continuous
/// arc; returns the largest difference in m/s.
double dopplerVersusPhaseRate(const std::vector<GnssSimEpoch>& epochs, int* pairs) {
  double worst = 0.0;
  for (std::size_t k = 1; k < epochs.size(); ++k) {
    const ObsEpoch& a = epochs[k - 1].obs;
    const ObsEpoch& b = epochs[k].obs;
    const double dt = b.time - a.time;
    for (std::size_t i = 0; i < b.sats.size(); ++i) {
      const SatObs* sa = a.find(b.sats[i].sat);
      if (!sa) continue;
      for (std::size_t j = 0; j < b.sats[i].signals.size(); ++j) {
        const SignalObs& gb = b.sats[i].signals[j];
        const SignalObs* ga = sa->find(gb.code);
        if (!ga || (gb.lli & 1) || epochs[k].truth.sats[i].signals[j].arcStart) continue;
        const double lambda = epochs[k].truth.sats[i].signals[j].wavelength;
        const double rate = -(gb.carrierPhase - ga->carrierPhase) / dt;
        worst = std::max(worst, std::abs(rate - 0.5 * (gb.doppler + ga->doppler)) * lambda);
        ++*pairs;
      }
    }
  }
  return worst;
}

TEST(GnssSimModel, DopplerIsTheRateOfTheCarrierPhase) {
  // Static antenna: the phase-rate over 0.2 s equals the mean Doppler to the curvature of the
  // range (1e-5 m/s); a moving one (8 m/s on an 80 m circle, 0.8 m/s^2, the antenna turning
  // with the body): to its jerk, with the phase wind-up's rate in the Doppler.
  for (const double speed : {0.0, 8.0}) {
    GnssSimConfig cfg = quietConfig();
    cfg.rover.rate = 5.0;
    cfg.base.enabled = false;
    const CircleTrajectory traj(10.0, 80.0, 40.0, speed);
    GnssEpochGenerator gen(cfg, nagoyaNav(), traj, nagoyaFrame(), Eigen::Vector3d(0.2, 0.0, 0.1), 3);
    std::vector<GnssSimEpoch> epochs;
    while (auto e = gen.next()) epochs.push_back(std::move(*e));
    int pairs = 0;
    const double worst = dopplerVersusPhaseRate(epochs, &pairs);
    std::fprintf(stderr, "speed %.0f m/s: Doppler against the phase rate, worst %.2e m/s (%d pairs)\n", speed, worst, pairs);
    EXPECT_GT(pairs, 3000);
    // Measured: 1.4e-4 static; moving 1.2e-3 (4.3e-3 before the Doppler carried the wind-up
    // rate: the body turns at 0.1 rad/s, 0.016 cycles/s of wind-up on every satellite).
    EXPECT_LT(worst, speed == 0.0 ? 2e-4 : 2e-3) << "speed " << speed;
    // The clock drift is in every Doppler: c * drift is tens of m/s for a 0.1 ppm oscillator.
    EXPECT_GT(std::abs(epochs.front().truth.clockDrift), 1e-10);
  }
}

TEST(GnssSimModel, ReceiverClockFollowsItsAllanVariance) {
  // Overlapping Allan variance of the simulated clock phase against the power-law model
  // sigma_y^2(tau) = h0 / (2 tau) + (2 pi^2 / 3) h_-2 tau (NIST Technical Note 1337, table 2 of
  // Barnes et al. for white and random-walk frequency noise).
  GnssClockConfig c;
  c.h0 = 1e-21;
  c.hMinus2 = 1e-22;
  GnssReceiverClock clock(c, 5);
  const GpsTime t0 = nagoyaFrame().startTime;
  const int n = 40000;
  std::vector<double> x(n);
  for (int i = 0; i < n; ++i) {
    clock.advanceToTag(t0 + static_cast<double>(i));
    x[static_cast<std::size_t>(i)] = clock.bias();
  }
  for (int m : {1, 10, 100}) {
    double sum = 0.0;
    int count = 0;
    for (int i = 0; i + 2 * m < n; ++i, ++count) {
      const double d = x[static_cast<std::size_t>(i + 2 * m)] - 2.0 * x[static_cast<std::size_t>(i + m)] + x[static_cast<std::size_t>(i)];
      sum += d * d;
    }
    const double tau = m;
    const double avar = sum / (2.0 * tau * tau * count);
    const double model = c.h0 / (2.0 * tau) + 2.0 * constants::kPi * constants::kPi / 3.0 * c.hMinus2 * tau;
    EXPECT_NEAR(avar / model, 1.0, m == 100 ? 0.25 : 0.1) << "tau " << tau;
  }
  // Inter-system biases: constant, GPS the reference.
  EXPECT_EQ(clock.isb(System::Gps), 0.0);
  EXPECT_NE(clock.isb(System::Glonass), 0.0);
}

TEST(GnssSimModel, RandomFieldsHaveTheConfiguredCovariance) {
  // Correlation of values at separations of 0.25, 1 and 2 correlation lengths over 600 random
  // realisations: exp(-d^2/L^2) or exp(-d/L) within sampling error.
  for (const auto cov : {GnssRandomFieldConfig::Covariance::Gaussian, GnssRandomFieldConfig::Covariance::Exponential}) {
    GnssRandomFieldConfig fc{2.0, 10e3, cov, 0.0};
    const double ds[] = {0.0, 2.5e3, 10e3, 20e3};
    double sxx = 0.0, sxy[4] = {0, 0, 0, 0};
    const int runs = 600;
    for (int r = 0; r < runs; ++r) {
      const GnssRandomField f(fc, 1000 + static_cast<std::uint64_t>(r));
      const Eigen::Vector2d p0(1234.0, -567.0);
      const double v0 = f.value(p0, 0.0);
      sxx += v0 * v0;
      for (int k = 0; k < 4; ++k) {
        const double a = 0.7 * k;  // several directions
        sxy[k] += v0 * f.value(p0 + ds[k] * Eigen::Vector2d(std::cos(a), std::sin(a)), 0.0);
      }
    }
    EXPECT_NEAR(std::sqrt(sxx / runs), 2.0, 0.15);
    for (int k = 1; k < 4; ++k) {
      const double d = ds[k] / fc.correlationLength;
      const double model = cov == GnssRandomFieldConfig::Covariance::Gaussian ? std::exp(-d * d) : std::exp(-d);
      EXPECT_NEAR(sxy[k] / sxx, model, 0.1) << "separation " << ds[k];
    }
  }
  // Frozen flow: the field moves with the wind.
  const GnssRandomField f({1.0, 5e3, GnssRandomFieldConfig::Covariance::Gaussian, 20.0}, 9);
  const Eigen::Vector2d p(100.0, 200.0);
  EXPECT_NEAR(f.value(p + f.wind() * 30.0, 30.0), f.value(p, 0.0), 1e-12);
  EXPECT_NEAR(f.wind().norm(), 20.0, 1e-12);
}

TEST(GnssSimModel, AtmosphereErrorsCancelInDoubleDifferencesMoreTheCloserTheBase) {
  // Static rover at the origin, base at 0.5, 3 and 20 km: double differences (rover - base,
  // satellite - reference satellite) of the atmospheric errors the models leave are millimetres
  // at short range and grow with the distance, while the undifferenced errors are decimetres to
  // metres.
  std::vector<double> ddRms;
  double undiffRms = 0.0;
  for (const double distance : {500.0, 3000.0, 20000.0}) {
    GnssSimConfig cfg = quietConfig();
    cfg.rover.rate = 1.0;
    cfg.base.distance = distance;
    const CircleTrajectory traj(60.0, 0.0, 0.0, 0.0);
    GnssEpochGenerator gen(cfg, nagoyaNav(), traj, nagoyaFrame(), Eigen::Vector3d::Zero(), 11);
    std::map<std::int64_t, std::map<SatId, double>> rover, base;  // tag -> sat -> L1 error (m)
    double u2 = 0.0;
    int un = 0;
    while (auto e = gen.next()) {
      for (const GnssSatelliteTruth& st : e->truth.sats) {
        if (st.sat.system != System::Gps || st.azel.elevation < 15.0 * constants::kDegToRad) continue;
        const double err = (st.troposphere - st.troposphereModel) - (st.ionosphereL1 - st.ionosphereModelL1);
        (e->role == GnssReceiverRole::Rover ? rover : base)[e->obs.time.wholeSeconds()][st.sat] = err;
        u2 += err * err;
        ++un;
      }
    }
    double s2 = 0.0;
    int n = 0;
    for (const auto& [tag, rs] : rover) {
      const auto bit = base.find(tag);
      if (bit == base.end()) continue;
      const auto& bs = bit->second;
      std::optional<double> ref;
      for (const auto& [sat, er] : rs) {
        const auto b = bs.find(sat);
        if (b == bs.end()) continue;
        const double sd = er - b->second;
        if (!ref) {
          ref = sd;
          continue;
        }
        s2 += (sd - *ref) * (sd - *ref);
        ++n;
      }
    }
    ASSERT_GT(n, 200);
    ddRms.push_back(std::sqrt(s2 / n));
    undiffRms = std::sqrt(u2 / un);
  }
  std::printf("DD atmosphere error RMS: %.4f m at 0.5 km, %.4f m at 3 km, %.4f m at 20 km; undifferenced %.3f m\n",
              ddRms[0], ddRms[1], ddRms[2], undiffRms);
  EXPECT_LT(ddRms[0], ddRms[1]);
  EXPECT_LT(ddRms[1], ddRms[2]);
  EXPECT_LT(ddRms[1], 0.02);
  EXPECT_GT(undiffRms, 10.0 * ddRms[1]);
}

TEST(GnssSimModel, TrueOrbitsAreContinuousAndCloseToEveryBroadcastRecord) {
  // Blended records: no jump where the nearest record changes (Galileo every 10 min, GLONASS
  // every 30 min), velocity = derivative of position, and within metres of whatever record a
  // user's EphemerisStore selects.
  GnssSimConfig cfg;
  cfg.satelliteErrors.sisre.fill(0.0);
  const LocalFrame frame = nagoyaFrame();
  EphemerisStore store;
  store.add(nagoyaNav());
  const GnssConstellation con(store, cfg, frame.startTime, frame.startTime + 3600.0, 1);
  ASSERT_GT(con.satellites().size(), 60u);
  double worstJump = 0.0, worstVel = 0.0, worstBroadcast = 0.0, worstClock = 0.0;
  for (SatId sat : con.satellites()) {
    for (double t = 0.0; t <= 3600.0; t += 20.0) {
      const GpsTime at = frame.startTime + t;
      const auto a = con.state(sat, at);
      const auto b = con.state(sat, at + 0.5);
      const auto c = con.state(sat, at - 0.5);
      if (!a || !b || !c) continue;
      worstVel = std::max(worstVel, ((b->position - c->position) - a->velocity).norm());
      // One record at the three instants (the store may switch records between them).
      std::optional<SatelliteState> s, sb, sc;
      if (sat.system == System::Glonass) {
        if (const GlonassEphemeris* g = store.selectGlonass(sat, at)) {
          s = glonassSatelliteState(*g, at);
          sb = glonassSatelliteState(*g, at + 0.5);
          sc = glonassSatelliteState(*g, at - 0.5);
        }
      } else if (const KeplerEphemeris* k = store.selectKepler(sat, at)) {
        s = keplerSatelliteState(*k, at);
        sb = keplerSatelliteState(*k, at + 0.5);
        sc = keplerSatelliteState(*k, at - 0.5);
      }
      if (!s) continue;
      // The second difference over +-0.5 s is the acceleration times 0.25 s^2 (~0.15 m); the
      // blend must not add a kink to it.
      worstJump = std::max(worstJump, ((b->position - 2.0 * a->position + c->position) -
                                       (sb->position - 2.0 * s->position + sc->position)).norm());
      worstBroadcast = std::max(worstBroadcast, (s->position - a->position).norm());
      worstClock = std::max(worstClock, kC * std::abs(s->clockBias - a->clock));
    }
  }
  std::printf("blended truth: max second difference beyond the record's %.2e m, max velocity error %.2e m/s, max distance to the "
              "selected record %.2f m (clock %.2f m)\n",
              worstJump, worstVel, worstBroadcast, worstClock);
  EXPECT_LT(worstJump, 1e-4);
  EXPECT_LT(worstVel, 1e-3);
  EXPECT_LT(worstBroadcast, 10.0);
  EXPECT_LT(worstClock, 10.0);
}

}  // namespace
}  // namespace gvins::sim
