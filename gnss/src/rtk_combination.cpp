#include "gvins/gnss/rtk_combination.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Cholesky>

#include "gvins/sri/chi_square.hpp"

namespace gvins {

const char* toString(Combination c) {
  switch (c) {
    case Combination::None: return "no solution";
    case Combination::Single: return "single";
    case Combination::Float: return "float";
    case Combination::BothFixed: return "both passes fixed, agreeing";
    case Combination::ForwardFixed: return "forward fix";
    case Combination::BackwardFixed: return "backward fix";
    case Combination::FixRejected: return "fix inconsistent with the other pass's float";
    case Combination::Disagreement: return "both passes fixed, disagreeing";
  }
  return "?";
}

void CombinationCounts::add(const RtkSolution& forward, const RtkSolution& backward, Combination how) {
  ++epochs;
  if (forward.quality == SolutionQuality::Fix) ++forwardFixed;
  if (backward.quality == SolutionQuality::Fix) ++backwardFixed;
  switch (how) {
    case Combination::BothFixed: ++bothFixed; ++combinedFixed; break;
    case Combination::ForwardFixed: ++forwardOnlyFixed; ++combinedFixed; break;
    case Combination::BackwardFixed: ++backwardOnlyFixed; ++combinedFixed; break;
    case Combination::FixRejected: ++fixRejected; break;
    case Combination::Disagreement: ++disagreements; break;
    default: break;
  }
}

bool combineEstimates(const Eigen::Vector3d& xa, const Eigen::Matrix3d& Pa, const Eigen::Vector3d& xb,
                      const Eigen::Matrix3d& Pb, Eigen::Vector3d& x, Eigen::Matrix3d& P) {
  // Information form: Λ = Pa⁻¹ + Pb⁻¹, x = Λ⁻¹ (Pa⁻¹ xa + Pb⁻¹ xb) = xa + Λ⁻¹ Pb⁻¹ (xb − xa)
  // (the increment form keeps the precision of ECEF coordinates).
  const Eigen::LLT<Eigen::Matrix3d> la(0.5 * (Pa + Pa.transpose())), lb(0.5 * (Pb + Pb.transpose()));
  if (la.info() != Eigen::Success || lb.info() != Eigen::Success) return false;
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d info = la.solve(I) + lb.solve(I);
  const Eigen::LLT<Eigen::Matrix3d> li(0.5 * (info + info.transpose()));
  if (li.info() != Eigen::Success) return false;
  x = xa + li.solve(lb.solve(Eigen::Vector3d(xb - xa)));
  P = li.solve(I);
  P = 0.5 * (P + P.transpose());
  return x.allFinite() && P.allFinite();
}

bool consistent(const Eigen::Vector3d& xa, const Eigen::Vector3d& xb, const Eigen::Matrix3d& S, double alpha) {
  const Eigen::LDLT<Eigen::Matrix3d> ldlt(0.5 * (S + S.transpose()));
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) return false;
  const Eigen::Vector3d d = xa - xb;
  const double t = d.dot(ldlt.solve(d));
  return std::isfinite(t) && t <= sri::chiSquareQuantile(1.0 - alpha, 3);
}

