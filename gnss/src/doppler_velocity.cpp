#include "gvins/gnss/doppler_velocity.hpp"

#include <cmath>

#include <Eigen/Cholesky>

#include "gvins/base/constants.hpp"
#include "gvins/gnss/sagnac.hpp"

namespace gvins {

namespace {
constexpr double kC = constants::kSpeedOfLight;
constexpr double kOmega = constants::kWgs84OmegaE;

struct Row {
  Eigen::Vector4d h;
  double y = 0.0;  // observed minus the part of the model that does not depend on the unknowns
  double w = 0.0;
};

struct LinearFit {
  bool ok = false;
  Eigen::Vector4d x = Eigen::Vector4d::Zero();
  Eigen::Matrix4d cov = Eigen::Matrix4d::Zero();
  double chi2 = 0.0;
  int n = 0;
  std::vector<double> norm;
};

LinearFit fitRows(const std::vector<Row>& rows, const std::vector<char>& use) {
  LinearFit f;
  Eigen::Matrix4d N = Eigen::Matrix4d::Zero();
  Eigen::Vector4d b = Eigen::Vector4d::Zero();
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if (!use[i]) continue;
    N.noalias() += rows[i].w * rows[i].h * rows[i].h.transpose();
    b.noalias() += rows[i].w * rows[i].y * rows[i].h;
    ++f.n;
  }
  if (f.n < 4) return f;
  Eigen::LDLT<Eigen::Matrix4d> ldlt(N);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().array() > 1e-12 * N.diagonal().maxCoeff()).all()) return f;
  f.x = ldlt.solve(b);
  f.cov = ldlt.solve(Eigen::Matrix4d::Identity());
  if (!f.x.allFinite()) return f;
  f.norm.assign(rows.size(), 0.0);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if (!use[i]) continue;
    const double v = rows[i].y - rows[i].h.dot(f.x);
    f.chi2 += rows[i].w * v * v;
    const double q = 1.0 / rows[i].w - rows[i].h.dot(f.cov * rows[i].h);
    f.norm[i] = std::abs(v) / std::sqrt(std::max(q, 1e-6 / rows[i].w));
  }
  f.ok = true;
  return f;
}
}  // namespace

VelocitySolution solveDopplerVelocity(const std::vector<RangeRateMeasurement>& meas, const Eigen::Vector3d& r,
                                      const FaultExclusionOptions& fde) {
  VelocitySolution sol;
  std::vector<Row> rows;
  rows.reserve(meas.size());
  for (const auto& m : meas) {
    const Eigen::Vector3d d = m.satPosition - r;
    const double rho = d.norm();
    if (!(rho > 1e5) || !(m.variance > 0.0)) continue;
    const Eigen::Vector3d e = d / rho;
    Row row;
    // rangeRate = e.(v_s - v_r) + omega/c (vx_s y_r + x_s vy_r - vy_s x_r - y_s vx_r) + cdt_dot - c dts_dot
    row.h << -e.x() - kOmega * m.satPosition.y() / kC, -e.y() + kOmega * m.satPosition.x() / kC, -e.z(), 1.0;
    const double known = e.dot(m.satVelocity) + sagnacRangeRateCorrection(m.satPosition, m.satVelocity, r,
                                                                            Eigen::Vector3d::Zero()) -
                         kC * m.satClockDrift;
    row.y = m.rangeRate - known;
    row.w = 1.0 / m.variance;
    rows.push_back(row);
  }
  // Map back to measurement indices (rows skipped above are not counted).
  std::vector<int> idx;
  for (std::size_t i = 0; i < meas.size(); ++i) {
    const double rho = (meas[i].satPosition - r).norm();
    if (rho > 1e5 && meas[i].variance > 0.0) idx.push_back(static_cast<int>(i));
  }
  std::vector<char> use(rows.size(), 1);
  LinearFit best;
  auto fit = [&](const std::vector<char>& u) {
    LinearFit f = fitRows(rows, u);
    SubsetFit s;
    s.ok = f.ok;
    s.chi2 = f.chi2;
    s.dof = f.n - 4;
    s.normalizedResidual = f.norm;
    return s;
  };
  const FaultExclusionResult res = detectAndExclude(use, fit, fde);
  const LinearFit f = fitRows(rows, use);
  if (!f.ok) return sol;
  sol.valid = true;
  sol.velocity = f.x.head<3>();
  sol.covariance = f.cov.topLeftCorner<3, 3>();
  sol.clockDrift = f.x[3];
  sol.clockDriftVariance = f.cov(3, 3);
  sol.numMeasurements = f.n;
  sol.chi2 = f.chi2;
  sol.dof = f.n - 4;
  sol.testPassed = res.testPassed;
  for (int i : res.excluded) sol.excluded.push_back(meas[idx[i]].sat);
  return sol;
}

}  // namespace gvins
