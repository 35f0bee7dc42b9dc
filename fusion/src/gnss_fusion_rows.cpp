// The rows of GnssFusion's stages (gnss_fusion.hpp, steps 2 and 4): one producer per kind of
// measurement, each with its noise model, and the tight stage that stacks them.
#include <algorithm>
#include <cmath>

#include "gnss_fusion_epoch.hpp"
#include "gvins/base/constants.hpp"
#include "gvins/gnss/phase_windup.hpp"

namespace gvins::fusion {
namespace {
constexpr double kC = constants::kSpeedOfLight;
}  // namespace

void addPositionRows(const GnssAnchor& anchor, const Eigen::Vector3d& position, const Eigen::Matrix3d& covariance,
                     const AntennaKinematics& k, GnssRowSet& rows) {
  const Eigen::Matrix3d R_NE = anchor.R_EN.transpose();
  const Eigen::Vector3d pN = R_NE * (position - anchor.ecef);
  std::vector<GnssRow> group;
  for (int a = 0; a < 3; ++a) group.push_back(positionRow(pN, a, k));
  const Eigen::Matrix3d c = R_NE * covariance * R_NE.transpose() + 0.25 * Eigen::Matrix3d::Identity();
  rows.addCorrelated(group, kFrame, c);
}

void addVelocityRows(const GnssAnchor& anchor, const VelocitySolution& velocity, const AntennaKinematics& k, int type,
                     bool lever, GnssRowSet& rows) {
  const Eigen::Matrix3d R_NE = anchor.R_EN.transpose();
  const Eigen::Vector3d vN = R_NE * velocity.velocity;
  std::vector<GnssRow> group;
  for (int a = 0; a < 3; ++a) {
    GnssRow r = velocityRow(vN, a, k);
    if (!lever) r.H_lever.setZero();
    group.push_back(r);
  }
  const Eigen::Matrix3d c = R_NE * velocity.covariance * R_NE.transpose() + 0.0025 * Eigen::Matrix3d::Identity();
  rows.addCorrelated(group, type, c);
}

void addDopplerRows(const std::vector<SatelliteModel>& models, const AntennaKinematics& k, const Eigen::VectorXd& clk,
                    bool excited, GnssRowSet& rows) {
  const Eigen::Index drift = clk.size() - 1;  // [c·dt per clock system..., c·ḋt]
  for (const SatelliteModel& m : models) {
    if (!m.hasDoppler) continue;
    GnssRow r = dopplerRow(m, k, clk[drift]);
    if (!excited) r.H_lever.setZero();
    rows.add(r, kDopp, r.variance);
  }
}

void addPseudorangeRows(const std::vector<SatelliteModel>& models, const AntennaKinematics& k,
                        const Eigen::VectorXd& clk, double cn0Mask, GnssRowSet& rows, int& masked) {
  for (const SatelliteModel& m : models) {
    if (m.clock < 0) continue;
    if (m.cn0 > 0.0 && m.cn0 < cn0Mask) {
      ++masked;
      continue;
    }
    GnssRow r = pseudorangeRow(m, k, clk[m.clock]);
    r.H_lever.setZero();
    rows.add(r, kPsr, r.variance);
  }
}

template <typename Scalar>
bool GnssFusion<Scalar>::prepareStates(vio::EstimatorBackend<Scalar>& est, Epoch& e,
                                       std::vector<SatelliteModel>& models, const AntennaKinematics& k) {
  const bool needClocks = config_.usesDoppler();
  if (needClocks && !clocks_.valid()) {
    if (!initClocks(est, models, k, e.tMeas)) return false;
    e.rep.clocksInitialized = true;
    for (SatelliteModel& m : models) m.clock = clockIndex(m.sat);
  }
  if (clocks_.valid()) clocks_.propagate(est, e.tMeas, config_);
  if (clocks_.valid() && !e.rep.clocksInitialized) {  // systems whose ephemerides came later
    addLateClockSystems(est, models, k, e.tMeas);
    for (SatelliteModel& m : models) m.clock = clockIndex(m.sat);
  }
  if (clocks_.valid() && config_.zwdState()) {
    if (!zwd_.valid()) zwd_.create(est, e.tMeas, config_.zwdSigma);
    zwd_.propagate(est, e.tMeas, config_.zwdRandomWalk);
    const double zwd = zwd_.value(est);
    for (SatelliteModel& m : models) m.troposphere += m.mapWet * zwd;
  }
  return true;
}

template <typename Scalar>
GnssAmbiguityArc& GnssFusion<Scalar>::newAmbiguity(vio::EstimatorBackend<Scalar>& est, const SatelliteModel& m,
                                                   const GpsTime& arcStart) {
  // Centred on phase minus code (code model: + c·group delay), which differ by the ambiguity
  // plus the code error. The arc may be older than the state (epochs before the VIO or the clocks
  // were ready, a restart after rejections): its carrier-smoothed code carries those epochs'
  // codes, weighted as the code rows are (each epoch as one measurement: σ/sqrt(n)) except for
  // the orbit/clock error, a bias per satellite that no averaging reduces; a new arc starts from
  // the raw code with a loose prior.
  double code = m.pseudorange, sigma = config_.ambiguitySigma;
  const SatObs* so = arcSmoothed_.find(m.sat);
  const SignalObs* s1 = so ? so->find(m.code) : nullptr;
  const SignalObs* s2 = so ? so->find(m.code2) : nullptr;
  if (arcs_->samples(m.sat) > 1 && s1 && s2 && s1->hasCode() && s2->hasCode()) {
    code = m.ifA1 * s1->pseudorange + m.ifA2 * s2->pseudorange;
    const double nf = arcs_->noiseFactor(m.sat);
    sigma = std::sqrt((m.codeVariance - m.ephemerisVariance) * nf * nf + m.ephemerisVariance);
  }
  return ambiguities_.add(est, m.sat, m.carrierRange - (code - kC * m.groupDelay), sigma, arcStart);
}

template <typename Scalar>
void GnssFusion<Scalar>::addPhaseRows(vio::EstimatorBackend<Scalar>& est, Epoch& e,
                                      const std::vector<SatelliteModel>& models, const AntennaKinematics& k,
                                      const Eigen::VectorXd& clk, GnssRowSet& rows) {
  const ObsEpoch& rover = e.rover;
  // Ambiguities of satellites on broadcast orbits and clocks follow their drifting errors.
  std::vector<SatId> broadcast;
  for (const SatelliteModel& m : models)
    if (!m.precise && !m.ssr) broadcast.push_back(m.sat);
  ambiguities_.propagate(est, broadcast, e.tMeas, config_.broadcastAmbiguityRandomWalk);
  // Satellites with a state first, then the others highest first (max_ambiguities).
  std::vector<const SatelliteModel*> order;
  for (const SatelliteModel& m : models) order.push_back(&m);
  std::stable_sort(order.begin(), order.end(), [&](const SatelliteModel* a, const SatelliteModel* b) {
    const bool ha = ambiguities_.contains(a->sat), hb = ambiguities_.contains(b->sat);
    if (ha != hb) return ha;
    return a->azel.elevation > b->azel.elevation;
  });
  for (const SatelliteModel* mp : order) {
    const SatelliteModel& m = *mp;
    if (!m.hasCarrier || m.clock < 0 || arcs_->samples(m.sat) == 0) continue;
    const GpsTime start = rover.time - arcs_->arcLength(m.sat);
    GnssAmbiguityArc* arc = ambiguities_.arc(m.sat);
    if (arc && std::abs(arc->start - start) > 1e-3) {
      ambiguities_.drop(est, m.sat);  // new arc: cycle slip, gap or signal change
      arc = nullptr;
    }
    if (!arc) {
      if (config_.maxAmbiguities > 0 && static_cast<int>(ambiguities_.size()) >= config_.maxAmbiguities) continue;
      arc = &newAmbiguity(est, m, start);
    }
    arc->lastRow = rover.time;
    const double nAmb = ambiguities_.value(est, m.sat);
    SatelliteModel mc = m;
    if (config_.broadcastRecordChanges && !m.precise && !m.ssr) {
      BroadcastRecordContinuity& r = arc->records;
      if (r.update(e.nav, m.sat, rover.time - m.pseudorange / kC, m.transmitTime, k.x_E).changed) ++e.rep.recordChanges;
      mc.carrierRange += r.shift();
    }
    if (config_.phaseWindup) {
      const double w = continueWindup(m.windup, arc->windup);
      arc->windup = w;
      mc.carrierRange -= m.windupWavelength * w;
    }
    GnssRow r = carrierPhaseRow(mc, k, clk[m.clock], nAmb);
    r.H_lever.setZero();
    r.ambiguity = static_cast<int>(rows.ambiguityBlocks.size());
    rows.ambiguityBlocks.push_back(ambiguities_.block(m.sat));
    rows.ambiguitySats.push_back(m.sat);
    rows.add(r, kPhase, r.variance);
  }
}

template <typename Scalar>
void GnssFusion<Scalar>::addDifferenceRows(Epoch& e, const AntennaKinematics& k, const Eigen::VectorXd& clk,
                                           GnssRowSet& rows) {
  if (rtk_ && !e.fullRtk) e.baseAge = rtk_->differences(e.rover, k.x_E, &e.states);
  if (e.fullRtk && !e.rtkProcessed) {
    int heldFixed = 0;
    e.baseAge = rtk_->differencesWithHeldFix(e.roverRaw, k.x_E, heldFixed, &e.states);
    if (e.rtkDeferred && !rtk_->phasePairsAsProcessed()) runRtk(e);
  }
  // The code rows of dpsr and ddcp alike: the single differences of the carrier-smoothed codes
  // where configured (Ddcp's RTK module keeps the raw ones; codeRtk_ forms the smoothed ones).
  std::optional<double> codeAge = e.baseAge;
  if (codeRtk_) codeAge = codeRtk_->differences(e.rover, k.x_E, &e.states);
  if (codeAge && config_.usesDifferences() && *codeAge <= config_.maxBaseAge) {
    addSdCodeRows(e, (codeRtk_ ? codeRtk_ : rtk_)->measurements(), k, clk, rows);
  }
  if (config_.mode != GnssFusionMode::kDoppDdcp || !e.baseAge || *e.baseAge > config_.maxBaseAge) return;
  // The DD phases with the integers of a validated fix, as many and of as many satellites as a
  // fix of the RTK module needs (applicableFixedPhases); fewer are no fix.
  const DdEpoch& dd = rtk_->measurements();
  e.ddcpPhases = applicableFixedPhases(dd, rtk_->config());
  if (e.ddcpPhases.empty()) return;
  std::vector<GnssRow> group;
  for (const DoubleDifference& d : e.ddcpPhases) group.push_back(ddPhaseRow(dd, d, k));
  rows.addCorrelated(group, kDdcp, ddCovariance(dd, e.ddcpPhases, true));
}

template <typename Scalar>
void GnssFusion<Scalar>::addSdCodeRows(Epoch& e, const DdEpoch& dd, const AntennaKinematics& k,
                                       const Eigen::VectorXd& clk, GnssRowSet& rows) {
  const int n = static_cast<int>(clocks_.systems().size());
  // Base clock per system from the base code OMCs, continued over the signals common with the
  // previous epoch, so that satellites joining or leaving do not move it (gnss_base_clock.hpp).
  std::vector<GnssBaseClock::Residual> omc;
  for (const SingleDifference& sd : dd.sd) {
    const int c = clockIndex(sd.sat);
    if (c < 0 || !sd.hasCode) continue;
    omc.push_back({c, static_cast<std::int64_t>(satIndex(sd.sat)) * 65536 + sd.code.band * 256 + sd.code.attr,
                   sd.baseCodeOmc});
  }
  const std::vector<double> baseClock = baseClock_.update(omc, n);
  for (const SingleDifference& sd : dd.sd) {
    const int c = clockIndex(sd.sat);
    if (c < 0 || !sd.hasCode || sd.elevation < config_.elevationMaskDeg * constants::kDegToRad) continue;
    // cn0_mask_dbhz: either receiver's C/N0 (where known) below the mask.
    if ((sd.snr > 0.0 && sd.snr < config_.cn0MaskDbHz) || (sd.baseSnr > 0.0 && sd.baseSnr < config_.cn0MaskDbHz)) {
      ++e.rep.dpsr.masked;
      continue;
    }
    const double cb = baseClock[static_cast<std::size_t>(c)];
    GnssRow r = sdPseudorangeRow(sd, k, clk[c], cb);
    r.clockBias = c;
    rows.add(r, kDpsr, r.variance);
  }
}

template <typename Scalar>
void GnssFusion<Scalar>::applyRows(vio::EstimatorBackend<Scalar>& est, GnssEpochReport& rep,
                                   const AntennaKinematics& k, GnssRowSet& rows, std::vector<bool>& acc) {
  // Re-acquisition (gnss_gate_recovery.hpp): code, phase and differences agree on a position and
  // clock shift, Dopplers on a velocity and drift shift; SPP velocity triples keep their gate.
  ReacquisitionEpoch re;
  const int recoveries = gateRecovery_.recoveries();
  const bool reacquiring = gateRecovery_.reacquiring(rep.time);
  rep.reacquisition.started = gateRecovery_.recoveries() > recoveries;
  if (reacquiring) {
    re.tau = gateRecovery_.sinceUpdate(rep.time);
    for (const int type : rows.types) {
      re.groups.push_back(type == kDopp ? kReacquireRate : type == kVel || type == kFrame ? kReacquireNone : kReacquireRange);
    }
  }
  const auto u = apply(est, rows.rows, rows.noise(), k.integrationCovariance, acc, true, rows.ambiguityBlocks,
                       reacquiring ? &re : nullptr);
  const bool tested = !re.selection.admitted.empty();
  ReacquisitionTally tally = gateRecovery_.outcome(rep.time, rows.size(), u.applied, re.normal,
                                                   tested ? &re.selection : nullptr, tested ? &re.rows : nullptr);
  rep.reacquisition.admitted = tally.admitted;
  rep.reacquisition.excluded = tally.excluded;
  rep.reacquisition.excludedSats = std::move(tally.excludedSats);
  rep.chi2 = static_cast<double>(u.chi2);
  rep.dof = u.dof;
  rep.updated = u.applied;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    GnssTypeCount& c = countOf(rep, rows.types[i]);
    (acc[i] ? c.used : c.rejected)++;
    if (rows.types[i] != kPhase) continue;
    // A phase row gated out again and again: the ambiguity no longer fits (undetected slip,
    // broadcast orbit/clock change); it restarts from phase minus code.
    const SatId sat = rows.ambiguitySats[static_cast<std::size_t>(rows.rows[i].ambiguity)];
    GnssAmbiguityArc& a = *ambiguities_.arc(sat);
    a.rejections = acc[i] ? 0 : a.rejections + 1;
    if (a.rejections >= config_.ambiguityResetRejections) ambiguities_.drop(est, sat);
  }
}

