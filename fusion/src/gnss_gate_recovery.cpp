#include "gvins/fusion/gnss_gate_recovery.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include <Eigen/Cholesky>
#include <Eigen/QR>

#include "gvins/sri/chi_square.hpp"

namespace gvins::fusion {
namespace {

/// The columns of G the rows `idx` touch.
std::vector<int> activeColumns(const Eigen::MatrixXd& G, const std::vector<int>& idx) {
  std::vector<int> cols;
  for (int c = 0; c < 4; ++c) {
    bool any = false;
    for (int i : idx) any = any || G(i, c) != 0.0;
    if (any) cols.push_back(c);
  }
  return cols;
}

/// Weighted least squares of the correction on the rows `idx` (columns `cols`); nullopt if rank
/// deficient.
std::optional<Eigen::Vector4d> fitCorrection(const ReacquisitionRows& in, const std::vector<int>& idx,
                                             const std::vector<int>& cols) {
  const auto n = static_cast<Eigen::Index>(idx.size()), m = static_cast<Eigen::Index>(cols.size());
  if (n < m) return std::nullopt;
  Eigen::MatrixXd A(n, m);
  Eigen::VectorXd b(n);
  for (Eigen::Index r = 0; r < n; ++r) {
    const int i = idx[static_cast<std::size_t>(r)];
    const double w = 1.0 / std::sqrt(in.bandVariance[i]);
    for (Eigen::Index c = 0; c < m; ++c) A(r, c) = w * in.G(i, cols[static_cast<std::size_t>(c)]);
    b[r] = w * in.residual[i];
  }
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A);
  if (qr.rank() < m) return std::nullopt;
  const Eigen::VectorXd x = qr.solve(b);
  Eigen::Vector4d out = Eigen::Vector4d::Zero();
  for (Eigen::Index c = 0; c < m; ++c) out[cols[static_cast<std::size_t>(c)]] = x[c];
  return out;
}

/// Rows of `idx` that agree with the correction x (residual about it within the band).
std::vector<int> agreeing(const ReacquisitionRows& in, const std::vector<int>& idx, const Eigen::Vector4d& x,
                          double q1, double* cost) {
  std::vector<int> out;
  double sum = 0.0;
  for (int i : idx) {
    const double e = in.residual[i] - in.G.row(i).dot(x);
    const double z2 = e * e / in.bandVariance[i];
    if (z2 <= q1) {
      out.push_back(i);
      sum += z2;
    }
  }
  if (cost) *cost = sum;
  return out;
}

/// RANSAC over minimal samples of `idx`, then least squares on the best consensus and one
/// re-selection (as the clock initialisation, gnss_clock_init.hpp).
std::vector<int> consensus(const ReacquisitionRows& in, const std::vector<int>& idx, const std::vector<int>& cols,
                           double q1, Eigen::Vector4d& x) {
  const std::size_t m = cols.size();
  std::vector<int> best;
  double bestCost = 0.0;
  if (idx.size() < m || m == 0) return best;
  std::mt19937_64 rng(20240624);
  std::vector<int> sample(m);
  for (int it = 0; it < 256; ++it) {
    // A random minimal sample (distinct rows).
    std::vector<int> pool = idx;
    for (std::size_t k = 0; k < m; ++k) {
      std::uniform_int_distribution<std::size_t> pick(k, pool.size() - 1);
      std::swap(pool[k], pool[pick(rng)]);
      sample[k] = pool[k];
    }
    const auto h = fitCorrection(in, sample, cols);
    if (!h) continue;
    double cost = 0.0;
    std::vector<int> set = agreeing(in, idx, *h, q1, &cost);
    if (set.size() > best.size() || (set.size() == best.size() && cost < bestCost)) {
      best = std::move(set);
      bestCost = cost;
    }
  }
  if (best.size() < m) return {};
  const auto fit = fitCorrection(in, best, cols);
  if (!fit) return {};
  best = agreeing(in, idx, *fit, q1, nullptr);
  const auto refit = fitCorrection(in, best, cols);
  if (!refit) return {};
  x = *refit;
  return best;
}

}  // namespace

