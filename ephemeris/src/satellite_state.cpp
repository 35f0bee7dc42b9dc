// Satellite position, velocity and clock from broadcast ephemerides.
//
// Keplerian records: IS-GPS-200N table 20-IV (also used by QZSS, IS-QZSS-PNT-005; by Galileo, OS SIS
// ICD 2.1 5.1.1; and by BeiDou MEO/IGSO, BDS-SIS-ICD-B1I 3.0 5.2.4). BeiDou GEO satellites are
// computed in an inertial-like frame and rotated by -5 deg about x and by the Earth rotation since
// toe (BDS-SIS-ICD-B1I 3.0 5.2.4, user algorithm for GEO satellites). Velocities are the exact time
// derivatives of these formulas (the broadcast harmonic corrections included), not differences.
//
// GLONASS: fourth-order Runge-Kutta integration of the PZ-90 equations of motion with the J2 term
// and the broadcast luni-solar accelerations held constant (GLONASS ICD ed. 5.1, appendix A.3.1.2).
#include <cmath>

#include "gvins/base/constants.hpp"
#include "gvins/ephemeris/satellite_state.hpp"

namespace gvins {
namespace {

struct KeplerConstants {
  double sqrtGm;
  double omegaE;
  double f;  // relativistic clock constant -2 sqrt(GM)/c^2
};

// sin and cos of a small angle |d| < 1e-4 rad by their series, sin d = d - d^3/6 and
// cos d = 1 - d^2/2 + d^4/24 (truncation < d^5/120 < 1e-22: the libm values to rounding).
void smallAngleSinCos(double d, double& s, double& c) {
  const double d2 = d * d;
  s = d * (1.0 - d2 * (1.0 / 6.0));
  c = 1.0 - d2 * (0.5 - d2 * (1.0 / 24.0));
}

KeplerConstants keplerConstants(System s) {
  switch (s) {
    case System::Galileo:
      return {std::sqrt(constants::kGalileoGm), constants::kGalileoOmegaE, constants::kGalileoF};
    case System::BeiDou:
      return {std::sqrt(constants::kBeiDouGm), constants::kBeiDouOmegaE, constants::kBeiDouF};
    default:  // GPS, QZSS (IS-QZSS-PNT-005 uses the GPS values)
      return {std::sqrt(constants::kGpsGm), constants::kGpsOmegaE, constants::kGpsF};
  }
}

// sin(-5 deg), cos(-5 deg): BeiDou GEO frame tilt (BDS-SIS-ICD-B1I 3.0, 5.2.4).
const double kSinMinus5 = std::sin(-5.0 * constants::kDegToRad);
const double kCosMinus5 = std::cos(-5.0 * constants::kDegToRad);

}  // namespace

SatelliteState keplerSatelliteState(const KeplerEphemeris& eph, const GpsTime& t) {
  SatelliteState st;
  st.accuracy = eph.ura;
  st.iode = eph.iode;
  st.healthy = isHealthy(eph);
  const double e = eph.e;
  if (!(eph.sqrtA > 0.0) || !(e >= 0.0 && e < 1.0) || !std::isfinite(eph.sqrtA)) {
    st.healthy = false;  // no orbit can be computed from such a record
    return st;
  }
  const KeplerConstants k = keplerConstants(eph.sat.system);
  const double a = eph.sqrtA * eph.sqrtA;
  const double tk = t - eph.toe;
  const double tc = t - eph.toc;

  // Mean motion and Kepler's equation (Newton's method from E0 = M + e sin M). Newton converges
  // quadratically: after a step of size d the error is about e d^2 / (2 (1 - e)), below 1e-19 rad
  // once |d| < 1e-9, so that is where it stops (two or three steps for GNSS orbits).
  const double n = k.sqrtGm / (a * eph.sqrtA) + eph.deltaN;
  const double m = eph.m0 + n * tk;
  // Once a step is below 1e-4 rad, sin/cos of E - d follow from the angle-difference formulas
  // with the small-angle series: the same values to rounding, one sincos call fewer per iteration.
  double ecc = m + e * std::sin(m);
  double sinE = std::sin(ecc), cosE = std::cos(ecc);
  for (int it = 0; it < 30; ++it) {
    const double d = (ecc - e * sinE - m) / (1.0 - e * cosE);
    ecc -= d;
    if (std::fabs(d) < 1e-4) {
      double sd, cd;
      smallAngleSinCos(d, sd, cd);
      const double s = sinE * cd - cosE * sd;
      cosE = cosE * cd + sinE * sd;
      sinE = s;
    } else {
      sinE = std::sin(ecc);
      cosE = std::cos(ecc);
    }
    if (std::fabs(d) < 1e-9) break;
  }
  const double oneMinusECosE = 1.0 - e * cosE;
  const double eDot = n / oneMinusECosE;
  const double sqrt1mE2 = std::sqrt(1.0 - e * e);

  // True anomaly nu and argument of latitude phi = nu + omega, by their sines and cosines:
  // sin nu = sqrt(1-e^2) sin E / (1 - e cos E), cos nu = (cos E - e) / (1 - e cos E).
  const double sinNu = sqrt1mE2 * sinE / oneMinusECosE;
  const double cosNu = (cosE - e) / oneMinusECosE;
  const double sinW = std::sin(eph.omega), cosW = std::cos(eph.omega);
  const double sinPhi = sinNu * cosW + cosNu * sinW;
  const double cosPhi = cosNu * cosW - sinNu * sinW;
  const double nuDot = eDot * sqrt1mE2 / oneMinusECosE;
  const double s2 = 2.0 * sinPhi * cosPhi, c2 = cosPhi * cosPhi - sinPhi * sinPhi;
  const double du = eph.cus * s2 + eph.cuc * c2;
  const double r = a * oneMinusECosE + eph.crs * s2 + eph.crc * c2;
  const double inc = eph.i0 + eph.iDot * tk + eph.cis * s2 + eph.cic * c2;
  const double uDot = nuDot * (1.0 + 2.0 * (eph.cus * c2 - eph.cuc * s2));
  const double rDot = a * e * sinE * eDot + 2.0 * nuDot * (eph.crs * c2 - eph.crc * s2);
  const double incDot = eph.iDot + 2.0 * nuDot * (eph.cis * c2 - eph.cic * s2);

  // Position and velocity in the orbital plane.
  // u = phi + du (du ~ 1e-5 rad).
  // |du| < 1e-4 rad for every GNSS orbit (C_us, C_uc ~ 1e-5): the same series as above.
  double sinDu, cosDu;
  if (std::fabs(du) < 1e-4) {
    smallAngleSinCos(du, sinDu, cosDu);
  } else {
    sinDu = std::sin(du);
    cosDu = std::cos(du);
  }
  const double su = sinPhi * cosDu + cosPhi * sinDu, cu = cosPhi * cosDu - sinPhi * sinDu;
  const double xp = r * cu, yp = r * su;
  const double xpDot = rDot * cu - r * uDot * su;
  const double ypDot = rDot * su + r * uDot * cu;

  const bool geo = isBeiDouGeo(eph.sat);
  // Longitude of the ascending node: Earth-fixed for all but BeiDou GEO, which first uses an
  // inertial-like node and is rotated into the Earth-fixed frame below.
  const double omegaRate = geo ? eph.omegaDot : eph.omegaDot - k.omegaE;
  const double bigOmega = eph.omega0 + omegaRate * tk - k.omegaE * eph.toeSeconds;
  const double sO = std::sin(bigOmega), cO = std::cos(bigOmega);
  const double si = std::sin(inc), ci = std::cos(inc);
  Eigen::Vector3d p(xp * cO - yp * ci * sO, xp * sO + yp * ci * cO, yp * si);
  Eigen::Vector3d v(xpDot * cO - ypDot * ci * sO + yp * si * sO * incDot - omegaRate * p.y(),
                    xpDot * sO + ypDot * ci * cO - yp * si * cO * incDot + omegaRate * p.x(),
                    ypDot * si + yp * ci * incDot);
  if (geo) {
    // P = Rz(omegaE tk) Rx(-5 deg) Pg; V = Rz Rx Vg + omegaE [Py, -Px, 0].
    const double th = k.omegaE * tk;
    const double sT = std::sin(th), cT = std::cos(th);
    const Eigen::Vector3d q(p.x(), p.y() * kCosMinus5 + p.z() * kSinMinus5,
                            -p.y() * kSinMinus5 + p.z() * kCosMinus5);
    const Eigen::Vector3d qv(v.x(), v.y() * kCosMinus5 + v.z() * kSinMinus5,
                             -v.y() * kSinMinus5 + v.z() * kCosMinus5);
    p = Eigen::Vector3d(cT * q.x() + sT * q.y(), -sT * q.x() + cT * q.y(), q.z());
    v = Eigen::Vector3d(cT * qv.x() + sT * qv.y() + k.omegaE * p.y(),
                        -sT * qv.x() + cT * qv.y() - k.omegaE * p.x(), qv.z());
  }
  st.position = p;
  st.velocity = v;

  // Clock polynomial plus the relativistic eccentricity term F e sqrt(A) sin(E)
  // (IS-GPS-200N 20.3.3.3.3.1) and its rate.
  st.clockBias = eph.af0 + eph.af1 * tc + eph.af2 * tc * tc + k.f * e * eph.sqrtA * sinE;
  st.clockDrift = eph.af1 + 2.0 * eph.af2 * tc + k.f * e * eph.sqrtA * cosE * eDot;
  return st;
}

namespace {

// State derivative of the GLONASS equations of motion in PZ-90 (GLONASS ICD 5.1, A.3.1.2):
//   dv/dt = -GM/r^3 r - 3/2 J2 GM ae^2 / r^5 [x(1-5z^2/r^2), y(1-5z^2/r^2), z(3-5z^2/r^2)]
//           + omega^2 [x, y, 0] + 2 omega [vy, -vx, 0] + luni-solar acceleration.

inline void glonassDerivative(const double* s, const double* acc, double* d) {
  constexpr double gm = constants::kGlonassGm;
  constexpr double w = constants::kGlonassOmegaE;
  constexpr double c20 = 1.5 * constants::kGlonassJ2 * constants::kGlonassGm * constants::kGlonassAe *
                         constants::kGlonassAe;
  const double r2 = s[0] * s[0] + s[1] * s[1] + s[2] * s[2];
  if (!(r2 > 1.0)) {  // degenerate state (corrupt record): stop rather than divide by zero
    for (int i = 0; i < 6; ++i) d[i] = 0.0;
    return;
  }
  const double r = std::sqrt(r2);
  const double r3 = r2 * r;
  const double j2 = c20 / (r3 * r2);  // 3/2 J2 GM ae^2 / r^5
  const double z2r2 = 5.0 * s[2] * s[2] / r2;
  const double cxy = -gm / r3 - j2 * (1.0 - z2r2);
  d[0] = s[3];
  d[1] = s[4];
  d[2] = s[5];
  d[3] = (cxy + w * w) * s[0] + 2.0 * w * s[4] + acc[0];
  d[4] = (cxy + w * w) * s[1] - 2.0 * w * s[3] + acc[1];
  d[5] = (-gm / r3 - j2 * (3.0 - z2r2)) * s[2] + acc[2];
}

}  // namespace

SatelliteState glonassSatelliteState(const GlonassEphemeris& eph, const GpsTime& t) {
  return glonassSatelliteState(eph, t, kGlonassDefaultStep);
}

SatelliteState glonassSatelliteState(const GlonassEphemeris& eph, const GpsTime& t, double maxStep) {
  SatelliteState st;
  st.accuracy = eph.accuracy;
  st.iode = eph.iode;
  st.healthy = isHealthy(eph);
  const double dt = t - eph.toe;
  double s[6] = {eph.position.x(), eph.position.y(), eph.position.z(),
                 eph.velocity.x(), eph.velocity.y(), eph.velocity.z()};
  const double acc[3] = {eph.acceleration.x(), eph.acceleration.y(), eph.acceleration.z()};
  if (!(maxStep > 0.0)) maxStep = kGlonassDefaultStep;
  // Equal steps no longer than maxStep; the step count is bounded so that a corrupt record or a
  // time far from tb cannot make this loop run for long (one day is 1440 steps of 60 s).
  double steps = std::ceil(std::fabs(dt) / maxStep);
  if (!std::isfinite(steps) || steps > 4000.0) {
    st.healthy = false;
    return st;
  }
  const int nSteps = static_cast<int>(steps);
  if (nSteps > 0) {
    const double h = dt / nSteps;
    double k1[6], k2[6], k3[6], k4[6], w[6];
    for (int step = 0; step < nSteps; ++step) {
      glonassDerivative(s, acc, k1);
      for (int i = 0; i < 6; ++i) w[i] = s[i] + 0.5 * h * k1[i];
      glonassDerivative(w, acc, k2);
      for (int i = 0; i < 6; ++i) w[i] = s[i] + 0.5 * h * k2[i];
      glonassDerivative(w, acc, k3);
      for (int i = 0; i < 6; ++i) w[i] = s[i] + h * k3[i];
      glonassDerivative(w, acc, k4);
      for (int i = 0; i < 6; ++i) s[i] += h / 6.0 * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i]);
    }
  }
  st.position = Eigen::Vector3d(s[0], s[1], s[2]);
  st.velocity = Eigen::Vector3d(s[3], s[4], s[5]);
  // Satellite time minus GLONASS time = -tauN + gammaN (t - tb) (GLONASS ICD 5.1, 3.3.3); the
  // relativistic effects are part of the broadcast gammaN/tauN, so no eccentricity term is added.
  st.clockBias = -eph.tauN + eph.gammaN * dt;
  st.clockDrift = eph.gammaN;
  return st;
}

}  // namespace gvins