template <typename Scalar>
bool GnssFusion<Scalar>::tightUpdate(vio::EstimatorBackend<Scalar>& est, Epoch& e, const GnssStateValues& s,
                                     const AntennaKinematics& k) {
  const SppSolution* sppVel = config_.mode == GnssFusionMode::kGpsVel ? &sppOf(e) : nullptr;
  std::vector<SatelliteModel> models = satelliteModels(e.rover, e.nav, k.x_E, &e.states);
  if (!prepareStates(est, e, models, k)) return false;
  Eigen::VectorXd clk;
  if (clocks_.valid()) clk = clocks_.values(est);
  const bool excited = config_.calibrateLeverArm && (s.omegaMeasured - s.newest.bg).norm() >= config_.minRotationRate;
  GnssRowSet rows;
  if (config_.usesDoppler()) addDopplerRows(models, k, clk, excited, rows);
  if (config_.usesPseudorange()) addPseudorangeRows(models, k, clk, config_.cn0MaskDbHz, rows, e.rep.psr.masked);
  if (sppVel && sppVel->velocity.valid) addVelocityRows(anchor_, sppVel->velocity, k, kVel, false, rows);
  if (config_.mode == GnssFusionMode::kDoppPpp && clocks_.valid()) addPhaseRows(est, e, models, k, clk, rows);
  addDifferenceRows(e, k, clk, rows);
  std::vector<bool> acc;
  if (!rows.empty()) applyRows(est, e.rep, k, rows, acc);
  // Fixed: the DD phases of a validated fix were applied, as many and spanning as many
  // satellites as a fix needs (applicableFixedPhases); fewer left by the row gate are no fix.
  std::vector<DoubleDifference> applied;
  for (std::size_t i = 0, j = 0; i < acc.size(); ++i) {
    if (rows.types[i] != kDdcp) continue;
    if (acc[i]) applied.push_back(e.ddcpPhases[j]);
    ++j;
  }
  e.rep.rtkFixed = config_.mode == GnssFusionMode::kDoppDdcp && e.rep.updated &&
                   isFixSet(rtk_->measurements(), applied, rtk_->config());
  // Ambiguities of satellites without a phase row for a while (set, masked, lost).
  ambiguities_.dropStale(est, e.rover.time, 10.0);
  e.rep.ambiguities = static_cast<int>(ambiguities_.size());
  return true;
}

