// GNSS simulator, measurement model: every pseudorange, carrier phase and Doppler is rebuilt
// from truth with independent code (the broadcast ephemerides through EphemerisStore, the
// library's troposphere/Klobuchar/Sagnac functions, the trajectory itself) and what is left must
// equal the simulated error terms; ambiguities are integers; Doppler agrees with the phase rate.
#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "gvins/base/constants.hpp"
#include "gvins/base/local_frame.hpp"
#include "gvins/gnss/klobuchar.hpp"
#include "gvins/gnss/sagnac.hpp"
#include "gvins/gnss/troposphere.hpp"
#include "gvins/sim/gnss_epoch_generator.hpp"
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
        // Carrier phase: the same terms with the ionosphere advancing, plus N whole cycles.
        const double phaseModelled = rho + rxClock - kC * bs->clockBias + tropoModel - ionoModel * std::pow(1575.42e6 / f, 2);
        const double phaseErrors = (st.troposphere - st.troposphereModel) - (g.ionosphere - ionoModel * std::pow(1575.42e6 / f, 2)) +
                                   shapiro + g.multipathPhase + st.nlosBias + g.phaseNoise;
        EXPECT_NEAR((o.carrierPhase - static_cast<double>(g.ambiguity)) * lambda - phaseModelled, phaseErrors, 5e-4)
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

}  // namespace
}  // namespace gvins::sim
