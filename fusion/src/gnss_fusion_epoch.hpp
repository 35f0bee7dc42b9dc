// Internal to gvins_fusion: the working state of one GnssFusion::processEpoch call and the rows
// it stacks, shared by gnss_fusion.cpp (stages, gating and whitening) and gnss_fusion_rows.cpp
// (the rows of the tight stage).
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "gvins/fusion/gnss_fusion.hpp"

namespace gvins::fusion {

/// σ of the frame yaw's prior while it is a nuisance (GnssFusionConfig::frameStartAtRest): that
/// of a yaw uniform on the circle, π/√3 rad.
inline constexpr double kFrameYawPriorSigma = 1.8137993642342178;

/// The frame's yaw guess from motion: the heading of the SPP velocity `vSpp` minus that of the
/// IMU's velocity `vImu`, both in ENU as the frame currently turns W (rad, not wrapped).
inline double velocityHeadingDifference(const Eigen::Vector3d& vSpp, const Eigen::Vector3d& vImu) {
  return std::atan2(vSpp.y(), vSpp.x()) - std::atan2(vImu.y(), vImu.x());
}

/// The kinds of rows, counted per kind in GnssEpochReport.
enum GnssRowType : int { kPsr, kDopp, kDpsr, kDdcp, kVel, kFrame, kPhase };

/// The counter of a kind of row in the report.
inline GnssTypeCount& countOf(GnssEpochReport& r, int type) {
  switch (type) {
    case kPsr: return r.psr;
    case kDopp: return r.dopp;
    case kDpsr: return r.dpsr;
    case kDdcp: return r.ddcp;
    case kVel: return r.vel;
    case kPhase: return r.phase;
    default: return r.frame;
  }
}

/// The rows of an epoch with their measurement noise Σ_m: independent rows with their variance,
/// and groups of rows correlated among themselves with their joint covariance (the SPP position
/// and velocity triples, the DD phases). Σ_m is block diagonal in the order the rows were added.
struct GnssRowSet {
  std::vector<GnssRow> rows;
  std::vector<int> types;  ///< GnssRowType of each row
  /// vio+dopp+ppp: the ambiguity blocks the rows' `ambiguity` indices refer to, and their satellites.
  std::vector<sri::BlockId> ambiguityBlocks;
  std::vector<SatId> ambiguitySats;

  /// Appends a row independent of the others, with variance `variance`.
  void add(const GnssRow& r, int type, double variance) {
    rows.push_back(r);
    types.push_back(type);
    variances_.push_back(variance);
  }
  /// Appends rows correlated among themselves (and with no other row), with their covariance.
  void addCorrelated(const std::vector<GnssRow>& group, int type, const Eigen::MatrixXd& covariance) {
    groups_.emplace_back(rows.size(), covariance);
    for (const GnssRow& r : group) add(r, type, 0.0);
  }
  bool empty() const { return rows.empty(); }
  std::size_t size() const { return rows.size(); }
  /// Σ_m of all rows.
  Eigen::MatrixXd noise() const {
    const auto n = static_cast<Eigen::Index>(rows.size());
    Eigen::MatrixXd s = Eigen::MatrixXd::Zero(n, n);
    for (std::size_t i = 0; i < variances_.size(); ++i) s(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(i)) = variances_[i];
    for (const auto& [first, c] : groups_) {
      const auto o = static_cast<Eigen::Index>(first);
      s.block(o, o, c.rows(), c.cols()) = c;
    }
    return s;
  }

 private:
  std::vector<double> variances_;  // per row (0 in the groups)
  std::vector<std::pair<std::size_t, Eigen::MatrixXd>> groups_;  // first row, covariance
};

// Row producers (gnss_fusion_rows.cpp), each with its noise model.
/// The SPP position (ECEF) as three rows on p_N with its covariance, rotated to the local ENU
/// frame of the anchor, plus 0.5 m (σ per axis) for the models' differences (kFrame rows).
void addPositionRows(const GnssAnchor& anchor, const Eigen::Vector3d& position, const Eigen::Matrix3d& covariance,
                     const AntennaKinematics& k, GnssRowSet& rows);
/// The SPP Doppler velocity as three rows on v_N with its covariance in ENU plus 0.05 m/s (σ per
/// axis); `lever`: whether the rows keep their lever-arm columns.
void addVelocityRows(const GnssAnchor& anchor, const VelocitySolution& velocity, const AntennaKinematics& k, int type,
                     bool lever, GnssRowSet& rows);
/// Doppler rows of the satellites with a Doppler (variance: the signal's model); the lever-arm
/// columns only when the rotation excites the lever arm.
void addDopplerRows(const std::vector<SatelliteModel>& models, const AntennaKinematics& k, const Eigen::VectorXd& clk,
                    bool excited, GnssRowSet& rows);
/// Pseudorange rows of the satellites with an estimated clock (variance: the code model); those
/// with a known C/N0 below `cn0Mask` (dB-Hz, 0: off) are dropped and counted in `masked`.
void addPseudorangeRows(const std::vector<SatelliteModel>& models, const AntennaKinematics& k,
                        const Eigen::VectorXd& clk, double cn0Mask, GnssRowSet& rows, int& masked);

/// One rover epoch in GnssFusion::processEpoch.
template <typename Scalar>
struct GnssFusion<Scalar>::Epoch {
  Epoch(const ObsEpoch& raw, const ObsEpoch& smoothed, const EphemerisStore& navigation, GnssEpochReport& report)
      : roverRaw(raw), rover(smoothed), nav(navigation), rep(report), states(navigation, smoothed.time) {}
  const ObsEpoch& roverRaw;  ///< after the Doppler check
  const ObsEpoch& rover;     ///< with the carrier-smoothed codes where configured
  const EphemerisStore& nav;
  GnssEpochReport& rep;
  /// Satellite states of this epoch, computed once for the RTK module's differences and the
  /// fusion's satellite models.
  TransmitStates states;
  std::optional<SppSolution> spp;  ///< solved where used (sppOf)
  /// Ddcp runs the whole RTK module for its fixed ambiguities; dpsr needs only the single
  /// differences (RtkSolver::differences: no float filter, no ambiguity resolution).
  bool fullRtk = false;
  bool rtkProcessed = false;  ///< the RTK module ran on this epoch
  /// Held and nothing new: a new base epoch within rtk_revalidate_interval of the last run takes
  /// the held fix too, unless its DD phases differ from that run's (then the module runs there).
  bool rtkDeferred = false;
  std::optional<double> baseAge;
  /// Ddcp: the fixed DD phases of rtk_'s differences given as rows (their kDdcp rows, in order).
  std::vector<DoubleDifference> ddcpPhases;
  GpsTime tMeas;          ///< the tag minus the receiver clock
  std::int64_t t_ns = 0;  ///< tMeas, at most the newest state's time
};

}  // namespace gvins::fusion
