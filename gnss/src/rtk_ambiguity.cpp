// Step 7 of RtkSolver::process (rtk.hpp): integer ambiguity resolution of the float solution, the
// checks that make a fixed solution a fix, confirmation of marginal first fixes, fix-and-hold.
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <unordered_map>

#include <Eigen/Cholesky>

#include "gvins/gnss/ambiguity_resolution.hpp"
#include "gvins/gnss/rtk.hpp"
#include "gvins/sri/chi_square.hpp"

namespace gvins {

using Meas = sri::Measurement<double>;

namespace {


/// Start basis for this epoch's LAMBDA from the previous epoch's reduced basis (of the DD pairs
/// `before`), when every one of those pairs is still among `now`: the old basis on the old pairs'
/// rows and a unit column for each new pair (unimodular, and its inverse likewise). nullopt if a
/// pair has gone (or there is no previous basis): the reduction starts cold.
std::optional<ReductionStart> embedBasis(const std::vector<std::pair<sri::BlockId, sri::BlockId>>& before,
                                         const ReductionStart& basis,
                                         const std::vector<std::pair<sri::BlockId, sri::BlockId>>& now) {
  const int m0 = static_cast<int>(before.size());
  const int m = static_cast<int>(now.size());
  if (m0 == 0 || m0 > m || !basis.fits(m0)) return std::nullopt;
  std::vector<int> where(static_cast<std::size_t>(m0));
  for (int i = 0; i < m0; ++i) {
    const auto it = std::find(now.begin(), now.end(), before[static_cast<std::size_t>(i)]);
    if (it == now.end()) return std::nullopt;
    where[static_cast<std::size_t>(i)] = static_cast<int>(it - now.begin());
  }
  ReductionStart start{Eigen::MatrixXd::Zero(m, m), Eigen::MatrixXd::Zero(m, m)};
  std::vector<char> old(static_cast<std::size_t>(m), 0);
  for (int i = 0; i < m0; ++i) {
    const int r = where[static_cast<std::size_t>(i)];
    old[static_cast<std::size_t>(r)] = 1;
    for (int j = 0; j < m0; ++j) {
      start.Z(r, j) = basis.Z(i, j);
      start.Zinv(j, r) = basis.Zinv(j, i);
    }
  }
  for (int r = 0, c = m0; r < m; ++r) {
    if (old[static_cast<std::size_t>(r)]) continue;
    start.Z(r, c) = 1.0;
    start.Zinv(c, r) = 1.0;
    ++c;
  }
  return start;
}


}  // namespace

int fixedSatelliteSpan(const DdEpoch& dd, const std::vector<DoubleDifference>& phases) {
  // Satellites as nodes, DDs as edges: the independent directions are the nodes less the
  // connected sets (union-find over the satellites' indices).
  std::vector<SatId> sats;
  auto node = [&](int sdIndex) {
    const SatId s = dd.sd.at(static_cast<std::size_t>(sdIndex)).sat;
    const auto it = std::find(sats.begin(), sats.end(), s);
    if (it != sats.end()) return static_cast<int>(it - sats.begin());
    sats.push_back(s);
    return static_cast<int>(sats.size()) - 1;
  };
  std::vector<int> parent;
  auto root = [&](int i) {
    while (parent[static_cast<std::size_t>(i)] != i) i = parent[static_cast<std::size_t>(i)];
    return i;
  };
  int sets = 0;
  for (const DoubleDifference& d : phases) {
    const int a = node(d.reference), b = node(d.satellite);
    while (parent.size() < sats.size()) {
      parent.push_back(static_cast<int>(parent.size()));
      ++sets;
    }
    const int ra = root(a), rb = root(b);
    if (ra != rb) {
      parent[static_cast<std::size_t>(ra)] = rb;
      --sets;
    }
  }
  return sats.empty() ? 0 : static_cast<int>(sats.size()) - sets + 1;
}

bool isFixSet(const DdEpoch& dd, const std::vector<DoubleDifference>& phases, const RtkConfig& cfg) {
  return static_cast<int>(phases.size()) >= std::max(1, cfg.ar.minFixed) &&
         fixedSatelliteSpan(dd, phases) >= cfg.arMinSatellites;
}

std::vector<DoubleDifference> applicableFixedPhases(const DdEpoch& dd, const RtkConfig& cfg) {
  std::vector<DoubleDifference> out;
  for (const DoubleDifference& d : dd.phase) {
    if (d.fixedCycles && d.ambiguityMeters) out.push_back(d);
  }
  if (!isFixSet(dd, out, cfg)) out.clear();
  return out;
}

std::vector<RtkSolver::ArPair> RtkSolver::arPairs(std::vector<int>& arRef) const {
  // Eligible SDs per group and the DD pairs (AR reference, satellite).
  std::vector<char> inPhase(dd_.sd.size(), 0);
  for (const DoubleDifference& d : dd_.phase) {
    inPhase[static_cast<std::size_t>(d.reference)] = 1;
    inPhase[static_cast<std::size_t>(d.satellite)] = 1;
  }
  std::vector<ArPair> pairs;
  arRef.assign(dd_.groups.size(), -1);
  for (std::size_t g = 0; g < dd_.groups.size(); ++g) {
    std::vector<int> members;
    for (std::size_t i = 0; i < dd_.sd.size(); ++i) {
      const SingleDifference& s = dd_.sd[i];
      if (s.group != static_cast<int>(g) || !inPhase[i] || !s.hasPhase || s.halfCycle) continue;
      if (!cfg_.fixSystem(s.sat.system) || s.elevation < cfg_.arElevationMask) continue;
      const auto it = amb_.find(key(s.sat, s.code));
      if (it == amb_.end() || it->second.lock < cfg_.arMinLock) continue;
      members.push_back(static_cast<int>(i));
    }
    if (members.size() < 2) continue;
    int ref = dd_.groups[g].phaseReference;
    if (std::find(members.begin(), members.end(), ref) == members.end()) {
      ref = members[0];
      for (int i : members) {
        if (dd_.sd[static_cast<std::size_t>(i)].elevation > dd_.sd[static_cast<std::size_t>(ref)].elevation) ref = i;
      }
    }
    arRef[g] = ref;
    const SingleDifference& f = dd_.sd[static_cast<std::size_t>(ref)];
    const sri::BlockId rid = amb_.at(key(f.sat, f.code)).id;
    for (int i : members) {
      if (i == ref) continue;
      const SingleDifference& s = dd_.sd[static_cast<std::size_t>(i)];
      pairs.push_back(ArPair{ref, i, rid, amb_.at(key(s.sat, s.code)).id});
    }
  }
  return pairs;
}

bool RtkSolver::arCovariance(const std::vector<ArPair>& pairs, Eigen::VectorXd& a, Eigen::MatrixXd& Qaa,
                             Eigen::MatrixXd& Qxa, std::vector<int>& ionosphereRows) const {
  // Joint covariance of [position; ionosphere; DD ambiguities] from the square-root factor: with
  // F the rows of R⁻¹ of the position, of the SD ionosphere states (satIndex order in
  // ionosphereRows, rows 3.. of Qxa) and of the SD ambiguities (SriFilter::covarianceFactor,
  // ~n³/6), a DD's row is F_sat − F_ref and Q = Y Yᵀ over Y = [F_pos; F_iono; F_sat − F_ref].
  const int m = static_cast<int>(pairs.size());
  std::vector<sri::BlockId> ids{pos_};
  ionosphereRows.clear();
  for (const auto& [k, s] : iono_) {
    ionosphereRows.push_back(k);
    ids.push_back(s.id);
  }
  const int nx = 3 + static_cast<int>(ionosphereRows.size());
  std::unordered_map<std::uint64_t, int> rowOf;  // SD ambiguity block → row of F
  auto listed = [&](sri::BlockId id) {
    if (rowOf.emplace(id.value, 2 + static_cast<int>(ids.size())).second) ids.push_back(id);
  };
  a.resize(m);
  for (int k = 0; k < m; ++k) {
    const ArPair& p = pairs[static_cast<std::size_t>(k)];
    listed(p.satId);
    listed(p.refId);
    a[k] = filter_.estimate(p.satId).vector[0] - filter_.estimate(p.refId).vector[0];
  }
  Eigen::MatrixXd F;
  try {
    F = filter_.covarianceFactor(ids);
  } catch (const std::domain_error&) {
    return false;
  }
  if (F.rows() != static_cast<Eigen::Index>(ids.size()) + 2) return false;  // a block without information
  Eigen::MatrixXd Y(nx + m, F.cols());
  Y.topRows(nx) = F.topRows(nx);
  for (int k = 0; k < m; ++k) {
    const ArPair& p = pairs[static_cast<std::size_t>(k)];
    Y.row(nx + k) = F.row(rowOf.at(p.satId.value)) - F.row(rowOf.at(p.refId.value));
  }
  Eigen::MatrixXd Q = Eigen::MatrixXd::Zero(nx + m, nx + m);
  Q.selfadjointView<Eigen::Lower>().rankUpdate(Y);
  Q = Q.selfadjointView<Eigen::Lower>();
  Qaa = Q.bottomRightCorner(m, m);
  Qxa = Q.topRightCorner(nx, m);
  return true;
}

ArStatus RtkSolver::checkFix(const std::vector<ArPair>& pairs, const RtkSolution& sol, const ConditionedFix& f) {
  // 1. Precision: a fix must determine the position. Partial fixing can fix combinations that
  //    the geometry does not see (with few satellites and one epoch of code, the n − 3
  //    combinations free of the position): their integers may be right, the position is not.
  if (!(std::sqrt(std::max(f.covariance.trace(), 0.0)) <= cfg_.maxFixedSigma)) {
    ++counters_.impreciseFixes;
    return ArStatus::Imprecise;
  }
  // 2. Position domain: with the right integers x_fix − x_float ~ N(0, P_float − P_fix); the test
  //    takes the float covariance itself (larger: a filter's float error is correlated in time,
  //    which P_float − P_fix, small once the float has converged, does not allow for).
  if (cfg_.fixPositionTestAlpha > 0.0) {
    const Eigen::Vector3d dx = f.position - sol.floatPosition;
    const Eigen::Matrix3d S = sol.floatCovariance;
    const Eigen::LDLT<Eigen::Matrix3d> ldlt(0.5 * (S + S.transpose()));
    if (ldlt.info() == Eigen::Success && ldlt.isPositive()) {
      const double t = dx.dot(ldlt.solve(dx));
      if (std::isfinite(t) && t > sri::chiSquareQuantile(1.0 - cfg_.fixPositionTestAlpha, 3)) {
        ++counters_.inconsistentFixes;
        return ArStatus::Inconsistent;
      }
    }
  }
  // 3. Every DD phase of the AR set at the fixed position, with its conditioned ambiguity.
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    const ArPair& p = pairs[k];
    const SingleDifference& s = dd_.sd[static_cast<std::size_t>(p.sat)];
    const SingleDifference& r = dd_.sd[static_cast<std::size_t>(p.ref)];
    const double nref = filter_.estimate(p.refId).vector[0];
    const double v = sdPhaseResidual(s, f.position) - sdPhaseResidual(r, f.position) -
                     (s.wavelength * f.ambiguities[static_cast<Eigen::Index>(k)] + (s.wavelength - r.wavelength) * nref) +
                     ddIonosphere(s, r, &f.ionosphere);
    if (std::abs(v) > cfg_.fixValidationSigmas * std::sqrt(s.phaseVariance + r.phaseVariance)) {
      ++counters_.rejectedFixes;
      return ArStatus::Rejected;
    }
  }
  // 4. Every DD code at the fixed position: integers that move the position by metres (a wrong
  //    fix of a weak model) leave code residuals of several sigma.
  for (const DoubleDifference& d : dd_.code) {
    const DdResidual r = ddCodeResidual(dd_, d, f.position);
    const double v = r.residual - ddIonosphere(dd_.sd[static_cast<std::size_t>(d.satellite)],
                                               dd_.sd[static_cast<std::size_t>(d.reference)], &f.ionosphere);
    if (std::abs(v) > cfg_.fixCodeValidationSigmas * std::sqrt(r.variance)) {
      ++counters_.rejectedFixes;
      return ArStatus::Rejected;
    }
  }
  return ArStatus::Fixed;
}