ReacquisitionSelection selectReacquisitionRows(const ReacquisitionRows& in, double tau, double acceleration,
                                               double rowQuantile, double epochGate) {
  ReacquisitionSelection out;
  const auto n = static_cast<Eigen::Index>(in.residual.size());
  out.admitted.assign(static_cast<std::size_t>(n), false);
  out.tau = std::max(tau, 0.0);
  out.sigmaP = 0.5 * acceleration * out.tau * out.tau;
  out.sigmaV = acceleration * out.tau;
  for (int g = 0; g < 2; ++g) {
    ReacquisitionGroupResult& res = out.groups[static_cast<std::size_t>(g)];
    const double s2 = g == kReacquireRange ? out.sigmaP * out.sigmaP : out.sigmaV * out.sigmaV;  // Q(τ) = s2 I
    std::vector<int> offered, widened;
    for (Eigen::Index i = 0; i < n; ++i) {
      if (in.group[static_cast<std::size_t>(i)] != g || !std::isfinite(in.residual[i])) continue;
      offered.push_back(static_cast<int>(i));
      // 1. The widened row gate: r² ≤ q1 (S_ii + s2 |g|²).
      const double v = in.S(i, i) + s2 * in.G.row(i).squaredNorm();
      if (v > 0.0 && in.bandVariance[i] > 0.0 && in.residual[i] * in.residual[i] <= rowQuantile * v) {
        widened.push_back(static_cast<int>(i));
      }
    }
    res.offered = static_cast<int>(offered.size());
    if (offered.empty()) continue;
    const std::vector<int> cols = activeColumns(in.G, offered);
    res.unknowns = static_cast<int>(cols.size());
    // 2. The consensus: a majority, with at least one row more than the unknowns.
    const std::vector<int> set = consensus(in, widened, cols, rowQuantile, res.correction);
    res.agreeing = static_cast<int>(set.size());
    if (res.agreeing < res.unknowns + 1 || 2 * res.agreeing <= res.offered) continue;
    // The widened joint χ² of the agreeing rows: rᵀ (S + G Q Gᵀ)⁻¹ r.
    const auto k = static_cast<Eigen::Index>(set.size());
    Eigen::MatrixXd Sk(k, k);
    Eigen::VectorXd r(k);
    for (Eigen::Index a = 0; a < k; ++a) {
      const int i = set[static_cast<std::size_t>(a)];
      r[a] = in.residual[i];
      for (Eigen::Index b = 0; b < k; ++b) {
        const int j = set[static_cast<std::size_t>(b)];
        Sk(a, b) = in.S(i, j) + s2 * in.G.row(i).dot(in.G.row(j));
      }
    }
    const Eigen::LLT<Eigen::MatrixXd> llt(Sk);
    if (llt.info() != Eigen::Success) continue;
    res.chi2 = r.dot(llt.solve(r));
    res.threshold = sri::chiSquareQuantile(epochGate, static_cast<int>(k));
    if (!(res.chi2 <= res.threshold)) continue;
    res.admitted = true;
    for (int i : set) out.admitted[static_cast<std::size_t>(i)] = true;
  }
  return out;
}

bool GnssGateRecovery::reacquiring(const GpsTime& t) {
  if (!(after_ > 0.0)) return false;
  if (active_) return true;
  const bool outage = lastUpdate_ && t - *lastUpdate_ >= after_;
  const bool rejected = rejectedSince_ && t - *rejectedSince_ >= after_;
  if (!outage && !rejected) return false;
  active_ = true;
  activeSince_ = t;
  ++recoveries_;
  char buf[300];
  std::snprintf(buf, sizeof buf,
                "GNSS rows: %s for %.1f s at %d %.3f; re-acquiring through the widened gate and a consensus of the "
                "satellites (gnss_gate_recovery.hpp)",
                rejected ? "every row gated out (the state drifted away)" : "no GNSS update applied",
                rejected ? t - *rejectedSince_ : t - *lastUpdate_, t.week(), t.tow());
  warnings_.emplace_back(buf);
  return true;
}