// (The class is declared `extern template` in gnss_fusion.hpp: every member defined here is
// instantiated explicitly.)
#define GVINS_INSTANTIATE(S)                                                                                        \
  template bool GnssFusion<S>::prepareStates(vio::EstimatorBackend<S>&, Epoch&, std::vector<SatelliteModel>&,       \
                                             const AntennaKinematics&);                                             \
  template GnssAmbiguityArc& GnssFusion<S>::newAmbiguity(vio::EstimatorBackend<S>&, const SatelliteModel&,          \
                                                         const GpsTime&);                                           \
  template void GnssFusion<S>::addPhaseRows(vio::EstimatorBackend<S>&, Epoch&, const std::vector<SatelliteModel>&,  \
                                            const AntennaKinematics&, const Eigen::VectorXd&, GnssRowSet&);         \
  template void GnssFusion<S>::addDifferenceRows(Epoch&, const AntennaKinematics&, const Eigen::VectorXd&,          \
                                                 GnssRowSet&);                                                      \
  template void GnssFusion<S>::addSdCodeRows(Epoch&, const DdEpoch&, const AntennaKinematics&,                      \
                                             const Eigen::VectorXd&, GnssRowSet&);                                  \
  template void GnssFusion<S>::applyRows(vio::EstimatorBackend<S>&, GnssEpochReport&, const AntennaKinematics&,     \
                                         GnssRowSet&, std::vector<bool>&);                                          \
  template bool GnssFusion<S>::tightUpdate(vio::EstimatorBackend<S>&, Epoch&, const GnssStateValues&,               \
                                           const AntennaKinematics&);
GVINS_INSTANTIATE(float)
GVINS_INSTANTIATE(double)
#undef GVINS_INSTANTIATE

}  // namespace gvins::fusion
