// Integer least-squares (ILS) estimation of carrier-phase ambiguities with the LAMBDA method:
// the float ambiguities â with covariance Q are decorrelated by an integer, volume-preserving
// (unimodular) transformation z = Zᵀa, and the integer vectors closest to ẑ in the metric of
// Q_ẑ = ZᵀQZ are found by a depth-first search with a shrinking ellipsoid.
//
// References (algorithms implemented from their descriptions):
//   - P.J.G. Teunissen (1995), "The least-squares ambiguity decorrelation adjustment: a method for
//     fast GPS integer ambiguity estimation", J. Geodesy 70:65-82 (decorrelation, ILS).
//   - P.J. de Jonge, C.C.J.M. Tiberius (1996), "The LAMBDA method for integer ambiguity
//     estimation: implementation aspects", LGR series 12, TU Delft: the LᵀDL factorization,
//     integer Gauss transformations and the reordering of conditional variances.
//   - X.-W. Chang, X. Yang, T. Zhou (2005), "MLAMBDA: a modified LAMBDA method for integer
//     least-squares estimation", J. Geodesy 79:552-565: the reduction with symmetric pivoting
//     (Gauss transformations only where a permutation needs them) and the Schnorr-Euchner
//     enumeration that shrinks the search ellipsoid as soon as candidates are found.
//   - P.J.G. Teunissen (1998), "Success probability of integer GPS ambiguity rounding and
//     bootstrapping", J. Geodesy 72:606-612: the bootstrapped success rate
//     P = Π (2Φ(1/(2σ_i)) − 1), a sharp lower bound of the ILS success rate.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>

namespace gvins {

/// Q = Lᵀ diag(d) L with L unit lower triangular (de Jonge & Tiberius 1996, eq. 3.8): d[i] is
/// the variance of a_i conditioned on a_{i+1..n-1}: with a − â = Lᵀw, w ~ N(0, diag(d)) independent,
/// E[a_i | a_j, j > i] = â_i + Σ_{j>i} L(j, i) w_j, w_j = a_j − E[a_j | a_{>j}].
struct LtdlFactor {
  Eigen::MatrixXd L;
  Eigen::VectorXd d;
};

/// Factorizes a symmetric positive definite matrix (lower triangle read). nullopt if a
/// conditional variance is not positive (Q not positive definite within rounding).
std::optional<LtdlFactor> ltdlFactorize(const Eigen::MatrixXd& Q);

/// Result of the decorrelating reduction: z = Zᵀ a, Q_z = ZᵀQZ = Lᵀ diag(d) L (the factor of the
/// transformed problem). `Zinv` = Z⁻¹ (integer), so a = Z⁻ᵀ z = Zinvᵀ z.
struct Reduction {
  Eigen::MatrixXd Z;
  Eigen::MatrixXd Zinv;
  LtdlFactor factor;
  int gaussTransformations = 0;
  int permutations = 0;
};

/// LAMBDA reduction of a factor (Chang et al. 2005, algorithm REDUCTION): integer Gauss
/// transformations make |L(i, j)| ≤ 1/2 where needed and permutations order the conditional
/// variances so that d[k+1] ≤ d[k] + L(k+1,k)² d[k+1] (the later ones, searched first, small).
Reduction reduceLambda(const LtdlFactor& f);

struct IlsSearchOptions {
  int candidates = 2;              ///< number of best integer vectors wanted (≥ 1)
  std::int64_t maxNodes = 200000;  ///< search-tree nodes before giving up
};

struct IlsSearchResult {
  /// Best integer vectors (ascending squared norm), stored as doubles (exact integers).
  std::vector<Eigen::VectorXd> candidates;
  std::vector<double> squaredNorms;  ///< (ẑ − z)ᵀ Q_z⁻¹ (ẑ − z)
  std::int64_t nodes = 0;
  bool complete = true;  ///< false: maxNodes was reached (candidates may not be optimal)
};

/// Integer least-squares search with the factor of Q_z (Lᵀ diag(d) L) for the float vector ẑ:
/// Schnorr-Euchner zig-zag enumeration from the last component to the first, the ellipsoid
/// shrinking to the `candidates`-th best norm found so far (Chang et al. 2005, algorithm SEARCH).
IlsSearchResult searchIntegerLeastSquares(const LtdlFactor& f, const Eigen::VectorXd& zhat,
                                          const IlsSearchOptions& options = {});

/// Bootstrapped success rate Π (2Φ(1/(2√d_i)) − 1) of conditional variances d (Teunissen 1998).
double bootstrapSuccessRate(const Eigen::VectorXd& conditionalVariances);

/// Everything LAMBDA gives for one float vector.
struct LambdaResult {
  bool ok = false;  ///< false: Q not positive definite, or the search did not finish
  /// Best integer vectors in the original parametrisation, ascending squared norm.
  std::vector<Eigen::VectorXd> fixed;
  std::vector<double> squaredNorms;
  /// ratio = squaredNorms[1] / squaredNorms[0] (the usual "ratio test" value; 0 if fewer than two
  /// candidates).
  double ratio = 0.0;
  Reduction reduction;
  Eigen::VectorXd zhat;  ///< decorrelated float vector Zᵀ â
  double successRate = 0.0;  ///< bootstrapped, of the decorrelated problem
  std::int64_t nodes = 0;
};

/// A unimodular basis to start the reduction from: Z and Z⁻¹ of an earlier reduction of the same
/// ambiguities in the same order (in a filter, the previous epoch's). The float covariance changes
/// little between epochs, so ZᵀQZ is nearly reduced already and only a few permutations remain
/// (simulated Ddcp flight, 60 DD ambiguities: ~1000 per epoch cold, < 1 warm on average). The result
/// satisfies the same reduction conditions, so the ILS solution and the ratio do not depend on the
/// start; the reduced basis itself, and with it the bootstrapped success rate and the subsets of
/// partial fixing, may differ slightly.
struct ReductionStart {
  Eigen::MatrixXd Z;
  Eigen::MatrixXd Zinv;
  bool fits(int n) const { return Z.rows() == n && Z.cols() == n && Zinv.rows() == n && Zinv.cols() == n; }
};

/// Full LAMBDA: integer shift of â to [-0.5, 0.5] (the problem is invariant to it), LᵀDL
/// factorization, reduction, search, back transformation a = Z⁻ᵀ z + shift. With `start` (of the
/// right size) the reduction begins from that basis; a start that does not give a positive
/// definite ZᵀQZ is ignored.
LambdaResult lambda(const Eigen::VectorXd& afloat, const Eigen::MatrixXd& Q, const IlsSearchOptions& options = {},
                    const ReductionStart* start = nullptr);

}  // namespace gvins