namespace {

/// "G10 G23 E7" of the rows `which` (admitted or not) of group g.
std::string satList(const ReacquisitionRows& in, const ReacquisitionSelection& s, int g, bool which) {
  std::string out;
  for (std::size_t i = 0; i < s.admitted.size(); ++i) {
    if (in.group[i] != g || !std::isfinite(in.residual[static_cast<Eigen::Index>(i)]) || s.admitted[i] != which) continue;
    if (!out.empty()) out += ' ';
    out += in.sats[i].str();
  }
  return out.empty() ? "none" : out;
}

}  // namespace

std::string describeReacquisition(const ReacquisitionRows& in, const ReacquisitionSelection& s) {
  static const char* kName[2] = {"range", "rate"};
  static const char* kUnit[2] = {"m", "m/s"};
  char head[160];
  std::snprintf(head, sizeof head, "%.2f s since the last update, widened by %.1f m, %.2f m/s", s.tau, s.sigmaP,
                s.sigmaV);
  std::string msg = head;
  for (int g = 0; g < 2; ++g) {
    const ReacquisitionGroupResult& r = s.groups[static_cast<std::size_t>(g)];
    if (r.offered == 0) continue;
    char buf[320];
    if (r.admitted) {
      std::snprintf(buf, sizeof buf,
                    "; %s rows: %d of %d agree on a common shift of %.2f %s (clock %.2f), χ² %.1f <= %.1f; admitted %s; "
                    "excluded %s",
                    kName[g], r.agreeing, r.offered, r.correction.head<3>().norm(), kUnit[g], r.correction[3], r.chi2,
                    r.threshold, satList(in, s, g, true).c_str(), satList(in, s, g, false).c_str());
    } else if (r.agreeing < r.unknowns + 1 || 2 * r.agreeing <= r.offered) {
      std::snprintf(buf, sizeof buf, "; %s rows: no consensus (%d of %d agree), none admitted", kName[g], r.agreeing,
                    r.offered);
    } else {
      std::snprintf(buf, sizeof buf, "; %s rows: %d of %d agree but χ² %.1f > %.1f, none admitted", kName[g],
                    r.agreeing, r.offered, r.chi2, r.threshold);
    }
    msg += buf;
  }
  return msg;
}

ReacquisitionTally tallyReacquisition(const ReacquisitionRows& in, const ReacquisitionSelection& s) {
  ReacquisitionTally out;
  for (std::size_t i = 0; i < s.admitted.size(); ++i) {
    if (in.group[i] == kReacquireNone || !std::isfinite(in.residual[static_cast<Eigen::Index>(i)])) continue;
    if (s.admitted[i]) {
      ++out.admitted;
      continue;
    }
    ++out.excluded;
    if (std::find(out.excludedSats.begin(), out.excludedSats.end(), in.sats[i]) == out.excludedSats.end())
      out.excludedSats.push_back(in.sats[i]);
  }
  return out;
}

ReacquisitionTally GnssGateRecovery::outcome(const GpsTime& t, std::size_t rows, bool applied, bool normal,
                                             const ReacquisitionSelection* selection, const ReacquisitionRows* input) {
  ReacquisitionTally tally;
  if (applied) {
    lastUpdate_ = t;
    rejectedSince_.reset();
  } else if (rows > 0 && !rejectedSince_) {
    rejectedSince_ = t;
  }
  if (!active_) return tally;
  const bool admitted =
      selection && std::find(selection->admitted.begin(), selection->admitted.end(), true) != selection->admitted.end();
  if (admitted && input && applied) {
    tally = tallyReacquisition(*input, *selection);
    char buf[80];
    std::snprintf(buf, sizeof buf, "GNSS re-acquisition at %d %.3f: ", t.week(), t.tow());
    warnings_.push_back(buf + describeReacquisition(*input, *selection) +
                        (normal ? " (normal gates pass: re-acquired)" : " (applied without the epoch gate)"));
  }
  if (applied && normal) {
    char buf[200];
    std::snprintf(buf, sizeof buf, "GNSS rows: re-acquired at %d %.3f after %.1f s (normal gates again)", t.week(),
                  t.tow(), activeSince_ ? t - *activeSince_ : 0.0);
    warnings_.emplace_back(buf);
    active_ = false;
  }
  return tally;
}

}  // namespace gvins::fusion
