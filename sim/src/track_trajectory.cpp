#include "gvins/sim/track_trajectory.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

#include "gvins/gnss/pos_reader.hpp"
#include "gvins/sim/uniform_bspline.hpp"
#include "gvins/vio/so3.hpp"
#include "band_matrix.hpp"

namespace gvins::sim {
namespace {

constexpr double kGridStep = 0.005;  // s, spacing of the fitted states handed to RecordedTrajectory
constexpr double kPi = 3.14159265358979323846;

/// One observation of a penalised spline fit: the `derivative`-th time derivative at t.
struct SplineObs {
  double t = 0.0;
  int derivative = 0;
  Eigen::Vector3d value = Eigen::Vector3d::Zero();
  Eigen::Vector3d weight = Eigen::Vector3d::Zero();  ///< 1 / sigma² per axis
};

/// Penalised least-squares septic B-spline (Eilers & Marx 1996) through value and derivative
/// observations; each axis solved on its own.
UniformBSpline<3> fitPSpline(const std::vector<SplineObs>& obs, double dt, double lambda) {
  double tFirst = obs.front().t, tLast = obs.front().t;
  for (const SplineObs& o : obs) {
    tFirst = std::min(tFirst, o.t);
    tLast = std::max(tLast, o.t);
  }
  const double t0 = tFirst - 4.0 * dt;
  const auto n = static_cast<std::size_t>(std::ceil((tLast - t0) / dt)) + 5;
  std::vector<Eigen::Vector3d> cp(n, Eigen::Vector3d::Zero());
  const double d3[4] = {-1.0, 3.0, -3.0, 1.0};
  for (int axis = 0; axis < 3; ++axis) {
    detail::BandMatrix N(n);
    std::vector<double> rhs(n, 0.0);
    double w[8];
    for (const SplineObs& o : obs) {
      const double x = (o.t - t0) / dt;
      const auto k = static_cast<long>(std::floor(x));
      UniformBSpline<3>::basis(x - static_cast<double>(k), o.derivative, w);
      const double scale = std::pow(1.0 / dt, o.derivative);
      const double wt = o.weight[axis];
      for (int m = 0; m < 8; ++m) {
        const auto i = static_cast<std::size_t>(k - 3 + m);
        for (int m2 = 0; m2 <= m; ++m2)
          N.add(i, static_cast<std::size_t>(k - 3 + m2), wt * scale * scale * w[m] * w[m2]);
        rhs[i] += wt * scale * w[m] * o.value[axis];
      }
    }
    for (std::size_t r = 0; r + 3 < n; ++r)
      for (int a = 0; a < 4; ++a)
        for (int b = 0; b <= a; ++b)
          N.add(r + static_cast<std::size_t>(a), r + static_cast<std::size_t>(b), lambda * d3[a] * d3[b]);
    for (std::size_t i = 0; i < n; ++i) N.add(i, i, 1e-9);
    N.factor();
    N.solve(rhs);
    for (std::size_t i = 0; i < n; ++i) cp[i][axis] = rhs[i];
  }
  return UniformBSpline<3>(t0, dt, std::move(cp));
}

struct TrackEpoch {
  double t = 0.0;                                      ///< flight time, s
  Eigen::Vector3d p = Eigen::Vector3d::Zero();         ///< antenna in W
  Eigen::Vector3d sigma = Eigen::Vector3d::Zero();     ///< per axis of W, m
};

/// The real IMU over the span, in flight seconds.
struct ImuSpan {
  std::vector<double> t;
  std::vector<Eigen::Vector3d> w, f;
  std::size_t index(double time) const {  // segment [i, i+1] containing time (clamped)
    const auto it = std::upper_bound(t.begin(), t.end(), time);
    const auto i = static_cast<std::size_t>(std::max<long>(0, (it - t.begin()) - 1));
    return std::min(i, t.size() - 2);
  }
};

/// Gyro integration with the bias model and the velocity-increment residuals of the attitude fit.
class AttitudeModel {
 public:
  AttitudeModel(const ImuSpan& imu, double gravity, double biasInterval, const Eigen::Vector3d& lever)
      : imu_(imu), g_(gravity), lever_(lever) {
    const double span = imu.t.back() - imu.t.front();
    nodes_ = biasInterval > 0.0 ? static_cast<int>(std::ceil(span / biasInterval)) + 1 : 1;
    step_ = nodes_ > 1 ? span / (nodes_ - 1) : 1.0;
  }
  int parameters() const { return 6 + 3 * nodes_; }
  /// Gyro bias at flight time t: x[6..] are the nodes.
  Eigen::Vector3d gyroBias(const Eigen::VectorXd& x, double t) const {
    if (nodes_ == 1) return x.segment<3>(6);
    const double u = std::clamp((t - imu_.t.front()) / step_, 0.0, static_cast<double>(nodes_ - 1));
    const int i = std::min(static_cast<int>(u), nodes_ - 2);
    const double a = u - i;
    return (1.0 - a) * x.segment<3>(6 + 3 * i) + a * x.segment<3>(6 + 3 * (i + 1));
  }
  /// R_k at every sample; F and M are the prefix sums of R f dt and R dt.
  void integrate(const Eigen::Matrix3d& R0ref, const Eigen::VectorXd& x, std::vector<Eigen::Matrix3d>& R,
                 std::vector<Eigen::Vector3d>& F, std::vector<Eigen::Matrix3d>& M) const {
    const std::size_t n = imu_.t.size();
    R.resize(n);
    F.resize(n);
    M.resize(n);
    R[0] = R0ref * vio::so3::exp(x.head<3>());
    F[0].setZero();
    M[0].setZero();
    for (std::size_t k = 0; k + 1 < n; ++k) {
      const double dt = imu_.t[k + 1] - imu_.t[k];
      const Eigen::Vector3d w = 0.5 * (imu_.w[k] + imu_.w[k + 1]) - gyroBias(x, 0.5 * (imu_.t[k] + imu_.t[k + 1]));
      R[k + 1] = R[k] * vio::so3::exp(w * dt);
      const Eigen::Matrix3d Rm = 0.5 * (R[k] + R[k + 1]);
      F[k + 1] = F[k] + Rm * (0.5 * (imu_.f[k] + imu_.f[k + 1])) * dt;
      M[k + 1] = M[k] + Rm * dt;
    }
  }
  /// Residuals of the velocity increments over the windows [a_i, b_i] against the track's dv_i.
  Eigen::VectorXd residuals(const Eigen::Matrix3d& R0ref, const Eigen::VectorXd& x, const std::vector<double>& a,
                            const std::vector<double>& b, const std::vector<Eigen::Vector3d>& dv) const {
    std::vector<Eigen::Matrix3d> R, M;
    std::vector<Eigen::Vector3d> F;
    integrate(R0ref, x, R, F, M);
    const Eigen::Vector3d ba = x.segment<3>(3);
    auto at = [&](double t, Eigen::Vector3d& f, Eigen::Matrix3d& m, Eigen::Vector3d& lev) {
      const std::size_t k = imu_.index(t);
      const double s = (t - imu_.t[k]) / (imu_.t[k + 1] - imu_.t[k]);
      f = F[k] + s * (F[k + 1] - F[k]);
      m = M[k] + s * (M[k + 1] - M[k]);
      // Antenna minus IMU velocity: R (w x l).
      lev = R[k] * (imu_.w[k] - gyroBias(x, imu_.t[k])).cross(lever_);
    };
    Eigen::VectorXd r(3 * static_cast<long>(a.size()));
    for (std::size_t i = 0; i < a.size(); ++i) {
      Eigen::Vector3d fa, fb, la, lb;
      Eigen::Matrix3d ma, mb;
      at(a[i], fa, ma, la);
      at(b[i], fb, mb, lb);
      const Eigen::Vector3d imuDv = (fb - fa) - (mb - ma) * ba - Eigen::Vector3d(0.0, 0.0, g_ * (b[i] - a[i]));
      r.segment<3>(3 * static_cast<long>(i)) = imuDv - (dv[i] - (lb - la));
    }
    return r;
  }

