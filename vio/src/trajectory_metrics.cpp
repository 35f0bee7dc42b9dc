#include "gvins/vio/trajectory_metrics.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <ostream>
#include <stdexcept>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

#include "gvins/vio/so3.hpp"
#include "gvins/vio/svg_plot.hpp"

namespace gvins::vio {

std::vector<TrajectorySample> toTrajectorySamples(const std::vector<TumPose>& poses) {
  std::vector<TrajectorySample> out;
  out.reserve(poses.size());
  for (const TumPose& p : poses) out.push_back({p.t_ns, p.R, p.p, std::nullopt});
  return out;
}

std::vector<TrajectorySample> toTrajectorySamples(const std::vector<GroundTruthSample>& gt) {
  std::vector<TrajectorySample> out;
  out.reserve(gt.size());
  for (const GroundTruthSample& g : gt) {
    TrajectorySample s{g.state.t_ns, g.state.R_WI, g.state.p_WI, std::nullopt};
    if (g.hasVelocityAndBiases) s.v = g.state.v_WI;
    out.push_back(s);
  }
  return out;
}

namespace {

constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;

/// Reference at time t (see the header for the rule); nullopt if none within tolerance.
std::optional<TrajectorySample> referenceAt(const std::vector<TrajectorySample>& ref, std::int64_t t,
                                            std::int64_t tol) {
  if (ref.empty()) return std::nullopt;
  const auto it = std::lower_bound(ref.begin(), ref.end(), t,
                                   [](const TrajectorySample& s, std::int64_t v) { return s.t_ns < v; });
  if (it != ref.end() && it->t_ns == t) return *it;
  const TrajectorySample* after = it != ref.end() ? &*it : nullptr;
  const TrajectorySample* before = it != ref.begin() ? &*(it - 1) : nullptr;
  const bool okB = before && t - before->t_ns <= tol, okA = after && after->t_ns - t <= tol;
  if (okB && okA) {
    const double a = static_cast<double>(t - before->t_ns) / static_cast<double>(after->t_ns - before->t_ns);
    TrajectorySample s;
    s.t_ns = t;
    s.p = (1.0 - a) * before->p + a * after->p;
    const Eigen::Quaterniond q0(before->R), q1(after->R);
    s.R = q0.slerp(a, q1).normalized().toRotationMatrix();
    if (before->v && after->v) s.v = (1.0 - a) * *before->v + a * *after->v;
    return s;
  }
  if (okB && (!okA)) return *before;
  if (okA) return *after;
  return std::nullopt;
}

ErrorStats stats(std::vector<double> v) {
  ErrorStats s;
  s.count = v.size();
  if (v.empty()) return s;
  double sum = 0.0, sq = 0.0;
  for (double x : v) {
    sum += x;
    sq += x * x;
    s.max = std::max(s.max, x);
  }
  s.mean = sum / static_cast<double>(v.size());
  s.rmse = std::sqrt(sq / static_cast<double>(v.size()));
  const std::size_t m = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(m), v.end());
  s.median = v[m];
  if (v.size() % 2 == 0) s.median = 0.5 * (s.median + *std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(m)));
  return s;
}

}  // namespace

