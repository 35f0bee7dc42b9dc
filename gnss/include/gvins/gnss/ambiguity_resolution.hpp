// Ambiguity resolution on top of LAMBDA: validation of the integer solution (ratio test,
// bootstrapped success rate) and partial ambiguity resolution when the full set fails.
//
// Validation. The ratio test accepts the best integer vector when the second-best squared norm
// is at least `ratioThreshold` times the best (threshold 3 by default, the usual fixed value; see
// Verhagen & Teunissen 2013, "The ratio test for future GNSS ambiguity resolution", GPS Solutions
// 17:535-548, for its theory). With `SuccessRate` the model-driven test of Teunissen (1998) is used
// instead: the integer solution is accepted when the bootstrapped success rate of the decorrelated
// problem, a sharp lower bound of the ILS success rate, is at least 1 − maxFailureRate, i.e. the
// failure rate is bounded by `maxFailureRate` whatever the data (a fixed-failure-rate acceptance
// that needs no simulated tables). `RatioAndSuccessRate` requires both.
//
// `FixedFailureRate` (the default) is the fixed-failure-rate ratio test (Teunissen & Verhagen
// 2009, "The GNSS ambiguity ratio-test revisited: a better way of using it", Survey Review 41:
// 138-151; Verhagen & Teunissen 2013): the critical value of the ratio is not a constant but
// follows the strength of the model, so that the probability of accepting a wrong integer vector
// stays below `maxFailureRate`. Where the bootstrapped success rate already reaches
// 1 − maxFailureRate any accepted fix fails at most that often, and the ratio threshold applies as
// it is. Below it, the critical value is found by simulation of the model itself instead of the
// published look-up tables: `ffrtSamples` float vectors are drawn from N(z, Q_ẑ) around an integer
// z in the reduced parametrisation, each is searched, and the critical ratio is the smallest
// value above which no more than maxFailureRate of all draws end with a wrong best candidate
// (deterministic: fixed seed). A model too weak for the bound at any ratio is not fixed. The
// ratio threshold stays a lower limit.
//
// Partial ambiguity resolution (PAR). If the full set fails, the decorrelated ambiguities are
// fixed from the back (where the reduction puts the smallest conditional variances) as long as
// the bootstrapped success rate of the subset stays at least `partialSuccessRate` (Teunissen,
// Joosten & Tiberius 1999, "A comparison of TCAR, CIR and LAMBDA GNSS ambiguity resolution",
// ION GPS; Verhagen, Teunissen & Odijk 2011 on the subset choice), then validated by the ratio test
// on that subset; if it fails the subset shrinks one ambiguity at a time down to `minFixed`.
// The result is a set of integer linear combinations T a = t of the input ambiguities (rows of
// Zᵀ), which the caller conditions its float solution on.
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>

#include <Eigen/Core>

#include "gvins/base/enum_names.hpp"
#include "gvins/gnss/lambda.hpp"

namespace gvins {

enum class AmbiguityValidation {
  Ratio,               ///< second-best / best squared norm ≥ ratioThreshold
  SuccessRate,         ///< bootstrapped success rate ≥ 1 − maxFailureRate
  RatioAndSuccessRate,  ///< both
  FixedFailureRate      ///< ratio ≥ the critical value that bounds the failure rate (simulated)
};
inline constexpr EnumName<AmbiguityValidation> kAmbiguityValidationNames[] = {
    {AmbiguityValidation::FixedFailureRate, "fixed-failure-rate"},
    {AmbiguityValidation::Ratio, "ratio"},
    {AmbiguityValidation::SuccessRate, "success-rate"},
    {AmbiguityValidation::RatioAndSuccessRate, "ratio+success-rate"}};

/// "ratio", "success-rate", "ratio+success-rate", "fixed-failure-rate".
const char* toString(AmbiguityValidation v);
/// The rule named as toString() spells it; nullopt for another text.
std::optional<AmbiguityValidation> parseAmbiguityValidation(std::string_view text);

struct AmbiguityResolutionOptions {
  AmbiguityValidation validation = AmbiguityValidation::FixedFailureRate;
  double ratioThreshold = 3.0;
  double maxFailureRate = 1e-3;  ///< for SuccessRate and FixedFailureRate validation
  int ffrtSamples = 4000;        ///< draws of the fixed-failure-rate simulation
  int ffrtMaxDimension = 30;     ///< larger weak sets are not simulated (not fixed as a whole)
  std::int64_t ffrtMaxNodes = 2000;  ///< per simulated search (an unfinished draw counts as a failure)
  bool partial = true;           ///< try partial fixing when the full set fails
  double partialSuccessRate = 0.999;  ///< bootstrapped success rate a PAR subset must reach
  int minFixed = 4;              ///< fewest ambiguities a (partial) fix may have
  int maxPartialAttempts = 6;    ///< subsets tried after the full set
  std::int64_t maxNodes = 200000;  ///< per ILS search
};

struct AmbiguityFix {
  bool fixed = false;
  bool partial = false;  ///< a subset (in the decorrelated parametrisation) was fixed
  /// Rows: the fixed integer combinations of the input ambiguities (k × n, integers): T â ≈ t.
  /// For a full fix T = I.
  Eigen::MatrixXd T;
  Eigen::VectorXd values;  ///< t (integers)
  /// For a full fix the integer vector ǎ (same as `values`); empty otherwise.
  Eigen::VectorXd fullSolution;
  double ratio = 0.0;        ///< of the set that was accepted (or of the full set if none)
  /// Ratio the accepted (or full) set had to reach: the threshold, or the fixed-failure-rate
  /// critical value when larger (infinity: no ratio bounds the failure rate of that model).
  double criticalRatio = 0.0;
  double successRate = 0.0;  ///< bootstrapped, of the accepted set (or of the full set)
  double bestNorm = 0.0;     ///< squared norm of the accepted integer solution
  int attempts = 0;          ///< ILS searches run
  std::int64_t nodes = 0;    ///< search nodes over all attempts
  /// Full-set ratio and success rate (diagnostics, also when a subset was fixed).
  double fullRatio = 0.0;
  double fullSuccessRate = 0.0;
  /// Reduced basis of the full set (empty if Q was not positive definite): the `start` of the
  /// next resolution of the same ambiguities.
  ReductionStart basis;
  int numFixed() const { return static_cast<int>(values.size()); }
};

/// Resolves float ambiguities â (cycles) with covariance Q. Never throws; `fixed` is false when
/// nothing passed validation or Q is not positive definite. `start`: see lambda().
AmbiguityFix resolveAmbiguities(const Eigen::VectorXd& afloat, const Eigen::MatrixXd& Q,
                                const AmbiguityResolutionOptions& options = {},
                                const ReductionStart* start = nullptr);

/// Whether an accepted solution passes the validation rule (exposed for tests and tools).
/// `criticalRatio`: the fixed-failure-rate critical value (FixedFailureRate; see
/// fixedFailureRateCriticalRatio).
bool passesValidation(double ratio, double successRate, const AmbiguityResolutionOptions& options,
                      double criticalRatio = 0.0);

/// Critical ratio of the fixed-failure-rate test for the reduced problem with conditional
/// variances `factor` (Q_ẑ = Lᵀ diag(d) L): the smallest ratio r such that draws with a wrong
/// best candidate and ratio ≥ r are at most `maxFailureRate` of all draws (1 when the draws fail
/// that rarely at any ratio; +infinity when no ratio is enough). Deterministic.
double fixedFailureRateCriticalRatio(const LtdlFactor& factor, const AmbiguityResolutionOptions& options);

}  // namespace gvins
