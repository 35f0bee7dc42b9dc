// Re-acquisition of the GNSS rows after the state drifted away from them (gnss_fusion.hpp step 4,
// docs/gnss_fusion.md "Re-acquisition"). Two situations start it, each `after` seconds long:
//   - every epoch's rows were gated out (the state drifted beyond what its covariance admits: a
//     MEMS IMU walking for 15 s without GNSS drifts by up to 10 m while its predicted σ says 2 m);
//   - no GNSS update was applied at all (an outage): the predicted covariance has grown, and the
//     normal gates alone could let a burst of faulted rows in together with the good ones.
// While it lasts an epoch's rows are admitted by two tests instead of the normal gates:
//   1. Widened innovation gate. The filter's own predicted innovation covariance S (from the
//      square-root information factor: h P hᵀ + J Σ_k Jᵀ + Σ_m) plus G Q(τ) Gᵀ, with G the rows'
//      coefficients of a common correction (range rows: antenna position and receiver clock;
//      rate rows: velocity and clock drift) and Q(τ) the growth of its uncertainty since the last
//      applied GNSS update, τ seconds ago, as an unmodelled acceleration a would make it:
//      σ_p = σ_c = a τ²/2 per axis, σ_v = σ_d = a τ. Each row alone: r² ≤ χ²₁(row_gate)·(S_ii + g Q gᵀ).
//   2. Consensus (RANSAC, Fischler & Bolles 1981), per group: minimal samples of the group's rows
//      fit the common correction; a row agrees when its residual about the correction is within
//      its measurement noise plus the states the correction leaves out (inter-system biases, wet
//      delay, ambiguities) at the row-gate quantile. A group is admitted only when more than half
//      of its rows, and at least one more than its unknowns, agree, and the agreeing rows pass the
//      widened joint χ² at `epoch_gate`; the other rows stay out. A few faulted satellites can
//      neither form a consensus of their own nor stay inside the majority's.
// The admitted rows are applied with the normal epoch gate: when it and every admitted row's
// normal gate pass, the state is back and re-acquisition ends (with a notice); else they are
// applied without the epoch gate (the widened joint χ² stands for it) and the next epoch is tested
// again. Rows of other kinds (SPP velocity triples) keep their normal row gate. Each admission
// gives a warning naming the satellites admitted and excluded, τ, the correction and the χ².
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "gvins/base/gnss_time.hpp"
#include "gvins/base/observation.hpp"