 private:
  const ImuSpan& imu_;
  double g_;
  Eigen::Vector3d lever_;
  int nodes_ = 1;
  double step_ = 1.0;
};

Eigen::Matrix3d rotZ(double a) {
  return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

/// Levenberg-Marquardt on the attitude model with a central-difference Jacobian (9 to a few
/// dozen parameters, a few hundred windows: cheap and exact enough).
double solveAttitude(const AttitudeModel& model, const Eigen::Matrix3d& R0ref, Eigen::VectorXd& x,
                     const std::vector<double>& a, const std::vector<double>& b, const std::vector<Eigen::Vector3d>& dv) {
  Eigen::VectorXd r = model.residuals(R0ref, x, a, b, dv);
  double cost = r.squaredNorm(), mu = 1e-3;
  for (int it = 0; it < 30; ++it) {
    Eigen::MatrixXd J(r.size(), x.size());
    for (long p = 0; p < x.size(); ++p) {
      const double h = 1e-6;
      Eigen::VectorXd xp = x, xm = x;
      xp[p] += h;
      xm[p] -= h;
      J.col(p) = (model.residuals(R0ref, xp, a, b, dv) - model.residuals(R0ref, xm, a, b, dv)) / (2.0 * h);
    }
    const Eigen::MatrixXd H = J.transpose() * J;
    const Eigen::VectorXd g = J.transpose() * r;
    bool improved = false;
    for (int tries = 0; tries < 8 && !improved; ++tries) {
      Eigen::MatrixXd A = H;
      A.diagonal() += mu * H.diagonal().cwiseMax(1e-9);
      const Eigen::VectorXd step = A.ldlt().solve(-g);
      const Eigen::VectorXd xn = x + step;
      const Eigen::VectorXd rn = model.residuals(R0ref, xn, a, b, dv);
      if (rn.squaredNorm() < cost) {
        const double gain = cost - rn.squaredNorm();
        x = xn;
        r = rn;
        cost = rn.squaredNorm();
        mu = std::max(mu * 0.3, 1e-9);
        improved = true;
        if (gain < 1e-10 * cost) return cost;
      } else {
        mu *= 10.0;
      }
    }
    if (!improved) break;
  }
  return cost;
}

std::vector<TrackEpoch> trackInW(const std::vector<PositionSolution>& track, const TrackTrajectoryConfig& cfg,
                                 const LocalFrame& frame) {
  std::vector<TrackEpoch> out;
  const Eigen::Matrix3d R_EW = frame.rotationEcefFromW();
  for (const PositionSolution& s : track) {
    const int q = static_cast<int>(s.quality);
    if (q < 1 || q > cfg.maxQuality) continue;
    TrackEpoch e;
    e.t = frame.flightTime(s.time);
    e.p = frame.fromEcef(s.position);
    const Eigen::Matrix3d C = R_EW.transpose() * s.positionCovariance * R_EW;
    for (int i = 0; i < 3; ++i) e.sigma[i] = std::max(std::sqrt(std::max(C(i, i), 0.0)), cfg.trackSigmaFloor);
    if (!out.empty() && e.t <= out.back().t) throw std::invalid_argument("track: epochs not in increasing time");
    out.push_back(e);
  }
  return out;
}

/// Initial attitude: roll and pitch from the mean specific force of the first second, yaw from
/// a 10-degree grid of the attitude cost; biases start at zero (the fit finds them, so a rig
/// that stands still at first can check the gyro bias against its mean rate then).
Eigen::Matrix3d initialAttitude(const AttitudeModel& model, const ImuSpan& imu, Eigen::VectorXd& x,
                                const std::vector<double>& a, const std::vector<double>& b,
                                const std::vector<Eigen::Vector3d>& dv) {
  Eigen::Vector3d fm = Eigen::Vector3d::Zero();
  int cnt = 0;
  for (std::size_t k = 0; k < imu.t.size() && imu.t[k] < imu.t.front() + 1.0; ++k, ++cnt) fm += imu.f[k];
  fm /= cnt;
  x.setZero();
  const Eigen::Matrix3d tilt = Eigen::Quaterniond::FromTwoVectors(fm.normalized(), Eigen::Vector3d::UnitZ()).toRotationMatrix();
  double best = 1e300;
  Eigen::Matrix3d R0 = tilt;
  for (int k = 0; k < 36; ++k) {
    const Eigen::Matrix3d R = rotZ(k * 10.0 * kPi / 180.0) * tilt;
    const double c = model.residuals(R, x, a, b, dv).squaredNorm();
    if (c < best) {
      best = c;
      R0 = R;
    }
  }
  return R0;
}

}  // namespace

TrackImuFit fitTrackImu(const std::vector<PositionSolution>& trackIn, const std::vector<vio::ImuSample>& imuIn,
                        const TrackTrajectoryConfig& cfg, const LocalFrame& frame, const Eigen::Vector3d& lever,
                        double gravity) {
  const std::vector<TrackEpoch> track = trackInW(trackIn, cfg, frame);
  if (track.size() < 20) throw std::invalid_argument("track: fewer than 20 epochs of the accepted quality");
  if (imuIn.size() < 100) throw std::invalid_argument("IMU: fewer than 100 samples");
  const double tImu0 = frame.flightTimeOfStamp(imuIn.front().t_ns), tImu1 = frame.flightTimeOfStamp(imuIn.back().t_ns);
  if (tImu0 > 0.0 || track.front().t > 0.5)
    throw std::invalid_argument("the IMU log and the track must begin by the start time (IMU " + std::to_string(tImu0) +
                                " s, track " + std::to_string(track.front().t) + " s after it)");
  double duration = cfg.duration > 0.0 ? cfg.duration : std::min(tImu1, track.back().t);
  if (duration > tImu1 || duration > track.back().t + 0.5 || !(duration > 2.0 * cfg.attitudeWindow))
    throw std::invalid_argument("the IMU log and the track do not cover the requested duration");
  duration = std::floor(duration / kGridStep + 1e-9) * kGridStep;

  TrackImuFit out;
  ImuSpan span;
  for (const vio::ImuSample& s : imuIn) {
    const double t = frame.flightTimeOfStamp(s.t_ns);
    if (t < -0.1 || t > duration + 0.1) continue;
    out.imu.push_back(s);
    span.t.push_back(t);
    span.w.push_back(s.gyro);
    span.f.push_back(s.accel);
  }

  // Antenna velocity of the track alone (knots at the track's epoch spacing).
  std::vector<SplineObs> obs;
  for (const TrackEpoch& e : track)
    obs.push_back({e.t, 0, e.p, e.sigma.cwiseAbs2().cwiseInverse()});
  std::vector<double> gaps;
  for (std::size_t i = 1; i < track.size(); ++i) gaps.push_back(track[i].t - track[i - 1].t);
  std::nth_element(gaps.begin(), gaps.begin() + static_cast<long>(gaps.size() / 2), gaps.end());
  const UniformBSpline<3> trackSpline = fitPSpline(obs, std::clamp(gaps[gaps.size() / 2], 0.05, 1.0), 1e-2);
  std::vector<double> wa, wb;
  std::vector<Eigen::Vector3d> dv;
  for (const TrackEpoch& e : track) {
    if (e.t < span.t.front() || e.t + cfg.attitudeWindow > std::min(duration, span.t.back())) continue;
    Eigen::Vector3d va[2], vb[2];
    trackSpline.evaluate(e.t, 1, va);
    trackSpline.evaluate(e.t + cfg.attitudeWindow, 1, vb);
    wa.push_back(e.t);
    wb.push_back(e.t + cfg.attitudeWindow);
    dv.push_back(vb[1] - va[1]);
  }
  if (wa.size() < 20) throw std::invalid_argument("track: fewer than 20 attitude windows inside the IMU log");

  // Attitude: R0, accelerometer bias, gyro bias.
  const AttitudeModel model(span, gravity, cfg.gyroBiasInterval, lever);
  Eigen::VectorXd x(model.parameters());
  Eigen::Matrix3d R0 = initialAttitude(model, span, x, wa, wb, dv);
  const double cost = solveAttitude(model, R0, x, wa, wb, dv);
  TrackFitReport& rep = out.report;
  rep.velocityResidualRms = std::sqrt(cost / static_cast<double>(3 * wa.size()));
  std::vector<Eigen::Matrix3d> R, M;
  std::vector<Eigen::Vector3d> F;
  model.integrate(R0, x, R, F, M);
  const Eigen::Vector3d ba = x.segment<3>(3);
  const Eigen::Vector3d x0 = R[0].col(0);
  rep.initialYawDeg = std::atan2(x0.y(), x0.x()) * 180.0 / kPi;
  rep.accelBias = ba;
  auto attitude = [&](double t) {  // geodesic interpolation between samples
    const std::size_t k = span.index(t);
    const double s = std::clamp((t - span.t[k]) / (span.t[k + 1] - span.t[k]), 0.0, 1.0);
    return Eigen::Matrix3d(R[k] * vio::so3::exp(s * vio::so3::log(R[k].transpose() * R[k + 1])));
  };

  // Position of the IMU: the track (antenna minus R l) and the rotated real accelerations.
  obs.clear();
  for (const TrackEpoch& e : track) {
    if (e.t < span.t.front() || e.t > span.t.back()) continue;
    obs.push_back({e.t, 0, e.p - attitude(e.t) * lever, e.sigma.cwiseAbs2().cwiseInverse()});
    ++rep.trackEpochs;
  }
  const Eigen::Vector3d wAcc = Eigen::Vector3d::Constant(1.0 / (cfg.accelSigma * cfg.accelSigma));
  std::vector<Eigen::Vector3d> accW(span.t.size());
  for (std::size_t k = 0; k < span.t.size(); ++k) {
    accW[k] = R[k] * (span.f[k] - ba) - Eigen::Vector3d(0.0, 0.0, gravity);
    obs.push_back({span.t[k], 2, accW[k], wAcc});
  }
  const UniformBSpline<3> pos = fitPSpline(obs, cfg.knotInterval, cfg.smoothing);

  // Report and the fitted states every 5 ms.
  double sr = 0.0, sa = 0.0;
  for (const TrackEpoch& e : track) {
    if (e.t < 0.0 || e.t > duration) continue;
    const double d = (pos.value(e.t) + attitude(e.t) * lever - e.p).norm();
    sr += d * d;
    rep.trackResidualMax = std::max(rep.trackResidualMax, d);
  }
  rep.trackResidualRms = std::sqrt(sr / static_cast<double>(std::max<std::size_t>(rep.trackEpochs, 1)));
  for (std::size_t k = 0; k < span.t.size(); ++k) {
    Eigen::Vector3d p[3];
    pos.evaluate(span.t[k], 2, p);
    sa += (p[2] - accW[k]).squaredNorm();
    ++rep.imuSamples;
  }
  rep.accelResidualRms = std::sqrt(sa / static_cast<double>(3 * std::max<std::size_t>(rep.imuSamples, 1)));
  Eigen::Vector3d fwd = Eigen::Vector3d::Zero(), bgSum = Eigen::Vector3d::Zero();
  const std::int64_t t0 = frame.startStampNs();
  const auto steps = static_cast<long>(std::llround(duration / kGridStep));
  for (long i = 0; i <= steps; ++i) {
    const double t = static_cast<double>(i) * kGridStep;
    Eigen::Vector3d p[2];
    pos.evaluate(t, 1, p);
    vio::GroundTruthSample g;
    g.hasVelocityAndBiases = true;
    g.state.t_ns = t0 + i * static_cast<std::int64_t>(std::llround(kGridStep * 1e9));
    g.state.R_WI = attitude(t);
    g.state.p_WI = p[0];
    g.state.v_WI = p[1];
    g.state.bg = model.gyroBias(x, t);
    g.state.ba = ba;
    bgSum += g.state.bg;
    if (p[1].norm() > 0.5) fwd += g.state.R_WI.transpose() * p[1].normalized();
    out.truth.push_back(g);
  }
  rep.gyroBias = bgSum / static_cast<double>(out.truth.size());
  if (fwd.norm() > 0.0) rep.forwardAxis = fwd.normalized();
  return out;
}

namespace {
TrackImuFit readAndFit(const TrackTrajectoryConfig& c, const LocalFrame& frame, const Eigen::Vector3d& lever, double g) {
  return fitTrackImu(readPosFile(c.posFile).solutions, vio::readImuCsv(c.imuCsv), c, frame, lever, g);
}
RecordedTrajectoryConfig recordedConfig(double duration) {
  RecordedTrajectoryConfig r;
  r.duration = duration;
  r.knotInterval = 0.02;
  r.smoothing = 1e-3;
  return r;
}
}  // namespace

TrackTrajectory::TrackTrajectory(const TrackImuFit& fit, double duration)
    : RecordedTrajectory(fit.imu, fit.truth, recordedConfig(duration)), report_(fit.report) {}

TrackTrajectory::TrackTrajectory(const TrackTrajectoryConfig& config, const LocalFrame& frame,
                                 const Eigen::Vector3d& leverArm, double gravity)
    : TrackTrajectory(readAndFit(config, frame, leverArm, gravity), 0.0) {}

}  // namespace gvins::sim