namespace {

bool hasFloat(const RtkSolution& s) {
  return s.quality == SolutionQuality::Fix || s.quality == SolutionQuality::Float;
}

/// Float solution of the epoch from the passes' float positions (one or both).
RtkSolution combinedFloat(const RtkSolution& f, const RtkSolution& b) {
  if (!hasFloat(b)) {
    RtkSolution s = f;
    s.quality = SolutionQuality::Float;
    s.position = f.floatPosition;
    s.positionCovariance = f.floatCovariance;
    return s;
  }
  if (!hasFloat(f)) return combinedFloat(b, f);
  RtkSolution s = f;
  s.quality = SolutionQuality::Float;
  Eigen::Vector3d x;
  Eigen::Matrix3d P;
  if (combineEstimates(f.floatPosition, f.floatCovariance, b.floatPosition, b.floatCovariance, x, P)) {
    s.position = s.floatPosition = x;
    s.positionCovariance = s.floatCovariance = P;
  } else {
    const bool useB = b.floatCovariance.trace() < f.floatCovariance.trace();
    s.position = s.floatPosition = useB ? b.floatPosition : f.floatPosition;
    s.positionCovariance = s.floatCovariance = useB ? b.floatCovariance : f.floatCovariance;
  }
  s.numSatellites = std::max(f.numSatellites, b.numSatellites);
  return s;
}

/// Whether the fixed solution `fix` agrees with the other pass's float `other` (true when that
/// has no float: nothing to test against).
bool fixAgrees(const RtkSolution& fix, const RtkSolution& other, const CombinationOptions& o) {
  if (!hasFloat(other)) return true;
  const Eigen::Matrix3d S = other.floatCovariance + fix.positionCovariance +
                            o.floatSigmaFloor * o.floatSigmaFloor * Eigen::Matrix3d::Identity();
  return consistent(fix.position, other.floatPosition, S, o.alpha);
}

}  // namespace

RtkSolution combineSolutions(const RtkSolution& f, const RtkSolution& b, const CombinationOptions& o, Combination* how) {
  Combination h = Combination::None;
  RtkSolution s;
  const bool ff = f.quality == SolutionQuality::Fix, bf = b.quality == SolutionQuality::Fix;
  if (ff && bf) {
    if (consistent(f.position, b.position, f.positionCovariance + b.positionCovariance, o.alpha)) {
      s = combinedFloat(f, b);
      Eigen::Vector3d x;
      Eigen::Matrix3d P;
      if (!combineEstimates(f.position, f.positionCovariance, b.position, b.positionCovariance, x, P)) {
        x = f.position;
        P = f.positionCovariance;
      }
      s.quality = SolutionQuality::Fix;
      s.position = x;
      s.positionCovariance = P;
      s.ratio = std::max(f.ratio, b.ratio);
      s.numFixed = std::max(f.numFixed, b.numFixed);
      h = Combination::BothFixed;
    } else {
      s = combinedFloat(f, b);
      h = Combination::Disagreement;
    }
  } else if (ff || bf) {
    const RtkSolution& fix = ff ? f : b;
    const RtkSolution& other = ff ? b : f;
    if (fixAgrees(fix, other, o)) {
      s = fix;
      s.time = f.valid() ? f.time : b.time;
      h = ff ? Combination::ForwardFixed : Combination::BackwardFixed;
    } else {
      s = combinedFloat(f, b);
      h = Combination::FixRejected;
    }
  } else if (hasFloat(f) || hasFloat(b)) {
    s = combinedFloat(f, b);
    h = Combination::Float;
  } else if (f.valid() || b.valid()) {
    s = f.valid() ? f : b;
    h = Combination::Single;
  } else {
    s = f;
  }
  // One time tag for the epoch: the forward pass's (the rover time corrected by its SPP clock).
  if (f.valid()) s.time = f.time;
  if (how) *how = h;
  return s;
}

std::vector<RtkSolution> combinePasses(const std::vector<RtkSolution>& forward, const std::vector<RtkSolution>& backward,
                                       const CombinationOptions& options, std::vector<Combination>* how,
                                       CombinationCounts* counts) {
  if (forward.size() != backward.size()) {
    throw std::invalid_argument("combinePasses: forward pass of " + std::to_string(forward.size()) +
                                " epochs, backward pass of " + std::to_string(backward.size()));
  }
  std::vector<RtkSolution> out;
  out.reserve(forward.size());
  for (std::size_t i = 0; i < forward.size(); ++i) {
    Combination h = Combination::None;
    out.push_back(combineSolutions(forward[i], backward[i], options, &h));
    if (how) how->push_back(h);
    if (counts) counts->add(forward[i], backward[i], h);
  }
  return out;
}

}  // namespace gvins