EvaluationResult evaluateTrajectory(const std::vector<TrajectorySample>& estimate,
                                    const std::vector<TrajectorySample>& reference,
                                    const std::vector<PoseCovariance>& covariances,
                                    const EvaluationOptions& options) {
  EvaluationResult r;
  r.estimatePoses = estimate.size();
  r.referencePoses = reference.size();
  r.alignmentKind = options.alignment;
  std::vector<const TrajectorySample*> est;
  std::vector<TrajectorySample> ref;
  for (const TrajectorySample& e : estimate) {
    if (auto g = referenceAt(reference, e.t_ns, options.tolerance_ns)) {
      est.push_back(&e);
      ref.push_back(*g);
    } else {
      ++r.unmatched;
    }
  }
  r.matched = est.size();
  if (r.matched < 2) throw std::invalid_argument("fewer than 2 estimated poses match the reference in time (" +
                                                 std::to_string(r.matched) + " of " + std::to_string(estimate.size()) + ")");
  const std::size_t n = est.size();
  std::vector<Eigen::Vector3d> pe(n), pr(n);
  for (std::size_t i = 0; i < n; ++i) pe[i] = est[i]->p, pr[i] = ref[i].p;
  const std::size_t na = options.alignFirst > 0 ? std::min(options.alignFirst, n) : n;
  if (options.alignment == AlignmentKind::FirstPose4Dof) {
    // Yaw of R_ref0 R_est0ᵀ (rotation about z only) and the translation that maps p_est0 to p_ref0.
    const Eigen::Matrix3d D = ref[0].R * est[0]->R.transpose();
    const double yaw = std::atan2(D(1, 0) - D(0, 1), D(0, 0) + D(1, 1));
    r.alignment.R = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    r.alignment.t = pr[0] - r.alignment.R * pe[0];
  } else {
    r.alignment = alignTrajectory(options.alignment, std::span(pe.data(), na), std::span(pr.data(), na));
  }
  const SimilarityTransform& T = r.alignment;

  // Absolute errors.
  std::vector<double> terr(n), rerr(n);
  std::vector<Eigen::Matrix3d> Ra(n);
  r.time.resize(n);
  r.estimateAligned.resize(n);
  r.reference = pr;
  r.positionSigma3.assign(n, std::numeric_limits<double>::quiet_NaN());
  for (std::size_t i = 0; i < n; ++i) {
    r.time[i] = static_cast<double>(est[i]->t_ns - est[0]->t_ns) * 1e-9;
    r.estimateAligned[i] = T.apply(pe[i]);
    Ra[i] = T.R * est[i]->R;
    terr[i] = (pr[i] - r.estimateAligned[i]).norm();
    rerr[i] = so3::log(Ra[i].transpose() * ref[i].R).norm() * kRadToDeg;
    if (i > 0) r.pathLength += (pr[i] - pr[i - 1]).norm();
  }
  r.duration = r.time.back();
  r.translationError = terr;
  r.rotationErrorDeg = rerr;
  r.translation = stats(terr);
  r.rotation = stats(rerr);

  // Velocity: the estimated velocity (rotated and scaled by the alignment) where the estimate
  // carries one, else central differences over neighbouring matched poses (gaps up to 0.5 s).
  std::vector<double> verr;
  for (std::size_t i = 0; i < n; ++i) {
    Eigen::Vector3d ve, vr;
    if (est[i]->v) {
      ve = T.scale * (T.R * *est[i]->v);
      if (ref[i].v) {
        vr = *ref[i].v;
      } else {
        if (i == 0 || i + 1 >= n) continue;
        const double dt = static_cast<double>(est[i + 1]->t_ns - est[i - 1]->t_ns) * 1e-9;
        if (!(dt > 0.0) || dt > 1.0) continue;
        vr = (pr[i + 1] - pr[i - 1]) / dt;
      }
    } else {
      if (i == 0 || i + 1 >= n) continue;
      const double dt = static_cast<double>(est[i + 1]->t_ns - est[i - 1]->t_ns) * 1e-9;
      if (!(dt > 0.0) || dt > 1.0) continue;
      ve = (r.estimateAligned[i + 1] - r.estimateAligned[i - 1]) / dt;
      vr = ref[i].v ? *ref[i].v : Eigen::Vector3d((pr[i + 1] - pr[i - 1]) / dt);
    }
    verr.push_back((ve - vr).norm());
  }
  r.velocity = stats(verr);
  // Body-frame velocity (R^T v of each), where both carry a velocity: free of any alignment.
  std::vector<double> berr;
  for (std::size_t i = 0; i < n; ++i) {
    if (est[i]->v && ref[i].v) berr.push_back((est[i]->R.transpose() * *est[i]->v - ref[i].R.transpose() * *ref[i].v).norm());
  }
  r.bodyVelocity = stats(berr);

  // Relative errors over distance.
  std::vector<double> dist(n, 0.0);
  for (std::size_t i = 1; i < n; ++i) dist[i] = dist[i - 1] + (pr[i] - pr[i - 1]).norm();
  for (double L : options.segmentLengths) {
    SegmentError seg;
    seg.length = L;
    double sum = 0.0, sq = 0.0, rot = 0.0;
    std::size_t j = 0;
    for (std::size_t i = 0; i < n; ++i) {
      j = std::max(j, i + 1);
      while (j < n && dist[j] - dist[i] < L) ++j;
      if (j >= n) break;
      const Eigen::Matrix3d dRr = ref[i].R.transpose() * ref[j].R;
      const Eigen::Vector3d dpr = ref[i].R.transpose() * (pr[j] - pr[i]);
      const Eigen::Matrix3d dRe = est[i]->R.transpose() * est[j]->R;
      const Eigen::Vector3d dpe = T.scale * (est[i]->R.transpose() * (pe[j] - pe[i]));
      // ΔT_ref⁻¹ ΔT_est = (dRrᵀ dRe, dRrᵀ (dpe − dpr))
      const double e = (dRr.transpose() * (dpe - dpr)).norm();
      sum += e;
      sq += e * e;
      rot += so3::log(dRr.transpose() * dRe).norm() * kRadToDeg;
      ++seg.count;
    }
    if (seg.count > 0) {
      const double c = static_cast<double>(seg.count);
      seg.meanTranslation = sum / c;
      seg.rmseTranslation = std::sqrt(sq / c);
      seg.driftPercent = 100.0 * seg.meanTranslation / L;
      seg.rotationDegPerM = rot / c / L;
    }
    r.segments.push_back(seg);
  }

  // NEES.
  if (!covariances.empty()) {
    double sp = 0.0, so = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      const auto it = std::lower_bound(covariances.begin(), covariances.end(), est[i]->t_ns,
                                       [](const PoseCovariance& c, std::int64_t v) { return c.t_ns < v; });
      if (it == covariances.end() || it->t_ns != est[i]->t_ns) continue;
      const Eigen::Matrix3d Ppp = T.scale * T.scale * T.R * it->P.block<3, 3>(3, 3) * T.R.transpose();
      const Eigen::Matrix3d Ptt = it->P.block<3, 3>(0, 0);
      const Eigen::LLT<Eigen::Matrix3d> lp(Ppp), lt(Ptt);
      if (lp.info() != Eigen::Success || lt.info() != Eigen::Success) continue;
      const Eigen::Vector3d ep = pr[i] - r.estimateAligned[i];
      const Eigen::Vector3d et = so3::log(Ra[i].transpose() * ref[i].R);
      sp += ep.dot(lp.solve(ep));
      so += et.dot(lt.solve(et));
      r.positionSigma3[i] = 3.0 * std::sqrt(Ppp.trace());
      ++r.neesCount;
    }
    if (r.neesCount > 0) {
      r.positionNees = sp / static_cast<double>(r.neesCount);
      r.orientationNees = so / static_cast<double>(r.neesCount);
    }
  }
  return r;
}