namespace gvins::fusion {

/// Group of a row in the consensus: its common correction's unknowns.
enum ReacquisitionGroup : int {
  kReacquireNone = -1,  ///< not re-admitted by consensus (normal row gate)
  kReacquireRange = 0,  ///< code, phase, differences: [δp (3), δc]
  kReacquireRate = 1,   ///< Doppler: [δv (3), δḋ]
};

/// The rows of an epoch as the re-acquisition tests see them (built by GnssFusion::apply).
struct ReacquisitionRows {
  Eigen::VectorXd residual;      ///< innovation of each row
  Eigen::MatrixXd G;             ///< n × 4: coefficients of the group's common correction
  std::vector<int> group;        ///< ReacquisitionGroup per row
  Eigen::VectorXd bandVariance;  ///< variance of each row about the common correction
  Eigen::MatrixXd S;             ///< n × n predicted innovation covariance (h P hᵀ + J Σ_k Jᵀ + Σ_m)
  std::vector<SatId> sats;       ///< satellite of each row (for the messages)
};

struct ReacquisitionGroupResult {
  int offered = 0;    ///< rows of the group with a finite residual
  int agreeing = 0;   ///< rows in the consensus
  int unknowns = 0;   ///< columns of the correction the group's rows touch
  bool admitted = false;
  Eigen::Vector4d correction = Eigen::Vector4d::Zero();  ///< least squares on the agreeing rows
  double chi2 = 0.0, threshold = 0.0;                    ///< widened joint χ² of the agreeing rows
};

struct ReacquisitionSelection {
  std::vector<bool> admitted;  ///< per row (rows of kReacquireNone: false, the caller gates them)
  std::array<ReacquisitionGroupResult, 2> groups;
  double tau = 0.0;            ///< s since the last applied update
  double sigmaP = 0.0, sigmaV = 0.0;  ///< the growth Q(τ): m (position, clock), m/s (velocity, drift)
};

/// One epoch through the re-acquisition gate (GnssFusion::apply): the rows' groups and τ in; the
/// tests, their input and whether the normal gates passed too out.
struct ReacquisitionEpoch {
  std::vector<int> groups;  ///< ReacquisitionGroup per row
  double tau = 0.0;
  ReacquisitionRows rows;
  ReacquisitionSelection selection;  ///< empty `admitted`: the tests did not run
  bool normal = true;
};

/// What the tests of an applied epoch admitted: consensus-group rows admitted and excluded, and
/// the satellites of the excluded rows (in row order, a satellite once).
struct ReacquisitionTally {
  int admitted = 0, excluded = 0;
  std::vector<SatId> excludedSats;
};
ReacquisitionTally tallyReacquisition(const ReacquisitionRows& rows, const ReacquisitionSelection& selection);

/// The widened gate and the consensus of an epoch's rows (tests 1 and 2 of the file comment).
/// rowQuantile: χ²₁ quantile of the row gate; epochGate: the probability of the joint test.
/// Deterministic (a fixed seed).
ReacquisitionSelection selectReacquisitionRows(const ReacquisitionRows& rows, double tau, double acceleration,
                                               double rowQuantile, double epochGate);
/// One line on the selection: τ, the growth, per group the agreeing rows, the correction, the χ²
/// and the satellites admitted and excluded.
std::string describeReacquisition(const ReacquisitionRows& rows, const ReacquisitionSelection& selection);

class GnssGateRecovery {
 public:
  /// `after` <= 0: never (always the normal gates). `acceleration`: a of Q(τ), m/s².
  GnssGateRecovery(double after = 2.0, double acceleration = 0.3) : after_(after), acceleration_(acceleration) {}

  /// Whether the epoch at t is tested by the re-acquisition gate (starts it when due).
  bool reacquiring(const GpsTime& t);
  /// τ: seconds since the last applied update (before any: since the rows were first gated out).
  double sinceUpdate(const GpsTime& t) const {
    if (lastUpdate_) return t - *lastUpdate_;
    return rejectedSince_ ? t - *rejectedSince_ : 0.0;
  }
  double acceleration() const { return acceleration_; }
  /// The outcome of the epoch's update. rows: how many were offered; applied: an update was
  /// applied; normal: it passed the normal gates (ends the re-acquisition); `selection`: the
  /// re-acquisition tests of the epoch and their input, if any (an admission is reported).
  /// Returns the tally of an admission (rows applied through the tests), zero otherwise.
  ReacquisitionTally outcome(const GpsTime& t, std::size_t rows, bool applied, bool normal,
               const ReacquisitionSelection* selection = nullptr, const ReacquisitionRows* input = nullptr);
  /// Forget the history (state reset).
  void reset() {
    rejectedSince_.reset();
    lastUpdate_.reset();
    active_ = false;
  }
  const std::vector<std::string>& warnings() const { return warnings_; }
  /// Re-acquisitions started. The rows admitted and excluded are not counted here: outcome()
  /// returns them per epoch (GnssFusion's epoch report, summed by the replay summary).
  int recoveries() const { return recoveries_; }

 private:
  double after_, acceleration_;
  std::optional<GpsTime> rejectedSince_, lastUpdate_, activeSince_;
  bool active_ = false;
  std::vector<std::string> warnings_;
  int recoveries_ = 0;
};

}  // namespace gvins::fusion
