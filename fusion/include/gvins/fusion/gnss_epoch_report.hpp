// What GnssFusion::processEpoch (gnss_fusion.hpp) reports for one rover epoch: the stage, the rows
// used and gated out per kind, the antenna after the update, warnings; the replay's outputs
// (replay_pipeline.hpp) are written from it.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "gvins/base/enum_names.hpp"
#include "gvins/base/geodetic.hpp"
#include "gvins/base/gnss_time.hpp"
#include "gvins/base/satellite.hpp"
#include "gvins/fusion/gnss_ins_alignment.hpp"

namespace gvins::fusion {

enum class GnssFusionStage : std::uint8_t {
  kWaitingVio,    ///< estimator not initialised
  kWaitingFix,    ///< no SPP fix with enough speed yet
  kFrameInit,     ///< frame block being estimated from SPP
  kTight,         ///< frame converged, raw measurements used
};
/// Names of the stages (gnss_epochs.csv, docs/replay.md).
inline constexpr EnumName<GnssFusionStage> kGnssFusionStageNames[] = {{GnssFusionStage::kWaitingVio, "waiting-vio"},
                                                                      {GnssFusionStage::kWaitingFix, "waiting-fix"},
                                                                      {GnssFusionStage::kFrameInit, "frame-init"},
                                                                      {GnssFusionStage::kTight, "tight"}};
inline const char* toString(GnssFusionStage s) { return enumName(kGnssFusionStageNames, s); }

struct GnssTypeCount {
  int used = 0;
  int rejected = 0;  ///< gated out (row or epoch test)
  int masked = 0;    ///< code rows dropped below GnssFusionConfig::cn0MaskDbHz (psr, dpsr)
};

/// The re-acquisition gate in this epoch (gnss_gate_recovery.hpp).
struct GnssReacquisitionReport {
  bool started = false;  ///< a re-acquisition began with this epoch
  int admitted = 0;      ///< rows applied through the widened gate and the consensus
  int excluded = 0;      ///< rows of the consensus groups kept out in an epoch that was applied
  std::vector<SatId> excludedSats;  ///< their satellites
};

struct GnssEpochReport {
  GpsTime time;                 ///< rover time tag
  std::int64_t t_ns = 0;        ///< measurement time used (tag − receiver clock)
  GnssFusionStage stage = GnssFusionStage::kWaitingVio;
  GnssTypeCount psr, dopp, dpsr, ddcp, vel, frame;
  GnssTypeCount phase;          ///< undifferenced carrier phase (vio+dopp+ppp)
  int ambiguities = 0;          ///< float ambiguity states after the epoch (vio+dopp+ppp)
  int recordChanges = 0;        ///< broadcast record changes carried over to ambiguities (vio+dopp+ppp)
  bool updated = false;         ///< at least one update applied
  bool clocksInitialized = false;  ///< this epoch
  bool reset = false;           ///< outage reset this epoch, or the estimator started a new state
  bool frameRestart = false;    ///< the frame initialisation dropped the estimator's state (not linear)
  GnssReacquisitionReport reacquisition;
  bool rtkFixed = false;
  std::optional<Eigen::Vector3d> antennaEcef;  ///< after the update (at t_ns)
  std::optional<Eigen::Vector3d> antennaVelocityEcef;
  Geodetic antennaGeodetic;
  double chi2 = 0.0;
  int dof = 0;
  double elapsedMicroseconds = 0.0;
  std::vector<std::string> warnings;  ///< new this epoch (Doppler check of the rover and the base)
  /// Before the estimator is initialised (GnssFusionConfig::insStart): where the GNSS/INS
  /// alignment stands (kAligned: this epoch started the estimator).
  std::optional<GnssInsStatus> insStart;
};

}  // namespace gvins::fusion
