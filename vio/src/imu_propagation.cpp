#include "gvins/vio/imu_propagation.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Geometry>

#include "gvins/vio/so3.hpp"

namespace gvins::vio {

using Eigen::Matrix3d;
using Eigen::Vector3d;

namespace {
// Gauss-Legendre nodes on [0, 1] and the 4th-order Magnus commutator weight.
const double kGaussA = 0.5 - std::sqrt(3.0) / 6.0;
const double kGaussB = 0.5 + std::sqrt(3.0) / 6.0;
const double kMagnusC = std::sqrt(3.0) / 12.0;

[[noreturn]] void notIncreasing(std::int64_t t) {
  throw std::invalid_argument("IMU samples not strictly increasing in time at " + std::to_string(t));
}

void checkCoverage(std::span<const ImuSample> samples, std::int64_t t0, std::int64_t t1) {
  if (t1 < t0) {
    throw std::invalid_argument("IMU integration backwards in time: " + std::to_string(t0) + " -> " +
                                std::to_string(t1));
  }
  if (samples.empty()) throw std::invalid_argument("IMU integration without samples");
  if (samples.front().t_ns > t0 || samples.back().t_ns < t1) {
    throw std::invalid_argument("IMU samples [" + std::to_string(samples.front().t_ns) + ", " +
                                std::to_string(samples.back().t_ns) + "] do not cover [" + std::to_string(t0) +
                                ", " + std::to_string(t1) + "]");
  }
}

// Index of the last sample with stamp <= t (samples[0].t_ns <= t assumed).
std::size_t lastAtOrBefore(std::span<const ImuSample> s, std::int64_t t) {
  std::size_t lo = 0, hi = s.size();
  while (hi - lo > 1) {
    const std::size_t mid = (lo + hi) / 2;
    if (s[mid].t_ns <= t) lo = mid; else hi = mid;
  }
  return lo;
}

// Interpolation nodes for the sample interval [k, k+1] (k+1 < size), time origin at sample k.
void setNodes(std::span<const ImuSample> s, std::size_t k, ImuInterval& m) {
  const std::int64_t tk = s[k].t_ns;
  const std::int64_t len = s[k + 1].t_ns - tk;
  if (len <= 0) notIncreasing(s[k + 1].t_ns);
  const bool prev = k > 0 && s[k].t_ns - s[k - 1].t_ns > 0 && s[k].t_ns - s[k - 1].t_ns <= 2 * len;
  const bool next = k + 2 < s.size() && s[k + 2].t_ns - s[k + 1].t_ns > 0 && s[k + 2].t_ns - s[k + 1].t_ns <= 2 * len;
  if (k > 0 && s[k].t_ns <= s[k - 1].t_ns) notIncreasing(s[k].t_ns);
  if (k + 2 < s.size() && s[k + 2].t_ns <= s[k + 1].t_ns) notIncreasing(s[k + 2].t_ns);
  m.nodes = 0;
  auto add = [&](const ImuSample& x) {
    m.tau[m.nodes] = static_cast<double>(x.t_ns - tk) * 1e-9;
    m.gyro[m.nodes] = x.gyro;
    m.accel[m.nodes] = x.accel;
    ++m.nodes;
  };
  if (prev) add(s[k - 1]);
  add(s[k]);
  add(s[k + 1]);
  if (next) add(s[k + 2]);
}
}  // namespace

void ImuInterval::weights(double t, double w[4]) const {
  for (int i = 0; i < nodes; ++i) {
    double v = 1.0;
    for (int j = 0; j < nodes; ++j) {
      if (j != i) v *= (t - tau[j]) / (tau[i] - tau[j]);
    }
    w[i] = v;
  }
}

Vector3d ImuInterval::gyroAt(double t) const {
  double w[4];
  weights(t, w);
  Vector3d out = w[0] * gyro[0];
  for (int i = 1; i < nodes; ++i) out += w[i] * gyro[i];
  return out;
}

Vector3d ImuInterval::accelAt(double t) const {
  double w[4];
  weights(t, w);
  Vector3d out = w[0] * accel[0];
  for (int i = 1; i < nodes; ++i) out += w[i] * accel[i];
  return out;
}

void integrateImuInterval(const ImuInterval& m, const Vector3d& bg, const Vector3d& ba,
                          const Vector3d& gravity, Matrix3d& R, Vector3d& p, Vector3d& v,
                          ImuStepJacobians* J) {
  const double h = m.dt, hm = 0.5 * h;
  // Bias-corrected signals at the Gauss nodes of [0, h] and [0, h/2] and at 0, h/2, h.
  const Vector3d wA = m.gyroAt(m.t0 + kGaussA * h) - bg, wB = m.gyroAt(m.t0 + kGaussB * h) - bg;
  const Vector3d wmA = m.gyroAt(m.t0 + kGaussA * hm) - bg, wmB = m.gyroAt(m.t0 + kGaussB * hm) - bg;
  const Vector3d a0 = m.accelAt(m.t0) - ba, am = m.accelAt(m.t0 + hm) - ba, a1 = m.accelAt(m.t0 + h) - ba;
  const Vector3d phi1 = 0.5 * h * (wA + wB) + (kMagnusC * h * h) * wA.cross(wB);
  const Vector3d phiM = 0.5 * hm * (wmA + wmB) + (kMagnusC * hm * hm) * wmA.cross(wmB);
  const Matrix3d dR1 = so3::exp(phi1);
  const Matrix3d dRm = so3::exp(phiM);
  const Vector3d xm = dRm * am, x1 = dR1 * a1;  // accelerations in the start frame
  const Vector3d f0 = R * a0, fm = R * xm, f1 = R * x1;

  if (J) {
    // Local rotation error: R = R_est Exp(dtheta), so d(R Exp(dth) x)/d dth = -R [x]x.
    // Bias: dR(bg + d) = dR Exp(Jr(phi) dphi/dbg d), and (wA - d) x (wB - d) ~ wA x wB + [wB - wA]x d.
    const Matrix3d I = Matrix3d::Identity();
    const Matrix3d dPhi1_dbg = -h * I + (kMagnusC * h * h) * so3::skew(wB - wA);
    const Matrix3d dPhiM_dbg = -hm * I + (kMagnusC * hm * hm) * so3::skew(wmB - wmA);
    const Matrix3d M1 = so3::rightJacobian(phi1) * dPhi1_dbg;
    const Matrix3d Mm = so3::rightJacobian(phiM) * dPhiM_dbg;
    const Matrix3d Rm = R * dRm, R1 = R * dR1;
    const Matrix3d df0_dth = -R * so3::skew(a0), dfm_dth = -R * so3::skew(xm), df1_dth = -R * so3::skew(x1);
    const Matrix3d dfm_dbg = -Rm * so3::skew(am) * Mm;
    const Matrix3d df1_dbg = -R1 * so3::skew(a1) * M1;
    const Matrix3d& df0_dba = R;  // all three with a minus sign, applied below
    const Matrix3d& dfm_dba = Rm;
    const Matrix3d& df1_dba = R1;

    constexpr int T = 0, P = 3, V = 6;
    auto& A = J->A;
    auto& Bg = J->Bg;
    auto& Ba = J->Ba;
    A.setIdentity();
    Bg.setZero();
    Ba.setZero();
    A.block<3, 3>(T, T) = dR1.transpose();
    Bg.block<3, 3>(T, 0) = M1;
    A.block<3, 3>(V, T) = (h / 6.0) * (df0_dth + 4.0 * dfm_dth + df1_dth);
    Bg.block<3, 3>(V, 0) = (h / 6.0) * (4.0 * dfm_dbg + df1_dbg);
    Ba.block<3, 3>(V, 0) = -(h / 6.0) * (df0_dba + 4.0 * dfm_dba + df1_dba);
    A.block<3, 3>(P, V) = h * I;
    A.block<3, 3>(P, T) = (h * h / 6.0) * (df0_dth + 2.0 * dfm_dth);
    Bg.block<3, 3>(P, 0) = (h * h / 3.0) * dfm_dbg;
    Ba.block<3, 3>(P, 0) = -(h * h / 6.0) * (df0_dba + 2.0 * dfm_dba);
  }

  p += v * h + 0.5 * h * h * gravity + (h * h / 6.0) * (f0 + 2.0 * fm);
  v += gravity * h + (h / 6.0) * (f0 + 4.0 * fm + f1);
  R = R * dR1;
}

void forEachImuInterval(std::span<const ImuSample> samples, std::int64_t t0_ns, std::int64_t t1_ns,
                        const std::function<void(const ImuInterval&)>& fn) {
  checkCoverage(samples, t0_ns, t1_ns);
  if (t1_ns == t0_ns) return;
  std::size_t k = lastAtOrBefore(samples, t0_ns);
  if (k + 1 == samples.size()) --k;  // t0 == last stamp is impossible here since t1 > t0
  std::int64_t t = t0_ns;
  ImuInterval m;
  while (t < t1_ns) {
    setNodes(samples, k, m);
    const std::int64_t end = std::min(samples[k + 1].t_ns, t1_ns);
    m.t0 = static_cast<double>(t - samples[k].t_ns) * 1e-9;
    m.dt = static_cast<double>(end - t) * 1e-9;
    if (end > t) fn(m);
    t = end;
    ++k;
  }
}

ImuSample interpolateImu(std::span<const ImuSample> samples, std::int64_t t_ns) {
  checkCoverage(samples, t_ns, t_ns);
  std::size_t k = lastAtOrBefore(samples, t_ns);
  if (samples[k].t_ns == t_ns) return samples[k];
  ImuInterval m;
  setNodes(samples, k, m);
  const double t = static_cast<double>(t_ns - samples[k].t_ns) * 1e-9;
  ImuSample out;
  out.t_ns = t_ns;
  out.gyro = m.gyroAt(t);
  out.accel = m.accelAt(t);
  return out;
}

ImuPropagator::ImuPropagator(const ImuNoise& noise, double gravityMagnitude)
    : noise_(noise), gravity_(0.0, 0.0, -gravityMagnitude) {}

void ImuPropagator::propagate(ImuState& state, std::span<const ImuSample> samples, std::int64_t t_end_ns,
                              Matrix15d* Phi, Matrix15d* Qd) const {
  const bool wantJ = Phi || Qd;
  Matrix15d phiTotal = Matrix15d::Identity();
  Matrix15d q = Matrix15d::Zero();
  const double sg2 = noise_.gyroscope_noise_density * noise_.gyroscope_noise_density;
  const double sa2 = noise_.accelerometer_noise_density * noise_.accelerometer_noise_density;
  const double sbg2 = noise_.gyroscope_random_walk * noise_.gyroscope_random_walk;
  const double sba2 = noise_.accelerometer_random_walk * noise_.accelerometer_random_walk;
  ImuStepJacobians J;
  ImuState s = state;  // the caller's state is untouched if the samples are rejected
  forEachImuInterval(samples, state.t_ns, t_end_ns, [&](const ImuInterval& m) {
    integrateImuInterval(m, s.bg, s.ba, gravity_, s.R_WI, s.p_WI, s.v_WI, wantJ ? &J : nullptr);
    if (!wantJ) return;
    // Step transition F = [A B; 0 I] (A: navigation 9x9, B = [Bg Ba]: bias columns, biases
    // constant). Products are formed block-wise: Phi <- F Phi, q <- F q F^T + G Q G^T.
    Eigen::Matrix<double, 9, 6> B;
    B << J.Bg, J.Ba;
    auto phiTop = phiTotal.topRows<9>();
    phiTop.leftCols<9>() = (J.A * phiTop.leftCols<9>()).eval();
    phiTop.rightCols<6>() = (J.A * phiTop.rightCols<6>() + B).eval();
    if (Qd) {
      const double h = m.dt;
      const Eigen::Matrix<double, 9, 9> M = J.A * q.topLeftCorner<9, 9>() + B * q.bottomLeftCorner<6, 9>();
      const Eigen::Matrix<double, 9, 6> N = J.A * q.topRightCorner<9, 6>() + B * q.bottomRightCorner<6, 6>();
      // White noise held over the step (sigma^2/h) enters like the biases; bias random walk
      // adds sigma_b^2 h.
      q.topLeftCorner<9, 9>() = M * J.A.transpose() + N * B.transpose() + (sg2 / h) * J.Bg * J.Bg.transpose() +
                                (sa2 / h) * J.Ba * J.Ba.transpose();
      q.topRightCorner<9, 6>() = N;
      q.bottomLeftCorner<6, 9>() = N.transpose();
      q.block<3, 3>(ImuErr::kBg, ImuErr::kBg).diagonal().array() += sbg2 * h;
      q.block<3, 3>(ImuErr::kBa, ImuErr::kBa).diagonal().array() += sba2 * h;
    }
  });
  s.t_ns = t_end_ns;
  state = s;
  if (Phi) *Phi = phiTotal;
  if (Qd) *Qd = 0.5 * (q + q.transpose());
}

}  // namespace gvins::vio
