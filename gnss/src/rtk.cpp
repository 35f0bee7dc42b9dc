#include "gvins/gnss/rtk.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <set>
#include <stdexcept>
#include <unordered_map>

#include <Eigen/Cholesky>

#include "gvins/base/geodetic.hpp"
#include "gvins/base/local_frame.hpp"
#include "gvins/gnss/ambiguity_resolution.hpp"

namespace gvins {

using Filter = sri::SriFilter<double>;
using Meas = sri::Measurement<double>;

const char* toString(RtkIssue i) {
  switch (i) {
    case RtkIssue::None: return "none";
    case RtkIssue::NoBasePosition: return "base position unknown";
    case RtkIssue::NoBaseData: return "no base data";
    case RtkIssue::BaseTooOld: return "base data too old";
    case RtkIssue::NoCommonSatellites: return "fewer than 4 common satellites";
    case RtkIssue::FilterReset: return "float diverged from SPP (reset)";
    case RtkIssue::Undetermined: return "float position not determined";
  }
  return "?";
}

const char* toString(ArStatus s) {
  switch (s) {
    case ArStatus::Off: return "off";
    case ArStatus::TooFewAmbiguities: return "too few ambiguities";
    case ArStatus::NotValidated: return "validation failed (ratio below its critical value)";
    case ArStatus::Rejected: return "fix rejected by residual check";
    case ArStatus::Imprecise: return "fix leaves the position imprecise";
    case ArStatus::Inconsistent: return "fix inconsistent with the float position";
    case ArStatus::Unconfirmed: return "marginal first fix awaiting confirmation";
    case ArStatus::Fixed: return "fixed";
    case ArStatus::PartialFixed: return "partially fixed";
  }
  return "?";
}

PositionSolution RtkSolution::toPositionSolution() const {
  PositionSolution p;
  p.time = time;
  p.quality = quality;
  p.position = position;
  p.positionCovariance = positionCovariance;
  p.numSatellites = numSatellites;
  p.age = age;
  p.ratio = ratio;
  if (velocity) {
    p.velocity = *velocity;
    p.velocityCovariance = velocityCovariance;
  }
  return p;
}

RtkSolver::RtkSolver(const EphemerisStore& nav, RtkConfig config, SppConfig spp)
    : nav_(nav),
      cfg_(std::move(config)),
      spp_(nav, std::move(spp)),
      base_(nav, cfg_),
      roverSlips_(cfg_.slip),
      builder_(nav, cfg_) {}

void RtkSolver::setBasePosition(const Eigen::Vector3d& arp) {
  const auto old = base_.position();
  base_.setPosition(arp);
  if (old && (*old - arp).norm() >= 1e-3) reset();
}

void RtkSolver::setBaseGlonassChannels(const GlonassChannels& channels) { base_.setGlonassChannels(channels); }

void RtkSolver::setRoverGlonassChannels(const GlonassChannels& channels) {
  roverChannels_ = channels;
  spp_.setGlonassChannels(channels);
  builder_.setGlonassChannels(channels);
}

void RtkSolver::setPhaseAlignment(const PhaseAlignments& rover, const PhaseAlignments& base) {
  builder_.setPhaseAlignment(rover, base);
}

void RtkSolver::setRoverInitialPosition(const Eigen::Vector3d& ecef) { spp_.setInitialPosition(ecef); }

void RtkSolver::setTimeDirection(TimeDirection d) {
  direction_ = d;
  base_.setDirection(d);
  roverSlips_.setDirection(d);
  roverDoppler_.setDirection(d);
  slipEpoch_.reset();
  reset();
}

void RtkSolver::addBaseEpoch(const ObsEpoch& epoch) { base_.addEpoch(epoch); }

void RtkSolver::reset() {
  filter_ = Filter();
  held_.clear();
  amb_.clear();
  iono_.clear();
  processedPairs_.clear();
  lastProcess_.reset();
  initialized_ = false;
  consecutiveFixes_ = 0;
  lastVelocity_.reset();
  pos_ = vel_ = sri::BlockId{};
  arPairs_.clear();
  arBasis_ = {};
}

Eigen::Vector3d RtkSolver::positionEstimate() const { return filter_.estimate(pos_).vector.head<3>(); }

double RtkSolver::ambiguityEstimate(const SingleDifference& sd) const {
  const auto it = amb_.find(key(sd.sat, sd.code));
  return it == amb_.end() ? 0.0 : filter_.estimate(it->second.id).vector[0];
}

void RtkSolver::initialize(const Eigen::Vector3d& x, double sigma, const SppSolution& spp) {
  reset();
  pos_ = filter_.addBlock(sri::BlockSpec::vector("position", 3), sri::BlockEstimate<double>::fromVector(x),
                          sri::Prior<double>::stdDev(3, sigma));
  if (cfg_.mode == RtkMode::Kinematic && cfg_.dynamics == RtkDynamics::ConstantVelocity) {
    Eigen::Vector3d v = Eigen::Vector3d::Zero();
    double sv = 30.0;
    if (spp.velocity.valid) {
      v = spp.velocity.velocity;
      sv = 1.0;
    }
    vel_ = filter_.addBlock(sri::BlockSpec::vector("velocity", 3), sri::BlockEstimate<double>::fromVector(v),
                            sri::Prior<double>::stdDev(3, sv));
  }
  initialized_ = true;
}

void RtkSolver::timeUpdate(double dt, const SppSolution& spp) {
  // dt: signed (negative backward); the process noise grows with the elapsed |dt| either way.
  if (cfg_.mode == RtkMode::Static) return;
  const double adt = std::abs(dt);
  const Eigen::Vector3d x = positionEstimate();
  const std::optional<Eigen::Vector3d> v =
      spp.velocity.valid ? std::optional<Eigen::Vector3d>(spp.velocity.velocity) : std::nullopt;
  if (cfg_.dynamics == RtkDynamics::RandomWalk) {
    Eigen::Vector3d delta = Eigen::Vector3d::Zero();
    Eigen::Matrix3d Q;
    if (cfg_.dopplerAided && v) {
      // Trapezoid of the Doppler velocities at both ends of the interval.
      delta = lastVelocity_ ? Eigen::Vector3d(0.5 * (*lastVelocity_ + *v) * dt) : Eigen::Vector3d(*v * dt);
      Q = cfg_.dopplerAidedSigma * cfg_.dopplerAidedSigma * adt * Eigen::Matrix3d::Identity() +
          dt * dt * spp.velocity.covariance;
    } else {
      Q = cfg_.randomWalkSigma * cfg_.randomWalkSigma * adt * Eigen::Matrix3d::Identity();
    }
    Q += 1e-10 * Eigen::Matrix3d::Identity();
    sri::Propagation<double> p;
    p.addNewBlock(sri::BlockSpec::vector("position", 3), sri::BlockEstimate<double>::fromVector(x + delta));
    p.setTransition(pos_, Eigen::Matrix3d::Identity());
    p.setNoiseCovariance(Q);
    p.marginalizeAfter(pos_);
    pos_ = filter_.propagate(p).front();
  } else {
    const Eigen::Vector3d vel = filter_.estimate(vel_).vector.head<3>();
    const Geodetic g = ecefToGeodetic(x);
    const Eigen::Matrix3d Ren = ecefToEnuRotation(g.lat, g.lon);
    Eigen::Vector3d q(cfg_.accelerationSigmaHorizontal, cfg_.accelerationSigmaHorizontal, cfg_.accelerationSigmaVertical);
    q = q.cwiseProduct(q);
    const Eigen::Matrix3d Qa = Ren.transpose() * q.asDiagonal() * Ren + 1e-8 * Eigen::Matrix3d::Identity();
    Eigen::MatrixXd Q(6, 6);
    // Integrated white acceleration over the interval; backward the position and velocity noises
    // are anti-correlated (cross term dt·|dt|/2).
    Q << adt * adt * adt / 3.0 * Qa, dt * adt / 2.0 * Qa, dt * adt / 2.0 * Qa, adt * Qa;
    Eigen::MatrixXd phiP = Eigen::MatrixXd::Zero(6, 3), phiV = Eigen::MatrixXd::Zero(6, 3);
    phiP.topRows(3).setIdentity();
    phiV.topRows(3) = dt * Eigen::Matrix3d::Identity();
    phiV.bottomRows(3).setIdentity();
    sri::Propagation<double> p;
    p.addNewBlock(sri::BlockSpec::vector("position", 3), sri::BlockEstimate<double>::fromVector(x + vel * dt));
    p.addNewBlock(sri::BlockSpec::vector("velocity", 3), sri::BlockEstimate<double>::fromVector(vel));
    p.setTransition(pos_, phiP);
    p.setTransition(vel_, phiV);
    p.setNoiseCovariance(Q);
    p.marginalizeAfter(pos_);
    p.marginalizeAfter(vel_);
    const auto ids = filter_.propagate(p);
    pos_ = ids[0];
    vel_ = ids[1];
    if (cfg_.dopplerAided && v) {
      Meas m(3);
      m.jacobian(vel_, 3).setIdentity();
      m.residual() = *v - vel;
      m.whitenCovariance(4.0 * spp.velocity.covariance + 1e-6 * Eigen::Matrix3d::Identity());
      filter_.update(m);
      filter_.correct();
    }
  }
}

void RtkSolver::dropAmbiguity(std::uint32_t k) {
  const auto it = amb_.find(k);
  if (it == amb_.end()) return;
  filter_.marginalize(it->second.id);
  amb_.erase(it);
}

void RtkSolver::manageAmbiguities(const Eigen::Vector3d& x0, RtkSolution& sol) {
  std::vector<char> inPhase(dd_.sd.size(), 0);
  for (const DoubleDifference& d : dd_.phase) {
    inPhase[static_cast<std::size_t>(d.reference)] = 1;
    inPhase[static_cast<std::size_t>(d.satellite)] = 1;
  }
  bool rebuild = false;
  for (std::size_t i = 0; i < dd_.sd.size(); ++i) {
    if (!inPhase[i]) continue;
    SingleDifference& sd = dd_.sd[i];
    const std::uint32_t k = key(sd.sat, sd.code);
    const auto it = amb_.find(k);
    if (it != amb_.end()) {
      // Keyed by the rover signal: a change of the base signal (another tracking mode of the
      // band) is a new arc too.
      if (it->second.roverArc == sd.roverArc && it->second.baseArc == sd.baseArc &&
          it->second.baseCode == sd.baseCode && !forced_.count(k)) {
        it->second.lastSeen = dd_.time;
        continue;
      }
      // New arc at either receiver (slip, loss of lock, gap) or a post-fit outlier: the
      // ambiguity is not kept.
      dropAmbiguity(k);
      if (!forced_.count(k)) ++counters_.slipResets;
    }
    if (!sd.hasCode) {
      // Without a code the new ambiguity cannot be initialised (the SD clock is unknown).
      sd.hasPhase = false;
      rebuild = true;
      continue;
    }
    const double n0 = (sdPhaseResidual(sd, x0) - sdCodeResidual(sd, x0)) / sd.wavelength;
    const double sigma = cfg_.ambiguityInitialSigma / sd.wavelength;
    Ambiguity a;
    a.id = filter_.addBlock(sri::BlockSpec::vector("ambiguity", 1),
                            sri::BlockEstimate<double>::fromVector(Eigen::VectorXd::Constant(1, n0)),
                            sri::Prior<double>::stdDev(1, sigma), sri::Placement::before(pos_));
    a.sat = sd.sat;
    a.code = sd.code;
    a.baseCode = sd.baseCode;
    a.wavelength = sd.wavelength;
    a.roverArc = sd.roverArc;
    a.baseArc = sd.baseArc;
    a.lastSeen = dd_.time;
    amb_[k] = a;
    ++counters_.ambiguitiesAdded;
    ++sol.ambiguityResets;
  }
  // Ambiguities of satellites gone for too long.
  std::vector<std::uint32_t> stale;
  for (const auto& [k, a] : amb_) {
    if (elapsed(direction_, dd_.time, a.lastSeen) > cfg_.ambiguityOutage) stale.push_back(k);
  }
  for (std::uint32_t k : stale) {
    dropAmbiguity(k);
    ++counters_.ambiguitiesRemoved;
  }
  if (rebuild) builder_.formDoubleDifferences(dd_);
}

bool RtkSolver::measurementUpdate(const Eigen::Vector3d& x0) {
  bool any = false;
  std::vector<int> ph, cd;
  for (std::size_t g = 0; g < dd_.groups.size(); ++g) {
    ph.clear();
    cd.clear();
    for (std::size_t i = 0; i < dd_.phase.size(); ++i) {
      if (dd_.sd[static_cast<std::size_t>(dd_.phase[i].satellite)].group == static_cast<int>(g)) ph.push_back(static_cast<int>(i));
    }
    for (std::size_t i = 0; i < dd_.code.size(); ++i) {
      if (dd_.sd[static_cast<std::size_t>(dd_.code[i].satellite)].group == static_cast<int>(g)) cd.push_back(static_cast<int>(i));
    }
    const int np = static_cast<int>(ph.size()), nc = static_cast<int>(cd.size());
    if (np + nc == 0) continue;
    Meas m(np + nc);
    m.jacobian(pos_, 3);  // position columns first
    Eigen::MatrixXd C = Eigen::MatrixXd::Zero(np + nc, np + nc);
    for (int r = 0; r < np; ++r) {
      const DoubleDifference& d = dd_.phase[static_cast<std::size_t>(ph[static_cast<std::size_t>(r)])];
      const SingleDifference& s = dd_.sd[static_cast<std::size_t>(d.satellite)];
      const SingleDifference& f = dd_.sd[static_cast<std::size_t>(d.reference)];
      const Ambiguity& as = amb_.at(key(s.sat, s.code));
      const Ambiguity& af = amb_.at(key(f.sat, f.code));
      const double ns = filter_.estimate(as.id).vector[0], nf = filter_.estimate(af.id).vector[0];
      const DdResidual res = ddPhaseResidual(dd_, d, x0);
      // The phase is advanced by the ionosphere (μ I): + μ_s I_s − μ_f I_f back in the residual.
      m.residual()[r] = res.residual - (s.wavelength * ns - f.wavelength * nf) + ddIonosphere(s, f);
      // (jacobian() of a new block reallocates: always take the block afresh.)
      m.jacobian(pos_, 3).row(r) = res.jacobian;
      m.jacobian(as.id, 1)(r, 0) = s.wavelength;
      m.jacobian(af.id, 1)(r, 0) = -f.wavelength;
      ionosphereColumns(m, r, s, f, -1.0);
      C(r, r) = res.variance;
      for (int q = 0; q < r; ++q) {
        if (dd_.phase[static_cast<std::size_t>(ph[static_cast<std::size_t>(q)])].reference == d.reference) {
          C(r, q) = C(q, r) = f.phaseVariance;
        }
      }
    }
    for (int r = 0; r < nc; ++r) {
      const DoubleDifference& d = dd_.code[static_cast<std::size_t>(cd[static_cast<std::size_t>(r)])];
      const DdResidual res = ddCodeResidual(dd_, d, x0);
      const int row = np + r;
      m.residual()[row] = res.residual - ddIonosphere(dd_.sd[static_cast<std::size_t>(d.satellite)],
                                                      dd_.sd[static_cast<std::size_t>(d.reference)]);
      m.jacobian(pos_, 3).row(row) = res.jacobian;
      ionosphereColumns(m, row, dd_.sd[static_cast<std::size_t>(d.satellite)],
                        dd_.sd[static_cast<std::size_t>(d.reference)], 1.0);
      C(row, row) = res.variance;
      for (int q = 0; q < r; ++q) {
        if (dd_.code[static_cast<std::size_t>(cd[static_cast<std::size_t>(q)])].reference == d.reference) {
          C(row, np + q) = C(np + q, row) = dd_.sd[static_cast<std::size_t>(d.reference)].codeVariance;
        }
      }
    }
    m.whitenCovariance(C);
    filter_.update(m);
    any = true;
  }
  if (any) filter_.correct();
  return any;
}

bool RtkSolver::rejectOutlier(RtkSolution& sol) {
  const Eigen::Vector3d x = positionEstimate();
  double worst = 0.0;
  int culprit = -1;
  bool culpritPhase = false;
  std::vector<double> norm;
  std::vector<int> idx;
  for (std::size_t g = 0; g < dd_.groups.size(); ++g) {
    for (int pass = 0; pass < 2; ++pass) {
      const bool phase = pass == 0;
      const auto& list = phase ? dd_.phase : dd_.code;
      const double thr = phase ? cfg_.phaseOutlierSigmas : cfg_.codeOutlierSigmas;
      norm.clear();
      idx.clear();
      int ref = -1;
      for (std::size_t i = 0; i < list.size(); ++i) {
        const DoubleDifference& d = list[i];
        const SingleDifference& s = dd_.sd[static_cast<std::size_t>(d.satellite)];
        if (s.group != static_cast<int>(g)) continue;
        ref = d.reference;
        double v;
        double var;
        if (phase) {
          const SingleDifference& f = dd_.sd[static_cast<std::size_t>(d.reference)];
          const DdResidual r = ddPhaseResidual(dd_, d, x);
          v = r.residual - (s.wavelength * ambiguityEstimate(s) - f.wavelength * ambiguityEstimate(f)) +
              ddIonosphere(s, f);
          var = r.variance;
        } else {
          const DdResidual r = ddCodeResidual(dd_, d, x);
          v = r.residual - ddIonosphere(s, dd_.sd[static_cast<std::size_t>(d.reference)]);
          var = r.variance;
        }
        norm.push_back(std::abs(v) / std::sqrt(var));
        idx.push_back(d.satellite);
      }
      if (norm.empty()) continue;
      int over = 0;
      std::size_t imax = 0;
      for (std::size_t i = 0; i < norm.size(); ++i) {
        if (norm[i] > thr) ++over;
        if (norm[i] > norm[imax]) imax = i;
      }
      if (over == 0) continue;
      // Most DDs of the group off: the reference is the likely culprit.
      const bool blameRef = norm.size() >= 3 && over * 2 > static_cast<int>(norm.size());
      const double score = norm[imax] / thr;
      if (score > worst) {
        worst = score;
        culprit = blameRef ? ref : idx[imax];
        culpritPhase = phase;
      }
    }
  }
  if (culprit < 0) return false;
  SingleDifference& sd = dd_.sd[static_cast<std::size_t>(culprit)];
  if (culpritPhase) {
    // Re-initialise the ambiguity: an undetected slip, or a bad phase.
    forced_.insert(key(sd.sat, sd.code));
    ++sol.phaseOutliers;
    ++counters_.phaseOutliers;
  } else {
    sd.hasCode = false;
    builder_.formDoubleDifferences(dd_);
    ++sol.codeOutliers;
    ++counters_.codeOutliers;
  }
  return true;
}

std::optional<double> RtkSolver::differencesWithHeldFix(const ObsEpoch& rover, const Eigen::Vector3d& x, int& fixed,
                                                       TransmitStates* states) {
  fixed = 0;
  const std::optional<double> age = differences(rover, x, states);
  if (!age || held_.empty()) return age;
  for (DoubleDifference& d : dd_.phase) {
    if (flagged(d)) continue;
    const HeldPair p = pairOf(d);
    for (const HeldDd& h : held_) {
      if (h.satellite == p.first && h.reference == p.second) {
        d.fixedCycles = h.cycles;
        d.ambiguityMeters = h.meters;
        ++fixed;
        break;
      }
    }
  }
  return age;
}

void RtkSolver::detectSlips(const ObsEpoch& rover, const GlonassChannels& channels) {
  if (slipEpoch_ && *slipEpoch_ == rover.time) return;
  roverSlips_.process(rover, channels);
  slipEpoch_ = rover.time;
}

RtkSolver::HeldPair RtkSolver::pairOf(const DoubleDifference& d) const {
  return {HeldSignal::of(dd_.sd[static_cast<std::size_t>(d.satellite)]),
          HeldSignal::of(dd_.sd[static_cast<std::size_t>(d.reference)])};
}

bool RtkSolver::flagged(const DoubleDifference& d) const {
  const SingleDifference& s = dd_.sd[static_cast<std::size_t>(d.satellite)];
  const SingleDifference& f = dd_.sd[static_cast<std::size_t>(d.reference)];
  return s.halfCycle || f.halfCycle || s.roverSlip || s.baseSlip || f.roverSlip || f.baseSlip;
}

bool RtkSolver::phasePairsAsProcessed() const {
  if (!lastProcess_ || dd_.phase.size() != processedPairs_.size()) return false;
  for (const DoubleDifference& d : dd_.phase) {
    if (flagged(d) || std::find(processedPairs_.begin(), processedPairs_.end(), pairOf(d)) == processedPairs_.end())
      return false;
  }
  return true;
}

GlonassChannels RtkSolver::roverGlonassChannels() const {
  GlonassChannels ch = roverChannels_;
  ch.mergeMissing(nav_.glonassChannels());
  return ch;
}

const ObsEpoch& RtkSolver::checkedRover(const ObsEpoch& rover) {
  if (!checkRoverDoppler_ || &rover == &roverChecked_) return rover;
  roverChecked_ = rover;
  roverDoppler_.apply(roverChecked_, roverGlonassChannels());
  return roverChecked_;
}

std::optional<double> RtkSolver::differences(const ObsEpoch& roverIn, const Eigen::Vector3d& x, TransmitStates* states) {
  const ObsEpoch& rover = checkedRover(roverIn);
  const GlonassChannels ch = roverGlonassChannels();
  detectSlips(rover, ch);
  if (base_.snapshot(rover.time, snapshot_) != BaseAvailability::Ok) {
    dd_.clear();
    dd_.time = rover.time;
    return std::nullopt;
  }
  builder_.form(rover, roverSlips_, snapshot_, *base_.position(), x, dd_, states);
  return snapshot_.age;
}

RtkSolution RtkSolver::process(const ObsEpoch& rover, TransmitStates* states) {
  // A run that does not fix keeps the last fix to hold: its integers stay valid on the arcs that
  // continue (differencesWithHeldFix checks them); a reset drops it.
  // (processEpoch sets lastProcess_ before any return; only a reset, also the one initialize()
  // starts with, clears it again.)
  std::vector<HeldDd> previous = std::move(held_);
  held_.clear();
  RtkSolution sol = processEpoch(checkedRover(rover), states);
  if (sol.quality != SolutionQuality::Fix && lastProcess_) held_ = std::move(previous);
  return sol;
}

Eigen::Vector3d RtkSolver::updateWithOutlierRejection(Eigen::Vector3d x0, RtkSolution& sol) {
  // Measurement update with post-fit outlier rejection (redone from the saved state). When the
  // update moves the position by more than kRelinearize (a poor first position, e.g. without SPP)
  // it is redone about the updated position: ranges are non-linear at that scale.
  constexpr double kRelinearize = 1.0;
  const Filter predicted = filter_;
  const auto predictedAmb = amb_;
  Filter saved;
  std::unordered_map<std::uint32_t, Ambiguity> savedAmb;
  Eigen::Vector3d xf = x0;
  for (int iteration = 0; iteration < 3; ++iteration) {
    for (int round = 0;; ++round) {
      manageAmbiguities(x0, sol);
      saved = filter_;
      savedAmb = amb_;
      measurementUpdate(x0);
      if (round >= cfg_.maxOutlierRounds || !rejectOutlier(sol)) break;
      filter_ = saved;
      amb_ = savedAmb;
    }
    xf = positionEstimate();
    if ((xf - x0).norm() < kRelinearize || iteration == 2) break;
    filter_ = predicted;
    amb_ = predictedAmb;
    filter_.setEstimate(pos_, sri::BlockEstimate<double>::fromVector(xf));
    x0 = xf;
  }
  return xf;
}

RtkSolution RtkSolver::processEpoch(const ObsEpoch& rover, TransmitStates* states) {
  fixNow_.clear();
  RtkSolution sol;
  sol.time = rover.time;
  const SppSolution spp = spp_.solve(rover);
  sol.sppStatus = spp.status;
  if (spp.dop.valid) sol.hdop = spp.dop.hdop;
  if (spp.valid()) sol.time = spp.solutionTime;
  if (spp.velocity.valid) {
    sol.velocity = spp.velocity.velocity;
    sol.velocityCovariance = spp.velocity.covariance;
  }
  const GlonassChannels ch = roverGlonassChannels();
  detectSlips(rover, ch);
  lastProcess_ = rover.time;
  processedPairs_.clear();

  auto single = [&](RtkIssue issue) {
    sol.issue = issue;
    if (spp.valid()) {
      sol.quality = SolutionQuality::Single;
      sol.position = spp.position;
      sol.positionCovariance = spp.positionCovariance;
      sol.numSatellites = spp.numSatellites;
    }
    return sol;
  };

  forced_.clear();
  if (cfg_.ambiguityMode == AmbiguityMode::Instantaneous) initialized_ = false;
  const BaseAvailability avail = base_.snapshot(rover.time, snapshot_);
  if (avail != BaseAvailability::Ok) {
    dd_.clear();
    dd_.time = rover.time;
    switch (avail) {
      case BaseAvailability::NoPosition: return single(RtkIssue::NoBasePosition);
      case BaseAvailability::NoData: return single(RtkIssue::NoBaseData);
      default: return single(RtkIssue::BaseTooOld);
    }
  }
  sol.age = snapshot_.age;
  const Eigen::Vector3d basePos = *base_.position();

  if (!initialized_) {
    if (spp.valid()) initialize(spp.position, cfg_.initialPositionSigma, spp);
    else initialize(basePos, std::max(cfg_.initialPositionSigma, 1e4), spp);
    lastTime_ = rover.time;
  } else {
    if (elapsed(direction_, rover.time, lastTime_) > 0.0) {
      timeUpdate(rover.time - lastTime_, spp);
      propagateIonosphere(rover.time - lastTime_);
    }
    lastTime_ = rover.time;
  }
  if (spp.velocity.valid) lastVelocity_ = spp.velocity.velocity;

  const Eigen::Vector3d x0 = positionEstimate();
  builder_.form(rover, roverSlips_, snapshot_, basePos, x0, dd_, states);
  baseline_ = (x0 - basePos).norm();

  // Prefit gate on DD code (gross errors, multipath spikes), widened by the uncertainty of the
  // predicted position (a DD line-of-sight difference is at most 2 in length).
  const sri::BlockId pidPrior[] = {pos_};
  const double priorSigma = std::sqrt(std::max(filter_.covariance(pidPrior).trace(), 0.0));
  const double gate = cfg_.codeInnovationGate + 6.0 * priorSigma;
  bool gated = false;
  for (const DoubleDifference& d : dd_.code) {
    if (std::abs(ddCodeResidual(dd_, d, x0).residual) > gate) {
      dd_.sd[static_cast<std::size_t>(d.satellite)].hasCode = false;
      ++sol.codeOutliers;
      ++counters_.codeOutliers;
      gated = true;
    }
  }
  if (gated) builder_.formDoubleDifferences(dd_);

  std::set<SatId> sats;
  for (const auto* list : {&dd_.phase, &dd_.code}) {
    for (const DoubleDifference& d : *list) {
      sats.insert(dd_.sd[static_cast<std::size_t>(d.satellite)].sat);
      sats.insert(dd_.sd[static_cast<std::size_t>(d.reference)].sat);
    }
  }
  if (sats.size() < 4) return single(RtkIssue::NoCommonSatellites);
  manageIonosphere();

  const Eigen::Vector3d xf = updateWithOutlierRejection(x0, sol);

  if (spp.valid() && (xf - spp.position).norm() > cfg_.maxSppDeviation) {
    ++counters_.filterResets;
    reset();
    return single(RtkIssue::FilterReset);
  }
  {
    std::set<std::uint32_t> seen;
    for (const DoubleDifference& d : dd_.phase) {
      for (int i : {d.reference, d.satellite}) {
        const SingleDifference& s = dd_.sd[static_cast<std::size_t>(i)];
        const std::uint32_t k = key(s.sat, s.code);
        if (seen.insert(k).second) {
          const auto it = amb_.find(k);
          if (it != amb_.end()) ++it->second.lock;
        }
      }
    }
  }
  sol.floatPosition = xf;
  const sri::BlockId pid[] = {pos_};
  sol.floatCovariance = filter_.covariance(pid);
  if (!(std::sqrt(std::max(sol.floatCovariance.trace(), 0.0)) < kMaxFloatSigma) || !xf.allFinite()) {
    // The differences did not determine the position (e.g. the code was all gated away).
    return single(RtkIssue::Undetermined);
  }
  sol.quality = SolutionQuality::Float;
  sol.position = xf;
  sol.positionCovariance = sol.floatCovariance;
  sol.numSatellites = dd_.phaseSatellites();
  if (sol.numSatellites == 0) sol.numSatellites = static_cast<int>(sats.size());
  if (vel_.valid() && cfg_.dynamics == RtkDynamics::ConstantVelocity && cfg_.mode == RtkMode::Kinematic) {
    sol.velocity = filter_.estimate(vel_).vector.head<3>();
    const sri::BlockId vid[] = {vel_};
    sol.velocityCovariance = filter_.covariance(vid);
  }
  resolve(sol);
  rememberFix();
  for (const DoubleDifference& d : dd_.phase) processedPairs_.push_back(pairOf(d));
  // The fix to hold (differencesWithHeldFix): the DD phases that got an ambiguity.
  if (sol.quality == SolutionQuality::Fix) {
    for (const DoubleDifference& d : dd_.phase) {
      if (!d.ambiguityMeters || !d.fixedCycles) continue;
      const HeldPair p = pairOf(d);
      held_.push_back({p.first, p.second, *d.fixedCycles, *d.ambiguityMeters});
    }
  }
  return sol;
}

}  // namespace gvins