std::vector<double> RtkSolver::ddIntegers(const std::vector<ArPair>& pairs, const std::vector<int>& arRef,
                                          const ConditionedFix& f) const {
  // Conditioned ambiguities relative to each group's AR reference; a DD phase of dd_ gets an
  // integer where the difference of its two is one.
  std::vector<double> rel(dd_.sd.size(), std::numeric_limits<double>::quiet_NaN());
  for (int r : arRef) {
    if (r >= 0) rel[static_cast<std::size_t>(r)] = 0.0;
  }
  for (std::size_t k = 0; k < pairs.size(); ++k) rel[static_cast<std::size_t>(pairs[k].sat)] = f.ambiguities[static_cast<Eigen::Index>(k)];
  std::vector<double> out(dd_.phase.size(), std::numeric_limits<double>::quiet_NaN());
  for (std::size_t i = 0; i < dd_.phase.size(); ++i) {
    const DoubleDifference& d = dd_.phase[i];
    const double val = rel[static_cast<std::size_t>(d.satellite)] - rel[static_cast<std::size_t>(d.reference)];
    if (std::isfinite(val) && std::abs(val - std::round(val)) <= 1e-3) out[i] = std::round(val);
  }
  return out;
}

void RtkSolver::hold(const std::vector<ArPair>& pairs, const AmbiguityFix& fix, const Eigen::VectorXd& a) {
  // Fixed combinations as constraints on the SD ambiguity states.
  const Eigen::MatrixXd& T = fix.T;
  const int m = static_cast<int>(pairs.size());
  Meas h(static_cast<int>(T.rows()));
  for (int r = 0; r < T.rows(); ++r) {
    double cur = 0.0;
    for (int k = 0; k < m; ++k) {
      const double c = T(r, k);
      if (c == 0.0) continue;
      const ArPair& p = pairs[static_cast<std::size_t>(k)];
      h.jacobian(p.satId, 1)(r, 0) += c;
      h.jacobian(p.refId, 1)(r, 0) -= c;
      cur += c * a[k];
    }
    h.residual()[r] = fix.values[r] - cur;
  }
  h.whitenStdDev(cfg_.holdSigmaCycles);
  filter_.update(h);
  filter_.correct();
  ++counters_.holdUpdates;
}

