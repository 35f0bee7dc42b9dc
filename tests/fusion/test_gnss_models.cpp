// Jacobians of every GNSS fusion residual (pseudorange, Doppler, SD pseudorange, DD phase,
// loosely-coupled velocity, frame-initialisation position) w.r.t. the newest IMU state (through
// the integration terms γ, β, α and their bias corrections), the frame [ψ, p_NW], the lever arm and
// the clocks, against central finite differences of the residual functions themselves.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <vector>

#include "gvins/base/constants.hpp"
#include "gvins/base/geodetic.hpp"
#include "gvins/fusion/gnss_measurement_models.hpp"
#include "gvins/vio/imu_integration.hpp"
#include "gvins/vio/so3.hpp"

namespace gvins::fusion {
namespace {

using Eigen::Vector3d;

/// 0.4 s of smooth synthetic IMU samples at 200 Hz (rotating, accelerating).
std::vector<vio::ImuSample> syntheticImu(std::int64_t t0, std::int64_t t1) {
  std::vector<vio::ImuSample> out;
  for (std::int64_t t = t0 - 20000000; t <= t1 + 20000000; t += 5000000) {
    const double s = static_cast<double>(t - t0) * 1e-9;
    vio::ImuSample m;
    m.t_ns = t;
    m.gyro = Vector3d(0.3 * std::sin(2.0 * s), -0.2 + 0.1 * s, 0.5 * std::cos(1.5 * s));
    m.accel = Vector3d(0.4 + std::sin(3.0 * s), -0.3 * s, 9.7 + 0.2 * std::cos(s));
    out.push_back(m);
  }
  return out;
}

struct Fixture {
  GnssStateValues s;
  Fixture(bool withIntegration) {
    const std::int64_t t0 = 1000000000000LL, t1 = t0 + 400000000LL;
    s.newest.t_ns = t1;
    s.newest.R_WI = vio::so3::exp(Vector3d(0.2, -0.1, 1.3));
    s.newest.p_WI = Vector3d(12.0, -7.0, 3.0);
    s.newest.v_WI = Vector3d(4.0, 2.5, -0.3);
    s.newest.bg = Vector3d(0.01, -0.02, 0.005);
    s.newest.ba = Vector3d(0.05, 0.02, -0.08);
    s.gravity = Vector3d(0.0, 0.0, -9.80);
    s.omegaMeasured = Vector3d(0.3, -0.7, 0.9);
    s.yaw = 0.7;
    s.p_NW = Vector3d(3.0, -2.0, 1.5);
    s.lever = Vector3d(0.3, -0.1, 0.25);
    s.anchor = GnssAnchor::at(geodeticToEcef(geodeticFromDegrees(35.1, 136.9, 60.0)));
    if (withIntegration) {
      const auto samples = syntheticImu(t0, t1);
      vio::ImuIntegration integ(vio::ImuNoise{}, s.newest.bg, s.newest.ba);
      integ.integrate(samples, t0, t1);
      s.integration = integ;
    }
  }
};

SatelliteModel satellite(const Vector3d& x) {
  SatelliteModel m;
  m.sat = SatId{System::Gps, 5};
  m.clock = 1;
  const Vector3d up = x.normalized();
  const Vector3d east = Vector3d::UnitZ().cross(up).normalized();
  m.position = x + 2.1e7 * (0.6 * up + 0.5 * east + 0.3 * up.cross(east)).normalized();
  m.velocity = Vector3d(1200.0, -2500.0, 1800.0);
  m.clockBias = 1.2e-4;
  m.clockDrift = 2e-11;
  m.groupDelay = -5e-9;
  m.troposphere = 3.1;
  m.ionosphere = 4.2;
  m.pseudorange = (m.position - x).norm() + 12345.0;
  m.hasDoppler = true;
  m.rangeRate = -350.0;
  m.codeVariance = 0.36;
  m.dopplerVariance = 0.01;
  return m;
}

/// Compares H (analytic ∂h/∂x) with −∂r/∂x by central differences for every block.
void checkRow(const std::function<GnssRow(const GnssStateValues&)>& f, const GnssStateValues& s0, double tol,
              const char* what) {
  const GnssRow r0 = f(s0);
  const double h = 1e-4;  // ranges are ~2e7 m: rounding 4e-9 m / 2h stays < 2e-5
  for (int i = 0; i < 15; ++i) {
    vio::Vector15d d = vio::Vector15d::Zero();
    d[i] = h;
    GnssStateValues sp = s0, sm = s0;
    vio::boxPlus(sp.newest, d);
    vio::boxPlus(sm.newest, -d);
    const double num = -(f(sp).residual - f(sm).residual) / (2 * h);
    EXPECT_NEAR(r0.H_imu[i], num, tol * std::max(1.0, std::abs(num))) << what << " imu column " << i;
  }
  for (int i = 0; i < 4; ++i) {
    GnssStateValues sp = s0, sm = s0;
    if (i == 0) {
      sp.yaw += h;
      sm.yaw -= h;
    } else {
      sp.p_NW[i - 1] += h;
      sm.p_NW[i - 1] -= h;
    }
    const double num = -(f(sp).residual - f(sm).residual) / (2 * h);
    EXPECT_NEAR(r0.H_frame[i], num, tol * std::max(1.0, std::abs(num))) << what << " frame column " << i;
  }
  for (int i = 0; i < 3; ++i) {
    GnssStateValues sp = s0, sm = s0;
    sp.lever[i] += h;
    sm.lever[i] -= h;
    const double num = -(f(sp).residual - f(sm).residual) / (2 * h);
    EXPECT_NEAR(r0.H_lever[i], num, tol * std::max(1.0, std::abs(num))) << what << " lever column " << i;
  }
}

class GnssModelJacobians : public ::testing::TestWithParam<bool> {};

TEST_P(GnssModelJacobians, Pseudorange) {
  Fixture fx(GetParam());
  const SatelliteModel m = satellite(antennaKinematics(fx.s).x_E);
  checkRow([&](const GnssStateValues& s) { return pseudorangeRow(m, antennaKinematics(s), 100.0); }, fx.s, 1e-4,
           "psr");
  // Clock: +1 on its bias entry, the residual moves by −δ.
  const GnssRow r = pseudorangeRow(m, antennaKinematics(fx.s), 100.0);
  EXPECT_EQ(r.clockBias, 1);
  EXPECT_NEAR(pseudorangeRow(m, antennaKinematics(fx.s), 101.0).residual, r.residual - 1.0, 1e-6);
  // A non-trivial Jacobian (not all zero): the antenna position moves the range 1:1 along the LOS.
  EXPECT_NEAR(r.H_frame.tail<3>().norm(), 1.0, 1e-4);
}

// Undifferenced carrier phase (vio+dopp+ppp): the geometry of the code row without group delay
// and ionosphere, +1 on the clock bias and on the float ambiguity, the wet mapping function on the
// zenith wet delay state (also in the code row).
TEST_P(GnssModelJacobians, CarrierPhaseWithAmbiguityAndWetDelay) {
  Fixture fx(GetParam());
  SatelliteModel m = satellite(antennaKinematics(fx.s).x_E);
  m.ionosphere = 0.0;
  m.ionosphereFree = true;
  m.mapWet = 3.7;
  m.hasCarrier = true;
  m.carrierRange = m.pseudorange + 0.8 - constants::kSpeedOfLight * m.groupDelay;  // ambiguity 0.8 m
  m.phaseVariance = 1e-4;
  checkRow([&](const GnssStateValues& s) { return carrierPhaseRow(m, antennaKinematics(s), 100.0, 0.5); }, fx.s, 1e-4,
           "phase");
  const AntennaKinematics k = antennaKinematics(fx.s);
  const GnssRow r = carrierPhaseRow(m, k, 100.0, 0.5);
  const GnssRow code = pseudorangeRow(m, k, 100.0);
  EXPECT_EQ(r.clockBias, 1);
  EXPECT_EQ(r.ambiguity, -1);  // set by the fusion
  EXPECT_DOUBLE_EQ(r.variance, 1e-4);
  // Same geometry as the code; the residual differs by the ambiguity (0.8 true − 0.5 assumed).
  EXPECT_NEAR((r.H_imu - code.H_imu).norm(), 0.0, 1e-12);
  EXPECT_NEAR((r.H_frame - code.H_frame).norm(), 0.0, 1e-12);
  EXPECT_NEAR(r.residual - code.residual, 0.3, 1e-6);
  EXPECT_NEAR(carrierPhaseRow(m, k, 100.0, 0.6).residual, r.residual - 0.1, 1e-6);
  EXPECT_NEAR(carrierPhaseRow(m, k, 101.0, 0.5).residual, r.residual - 1.0, 1e-6);
  // Zenith wet delay z enters as T + m_w z (the fusion adds m_w ẑ to the modelled delay).
  for (auto row : {+[](const SatelliteModel& x, const AntennaKinematics& kk) { return carrierPhaseRow(x, kk, 100.0, 0.5); },
                   +[](const SatelliteModel& x, const AntennaKinematics& kk) { return pseudorangeRow(x, kk, 100.0); }}) {
    const double dz = 0.1;  // the delay is linear in z; a larger step keeps the 2e7 m rounding small
    SatelliteModel mp = m, mm = m;
    mp.troposphere += m.mapWet * dz;
    mm.troposphere -= m.mapWet * dz;
    EXPECT_NEAR(row(m, k).H_tropo, -(row(mp, k).residual - row(mm, k).residual) / (2 * dz), 1e-6 / dz);
    EXPECT_DOUBLE_EQ(row(m, k).H_tropo, 3.7);
  }
}

TEST_P(GnssModelJacobians, DopplerIncludingLeverArmRotation) {
  Fixture fx(GetParam());
  const SatelliteModel m = satellite(antennaKinematics(fx.s).x_E);
  checkRow([&](const GnssStateValues& s) { return dopplerRow(m, antennaKinematics(s), -30.0); }, fx.s, 1e-5, "dopp");
  const GnssRow r = dopplerRow(m, antennaKinematics(fx.s), -30.0);
  EXPECT_EQ(r.H_drift, 1.0);
  EXPECT_NEAR(dopplerRow(m, antennaKinematics(fx.s), -29.5).residual, r.residual - 0.5, 1e-9);
  // The lever arm enters the Doppler through R (ω × l): non-zero with rotation.
  EXPECT_GT(r.H_lever.norm(), 0.02);
}

TEST_P(GnssModelJacobians, SingleDifferencedPseudorange) {
  Fixture fx(GetParam());
  const Vector3d x = antennaKinematics(fx.s).x_E;
  const SatelliteModel m = satellite(x);
  SingleDifference sd;
  sd.sat = m.sat;
  sd.satPosition = m.position;
  sd.satClock = constants::kSpeedOfLight * 1e-4;
  sd.troposphere = 2.5;
  sd.hasCode = true;
  sd.roverCode = (m.position - x).norm() + 30.0;
  sd.baseCodeOmc = 7.0;
  sd.codeVariance = 0.5;
  checkRow([&](const GnssStateValues& s) { return sdPseudorangeRow(sd, antennaKinematics(s), 10.0, 3.0); }, fx.s,
           1e-4, "dpsr");
}

TEST_P(GnssModelJacobians, DoubleDifferencedPhase) {
  Fixture fx(GetParam());
  const Vector3d x = antennaKinematics(fx.s).x_E;
  DdEpoch e;
  for (int j = 0; j < 2; ++j) {
    SatelliteModel m = satellite(x);
    if (j == 1) m.position = x + 2.2e7 * (x.normalized() + Vector3d(0.2, -0.4, 0.1)).normalized();
    SingleDifference sd;
    sd.sat = SatId{System::Gps, 5 + j};
    sd.satPosition = m.position;
    sd.hasPhase = true;
    sd.roverPhase = (m.position - x).norm() + 0.3 * j;
    sd.basePhaseOmc = 1.0 + j;
    sd.phaseVariance = 1e-4;
    sd.wavelength = 0.19;
    e.sd.push_back(sd);
  }
  DoubleDifference dd;
  dd.reference = 0;
  dd.satellite = 1;
  dd.fixedCycles = 3.0;
  dd.ambiguityMeters = 0.57;
  checkRow([&](const GnssStateValues& s) { return ddPhaseRow(e, dd, antennaKinematics(s)); }, fx.s, 1e-4, "ddcp");
}

TEST_P(GnssModelJacobians, VelocityAndPosition) {
  Fixture fx(GetParam());
  for (int a = 0; a < 3; ++a) {
    checkRow([&](const GnssStateValues& s) { return velocityRow(Vector3d(1, 2, 3), a, antennaKinematics(s)); }, fx.s,
             1e-5, "gpsvel");
    checkRow([&](const GnssStateValues& s) { return positionRow(Vector3d(1, 2, 3), a, antennaKinematics(s)); }, fx.s,
             1e-5, "frame position");
  }
}

INSTANTIATE_TEST_SUITE_P(WithAndWithoutIntegration, GnssModelJacobians, ::testing::Values(true, false));

TEST(GnssModels, IntegrationMovesTheStateBackInTime) {
  // With integration the antenna is where the IMU was 0.4 s earlier (≈ v·0.4 s away from the
  // newest-state antenna), without it the newest pose is used.
  Fixture with(true), without(false);
  const AntennaKinematics a = antennaKinematics(with.s), b = antennaKinematics(without.s);
  const double moved = (a.p_N - b.p_N).norm();
  EXPECT_GT(moved, 0.5 * 0.4 * with.s.newest.v_WI.norm());
  EXPECT_LT(moved, 2.0 * 0.4 * with.s.newest.v_WI.norm());
  EXPECT_GT(a.integrationCovariance.trace(), 0.0);
  EXPECT_EQ(b.integrationCovariance.trace(), 0.0);
}

}  // namespace
}  // namespace gvins::fusion