void printEvaluation(std::ostream& os, const EvaluationResult& r) {
  char b[256];
  std::snprintf(b, sizeof b, "poses: %zu estimated, %zu reference, %zu matched, %zu unmatched; %.1f s, %.1f m path\n",
                r.estimatePoses, r.referencePoses, r.matched, r.unmatched, r.duration, r.pathLength);
  os << b;
  const double yaw = std::atan2(r.alignment.R(1, 0), r.alignment.R(0, 0)) * kRadToDeg;
  const double angle = so3::log(r.alignment.R).norm() * kRadToDeg;
  std::snprintf(b, sizeof b, "alignment %s: scale %.6f, rotation %.3f deg (yaw %.3f deg), t = (%.3f, %.3f, %.3f) m\n",
                toString(r.alignmentKind).c_str(), r.alignment.scale, angle, yaw, r.alignment.t.x(), r.alignment.t.y(),
                r.alignment.t.z());
  os << b;
  os << "error                 rmse       mean     median        max      n\n";
  auto row = [&](const char* name, const ErrorStats& s) {
    if (s.count == 0) {
      std::snprintf(b, sizeof b, "%-16s %10s\n", name, "n/a");
    } else {
      std::snprintf(b, sizeof b, "%-16s %10.4f %10.4f %10.4f %10.4f %6zu\n", name, s.rmse, s.mean, s.median, s.max, s.count);
    }
    os << b;
  };
  row("position [m]", r.translation);
  row("rotation [deg]", r.rotation);
  row("velocity [m/s]", r.velocity);
  if (r.bodyVelocity.count > 0) row("body vel. [m/s]", r.bodyVelocity);
  os << "segment [m]   count   mean [m]   rmse [m]   drift [%]   rot [deg/m]\n";
  for (const SegmentError& s : r.segments) {
    if (s.count == 0) {
      std::snprintf(b, sizeof b, "%11.0f %7zu   (path too short)\n", s.length, s.count);
    } else {
      std::snprintf(b, sizeof b, "%11.0f %7zu %10.4f %10.4f %11.3f %13.5f\n", s.length, s.count, s.meanTranslation,
                    s.rmseTranslation, s.driftPercent, s.rotationDegPerM);
    }
    os << b;
  }
  if (r.neesCount > 0) {
    std::snprintf(b, sizeof b, "NEES (expected 3): position %.3f, orientation %.3f over %zu poses\n", r.positionNees,
                  r.orientationNees, r.neesCount);
    os << b;
  }
}

std::vector<std::string> writeEvaluationPlots(const EvaluationResult& r, const std::string& prefix) {
  std::vector<std::string> files;
  {
    SvgPlot p("Trajectory (top view, " + toString(r.alignmentKind) + " aligned)", "x [m]", "y [m]");
    std::vector<double> xr, yr, xe, ye;
    for (std::size_t i = 0; i < r.reference.size(); ++i) {
      xr.push_back(r.reference[i].x());
      yr.push_back(r.reference[i].y());
      xe.push_back(r.estimateAligned[i].x());
      ye.push_back(r.estimateAligned[i].y());
    }
    p.addLine("reference", xr, yr, "#222222");
    p.addLine("estimate", xe, ye, "#d62728");
    p.setEqualAspect(true);
    files.push_back(prefix + "trajectory_top.svg");
    p.save(files.back());
  }
  {
    SvgPlot p("Position error", "time [s]", "error [m]");
    p.addLine("position error", r.time, r.translationError, "#1f77b4");
    if (r.neesCount > 0) p.addLine("3 sigma", r.time, r.positionSigma3, "#999999");
    files.push_back(prefix + "position_error.svg");
    p.save(files.back());
  }
  {
    SvgPlot p("Rotation error", "time [s]", "error [deg]");
    p.addLine("rotation error", r.time, r.rotationErrorDeg, "#2ca02c");
    files.push_back(prefix + "rotation_error.svg");
    p.save(files.back());
  }
  return files;
}

}  // namespace gvins::vio