void RtkSolver::rememberFix() {
  // A pair's arcs are part of its key (a detected slip starts a new arc); a flagged signal or an
  // ambiguity re-initialised by the post-fit test this epoch (forced_: an undetected slip?) ends
  // what an earlier fix says about it. This epoch's fix is of the arcs as they are now.
  auto reinitialised = [&](int sd) {
    const SingleDifference& s = dd_.sd[static_cast<std::size_t>(sd)];
    return forced_.count(key(s.sat, s.code)) > 0;
  };
  std::vector<std::pair<HeldPair, double>> kept;
  for (const DoubleDifference& d : dd_.phase) {
    const HeldPair p = pairOf(d);
    const auto now = std::find_if(fixNow_.begin(), fixNow_.end(), [&](const auto& e) { return e.first == p; });
    if (now != fixNow_.end()) {
      kept.push_back(*now);
      continue;
    }
    if (flagged(d) || reinitialised(d.satellite) || reinitialised(d.reference)) continue;
    const auto before = std::find_if(fixMemory_.begin(), fixMemory_.end(), [&](const auto& e) { return e.first == p; });
    if (before != fixMemory_.end()) kept.push_back(*before);
  }
  fixMemory_ = std::move(kept);
}

void RtkSolver::resolve(RtkSolution& sol) {
  if (cfg_.ambiguityMode == AmbiguityMode::Off) {
    sol.ar = ArStatus::Off;
    return;
  }
  auto notFixed = [&](ArStatus s) {
    sol.ar = s;
    consecutiveFixes_ = 0;
  };
  // 1. The AR set and its float ambiguities with their covariance.
  std::vector<int> arRef;
  const std::vector<ArPair> pairs = arPairs(arRef);
  const int m = static_cast<int>(pairs.size());
  sol.numAmbiguities = m;
  if (m < std::max(1, cfg_.ar.minFixed)) return notFixed(ArStatus::TooFewAmbiguities);
  ++counters_.arAttempts;
  Eigen::VectorXd a;
  Eigen::MatrixXd Qaa, Qxa;
  std::vector<int> ionosphereRows;
  if (!arCovariance(pairs, a, Qaa, Qxa, ionosphereRows)) return notFixed(ArStatus::NotValidated);

  // 2. LAMBDA with validation and partial fixing, warm-started from the last epoch's basis.
  std::vector<std::pair<sri::BlockId, sri::BlockId>> now(static_cast<std::size_t>(m));
  for (int k = 0; k < m; ++k) now[static_cast<std::size_t>(k)] = {pairs[static_cast<std::size_t>(k)].satId, pairs[static_cast<std::size_t>(k)].refId};
  const std::optional<ReductionStart> start = embedBasis(arPairs_, arBasis_, now);
  arPairs_ = std::move(now);
  const AmbiguityFix fix = resolveAmbiguities(a, Qaa, cfg_.ar, start ? &*start : nullptr);
  arBasis_ = fix.basis;
  if (!arBasis_.fits(m)) arPairs_.clear();
  sol.ratio = fix.fixed ? fix.ratio : fix.fullRatio;
  sol.successRate = fix.fixed ? fix.successRate : fix.fullSuccessRate;
  sol.criticalRatio = fix.criticalRatio;
  if (!fix.fixed) return notFixed(ArStatus::NotValidated);

  // 3. Condition the float solution on the fixed combinations y = T a = t (T = I for a full fix).
  ConditionedFix cf;
  {
    const bool full = !fix.partial;
    const Eigen::VectorXd dy = full ? Eigen::VectorXd(a - fix.values) : Eigen::VectorXd(fix.T * a - fix.values);
    const Eigen::MatrixXd QaT = full ? Qaa : Eigen::MatrixXd(Qaa * fix.T.transpose());  // Q_ay
    const Eigen::MatrixXd Qyy = full ? Qaa : Eigen::MatrixXd(fix.T * QaT);
    const Eigen::MatrixXd QxT = full ? Qxa : Eigen::MatrixXd(Qxa * fix.T.transpose());  // Q_xy
    const Eigen::LLT<Eigen::MatrixXd> llt(Qyy);
    if (llt.info() != Eigen::Success) return notFixed(ArStatus::NotValidated);
    const Eigen::VectorXd w = llt.solve(dy);
    const Eigen::VectorXd dx = QxT * w;
    cf.position = sol.floatPosition - dx.head<3>();
    for (std::size_t i = 0; i < ionosphereRows.size(); ++i) {
      const int k = ionosphereRows[i];
      cf.ionosphere[k] = filter_.estimate(iono_.at(k).id).vector[0] - dx[3 + static_cast<Eigen::Index>(i)];
    }
    const Eigen::Matrix3d P = sol.floatCovariance - QxT.topRows(3) * llt.solve(QxT.topRows(3).transpose());
    cf.covariance = 0.5 * (P + P.transpose());
    cf.ambiguities = full ? Eigen::VectorXd(fix.values) : Eigen::VectorXd(a - QaT * w);
  }

  // 4. The checks of the fixed solution.
  const ArStatus check = checkFix(pairs, sol, cf);
  if (check != ArStatus::Fixed) return notFixed(check);

  //    Too few DD integers, or of too few satellites, do not determine the position (isFixSet:
  //    the rule of applicableFixedPhases).
  const std::vector<double> ints = ddIntegers(pairs, arRef, cf);
  std::vector<DoubleDifference> integer;
  for (std::size_t i = 0; i < dd_.phase.size(); ++i) {
    if (std::isfinite(ints[i])) integer.push_back(dd_.phase[i]);
  }
  if (!isFixSet(dd_, integer, cfg_)) return notFixed(ArStatus::TooFewAmbiguities);

  // 5. Confirmation: a marginal fix needs another validated fix of the same integers on the same
  //    arcs, an earlier one (fixMemory_: the integers are constant on an arc) or the next epoch's
  //    (this epoch's integers are remembered); no DD integer may differ.
  for (std::size_t i = 0; i < dd_.phase.size(); ++i) {
    if (std::isfinite(ints[i])) fixNow_.emplace_back(pairOf(dd_.phase[i]), ints[i]);
  }
  if (fix.ratio < cfg_.confirmRatioFactor * fix.criticalRatio) {
    int same = 0, differ = 0;
    for (const auto& [p, n] : fixNow_) {
      for (const auto& [q, n0] : fixMemory_) {
        if (p == q) (n == n0 ? same : differ) += 1;
      }
    }
    const int needed = std::min<int>(std::max(1, cfg_.ar.minFixed), static_cast<int>(fixNow_.size()));
    if (differ > 0 || same < std::max(1, needed)) {
      ++counters_.unconfirmedFixes;
      return notFixed(ArStatus::Unconfirmed);
    }
  }

  // 6. The fix.
  sol.quality = SolutionQuality::Fix;
  sol.position = cf.position;
  sol.positionCovariance = cf.covariance;
  sol.ar = fix.partial ? ArStatus::PartialFixed : ArStatus::Fixed;
  sol.numFixed = fix.numFixed();
  if (fix.partial) ++counters_.partialFixes;
  for (std::size_t i = 0; i < dd_.phase.size(); ++i) {
    if (!std::isfinite(ints[i])) continue;
    DoubleDifference& d = dd_.phase[i];
    const SingleDifference& f = dd_.sd[static_cast<std::size_t>(d.reference)];
    d.fixedCycles = ints[i];
    // The DD phase's bias with its conditioned ionospheric advance (long baselines).
    d.ambiguityMeters = dd_.sd[static_cast<std::size_t>(d.satellite)].wavelength * ints[i] +
                        (dd_.sd[static_cast<std::size_t>(d.satellite)].wavelength - f.wavelength) * ambiguityEstimate(f) -
                        ddIonosphere(dd_.sd[static_cast<std::size_t>(d.satellite)], f, &cf.ionosphere);
  }

  // 7. Fix-and-hold: validated, confirmed fixes only, after holdMinFixes of them in a row.
  ++consecutiveFixes_;
  if (cfg_.ambiguityMode == AmbiguityMode::FixAndHold && consecutiveFixes_ >= cfg_.holdMinFixes) {
    hold(pairs, fix, a);
    sol.held = true;
  }
}

}  // namespace gvins
