#include "gvins/gnss/double_difference.hpp"
#include "gvins/gnss/signal_choice.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <set>
#include <tuple>

#include "gvins/base/geodetic.hpp"
#include "gvins/base/local_frame.hpp"
#include "gvins/gnss/measurement_weighting.hpp"
#include "gvins/gnss/satellite_observation_model.hpp"
#include "gvins/gnss/zero_difference.hpp"

namespace gvins {

void DdEpoch::clear() {
  sd.clear();
  groups.clear();
  phase.clear();
  code.clear();
  age = 0.0;
  baseInterpolated = false;
}

int DdEpoch::phaseSatellites() const {
  std::set<SatId> s;
  for (const DoubleDifference& d : phase) {
    s.insert(sd[static_cast<std::size_t>(d.reference)].sat);
    s.insert(sd[static_cast<std::size_t>(d.satellite)].sat);
  }
  return static_cast<int>(s.size());
}

double sdModelRange(const SingleDifference& sd, const Eigen::Vector3d& x, Eigen::Vector3d* gradient) {
  return geometricRange(sd.satPosition, x, gradient) - sd.satClock + sd.troposphere;
}

double sdPhaseResidual(const SingleDifference& sd, const Eigen::Vector3d& x, Eigen::Vector3d* gradient) {
  return sd.roverPhase - sdModelRange(sd, x, gradient) - sd.basePhaseOmc;
}

double sdCodeResidual(const SingleDifference& sd, const Eigen::Vector3d& x, Eigen::Vector3d* gradient) {
  return sd.roverCode - sdModelRange(sd, x, gradient) - sd.baseCodeOmc;
}

DdResidual ddPhaseResidual(const DdEpoch& e, const DoubleDifference& dd, const Eigen::Vector3d& x) {
  const SingleDifference& s = e.sd[static_cast<std::size_t>(dd.satellite)];
  const SingleDifference& r = e.sd[static_cast<std::size_t>(dd.reference)];
  Eigen::Vector3d gs, gr;
  DdResidual out;
  out.residual = sdPhaseResidual(s, x, &gs) - sdPhaseResidual(r, x, &gr) - dd.ambiguityMeters.value_or(0.0);
  out.jacobian = (gs - gr).transpose();
  out.variance = s.phaseVariance + r.phaseVariance;
  return out;
}

DdResidual ddCodeResidual(const DdEpoch& e, const DoubleDifference& dd, const Eigen::Vector3d& x) {
  const SingleDifference& s = e.sd[static_cast<std::size_t>(dd.satellite)];
  const SingleDifference& r = e.sd[static_cast<std::size_t>(dd.reference)];
  Eigen::Vector3d gs, gr;
  DdResidual out;
  out.residual = sdCodeResidual(s, x, &gs) - sdCodeResidual(r, x, &gr);
  out.jacobian = (gs - gr).transpose();
  out.variance = s.codeVariance + r.codeVariance;
  return out;
}

Eigen::MatrixXd ddCovariance(const DdEpoch& e, const std::vector<DoubleDifference>& dds, bool phase) {
  const int n = static_cast<int>(dds.size());
  Eigen::MatrixXd C = Eigen::MatrixXd::Zero(n, n);
  auto var = [&](int i) {
    const SingleDifference& s = e.sd[static_cast<std::size_t>(i)];
    return phase ? s.phaseVariance : s.codeVariance;
  };
  for (int i = 0; i < n; ++i) {
    C(i, i) = var(dds[static_cast<std::size_t>(i)].satellite) + var(dds[static_cast<std::size_t>(i)].reference);
    for (int j = 0; j < i; ++j) {
      if (dds[static_cast<std::size_t>(i)].reference == dds[static_cast<std::size_t>(j)].reference) {
        C(i, j) = C(j, i) = var(dds[static_cast<std::size_t>(i)].reference);
      }
    }
  }
  return C;
}

DoubleDifferenceBuilder::DoubleDifferenceBuilder(const EphemerisStore& nav, const RtkConfig& config)
    : nav_(nav), config_(config) {}

void DoubleDifferenceBuilder::setGlonassChannels(const GlonassChannels& channels) { channels_ = channels; }

void DoubleDifferenceBuilder::setPhaseAlignment(const PhaseAlignments& rover, const PhaseAlignments& base) {
  roverAlignment_ = rover;
  baseAlignment_ = base;
}

double DoubleDifferenceBuilder::alignedShift(const PhaseAlignments& a, System sys, ObsCode code) {
  return a.get(sys) == PhaseAlignment::Raw ? alignmentShift(sys, code) : 0.0;
}

std::pair<const BaseSignal*, const BaseSignal*> DoubleDifferenceBuilder::baseSignalsOf(const BaseSnapshot& base,
                                                                                       SatId sat) {
  const auto less = [](const BaseSignal& b, SatId s) { return b.sat < s; };
  const BaseSignal* first = base.signals.data();
  const BaseSignal* last = first + base.signals.size();
  const BaseSignal* b = std::lower_bound(first, last, sat, less);
  const BaseSignal* e = b;
  while (e != last && e->sat == sat) ++e;
  return {b, e};
}

std::optional<DoubleDifferenceBuilder::Pick> DoubleDifferenceBuilder::pickPair(const SatObs& so, char band,
                                                                               const BaseSignal* baseBegin,
                                                                               const BaseSignal* baseEnd) {
  const System sys = so.sat.system;
  // Pairs across tracking modes only when both receivers' phases refer to the band's reference.
  const bool crossAllowed = config_.signalMatching == SignalMatching::Band &&
                            roverAlignment_.get(sys) != PhaseAlignment::Unknown &&
                            baseAlignment_.get(sys) != PhaseAlignment::Unknown;
  const std::string_view pri = attributePriority(sys, band);
  const auto rank = [&](ObsCode r, ObsCode b) {
    const int kind = r == b ? 0 : sameSignal(sys, r, b) ? 1 : 2;
    const auto pr = std::min(pri.find(r.attr), pri.size()), pb = std::min(pri.find(b.attr), pri.size());
    return std::tuple<int, std::size_t, std::size_t>(kind, pr, pb);
  };
  bool roverHasBand = false, baseHasBand = false, crossSeen = false;
  for (const BaseSignal* b = baseBegin; b != baseEnd; ++b) baseHasBand = baseHasBand || b->code.band == band;
  // Prefer a pair with phase at both receivers, then one with code at both.
  for (int pass = 0; pass < 2; ++pass) {
    std::optional<Pick> best;
    std::tuple<int, std::size_t, std::size_t> bestRank;
    for (const SignalObs& s : so.signals) {
      if (s.code.band != band) continue;
      roverHasBand = true;
      for (const BaseSignal* b = baseBegin; b != baseEnd; ++b) {
        if (b->code.band != band) continue;
        const bool both = pass == 0 ? s.hasPhase() && b->hasPhase : s.hasCode() && b->hasCode;
        if (!both) continue;
        if (!(s.code == b->code) && !crossAllowed) {
          crossSeen = true;
          continue;
        }
        const auto r = rank(s.code, b->code);
        if (best && !(r < bestRank)) continue;
        best = Pick{&s, b};
        bestRank = r;
      }
    }
    if (best) return best;
  }
  if (roverHasBand && baseHasBand) {
    ++stats_.signalMismatch;
    if (crossSeen) ++stats_.crossModeRefused;
  }
  return std::nullopt;
}

void DoubleDifferenceBuilder::reset() {
  phaseRef_.clear();
  arcs_.clear();
  haveLast_ = false;
}

namespace {

/// The pseudorange that dates the transmission: the first picked signal's code, else any
/// plausible code of the satellite (0 if none).
template <typename PickT>
double transmitPseudorange(const SatObs& so, const PickT* picks, int np) {
  for (int i = 0; i < np; ++i) {
    if (picks[i].rover->hasCode() && picks[i].rover->pseudorange > 1e6) return picks[i].rover->pseudorange;
  }
  for (const SignalObs& s : so.signals) {
    if (s.hasCode() && s.pseudorange > 1e6 && s.pseudorange < 1e8) return s.pseudorange;
  }
  return 0.0;
}

/// One group per system and band; each single difference gets its group's index.
void assignGroups(DdEpoch& out) {
  for (SingleDifference& d : out.sd) {
    int gi = -1;
    for (std::size_t k = 0; k < out.groups.size(); ++k) {
      if (out.groups[k].system == d.sat.system && out.groups[k].band == d.code.band) gi = static_cast<int>(k);
    }
    if (gi < 0) {
      out.groups.push_back(DdGroup{d.sat.system, d.code.band, -1, -1});
      gi = static_cast<int>(out.groups.size() - 1);
    }
    d.group = gi;
  }
}

}  // namespace

void DoubleDifferenceBuilder::form(const ObsEpoch& rover, const CycleSlipDetector& roverSlips, const BaseSnapshot& base,
                                   const Eigen::Vector3d& basePosition, const Eigen::Vector3d& x, DdEpoch& out,
                                   TransmitStates* states) {
  out.clear();
  out.time = rover.time;
  out.baseTime = base.time;
  out.age = base.age;
  out.baseInterpolated = base.interpolated;
  out.basePosition = basePosition;
  const double r = x.norm();
  const Eigen::Vector3d xr = (r > 5.3e6 && r < 7.4e6) ? x : basePosition;
  // The shared per-satellite model (satellite_observation_model.hpp): az/el and, where asked
  // for, the standard-atmosphere troposphere.
  ObservationModelOptions modelOptions;
  modelOptions.troposphere = config_.troposphere ? TroposphereMeteo::StandardAtmosphere : TroposphereMeteo::Off;
  const SatelliteObservationModel model(xr, rover.time, modelOptions);
  const bool prevOk = haveLast_;
  const GpsTime prevEpoch = lastEpoch_;
  GlonassChannels ch = channels_;
  ch.mergeMissing(nav_.glonassChannels());
  const double a2 = config_.phaseSigmaA * config_.phaseSigmaA;
  const double b2 = config_.phaseSigmaB * config_.phaseSigmaB;
  MeasurementWeighting codeWeights;  // one receiver's code (RtkConfig::codeWeighting)
  codeWeights.scheme = config_.codeWeighting;
  codeWeights.a = config_.codePhaseRatio * config_.phaseSigmaA;
  codeWeights.b = config_.codePhaseRatio * config_.phaseSigmaB;
  codeWeights.systemFactor = config_.codeSystemFactor;

  for (const SatObs& so : rover.sats) {
    if (!so.sat.valid()) continue;
    ++stats_.satellites;
    const System sys = so.sat.system;
    if (!config_.useSystem(sys)) {
      ++stats_.systemDisabled;
      continue;
    }
    if (!base.has(so.sat)) {
      ++stats_.notAtBase;
      continue;
    }
    std::optional<int> channel;
    if (sys == System::Glonass) channel = ch.get(so.sat.prn);
    // One signal pair per band, the first `frequencies` bands of the preference list.
    Pick picks[3];
    int np = 0;
    const auto [baseBegin, baseEnd] = baseSignalsOf(base, so.sat);
    // The configured preference list, then the system's fallback bands (signal_choice.hpp).
    const std::string bands = bandsWithFallback(config_.bands[static_cast<std::size_t>(systemIndex(sys))], sys);
    for (char band : bands) {
      if (np >= std::clamp(config_.frequencies, 1, 3)) break;
      const auto pick = pickPair(so, band, baseBegin, baseEnd);
      if (pick) picks[np++] = *pick;
    }
    if (np == 0) continue;
    // Satellite state at the rover transmit time.
    const auto tx = transmitState(states, nav_, so.sat, rover.time, transmitPseudorange(so, picks, np));
    if (!tx) {
      ++stats_.noEphemeris;
      continue;
    }
    const AzEl azel = model.azimuthElevation(tx->state.position);
    if (azel.elevation < config_.elevationMask) {
      ++stats_.belowMask;
      continue;
    }
    const double snr = picks[0].rover->hasSnr() ? picks[0].rover->snr : 0.0;
    if (config_.snrMask > 0.0 && snr > 0.0 && snr < config_.snrMask) {
      ++stats_.lowSnr;
      continue;
    }
    const double tropo = model.terms(tx->state.position, azel, sys, 0.0).troposphere.slant;
    const double sinEl = std::max(std::sin(azel.elevation), 0.05);
    const double varPhase = 2.0 * (a2 + b2 / (sinEl * sinEl));
    bool any = false;
    for (int i = 0; i < np; ++i) {
      const SignalObs& rs = *picks[i].rover;
      const BaseSignal& bs = *picks[i].base;
      SingleDifference d;
      d.sat = so.sat;
      d.code = rs.code;
      d.baseCode = bs.code;
      d.elevation = azel.elevation;
      d.azimuth = azel.azimuth;
      d.snr = rs.hasSnr() ? rs.snr : 0.0;
      d.baseSnr = bs.snr;
      d.satPosition = tx->state.position;
      d.satClock = constants::kSpeedOfLight * tx->state.clockBias;
      d.troposphere = tropo;
      const auto lam = carrierWavelength(sys, rs.code.band, channel);
      d.wavelength = lam ? *lam : 0.0;
      d.hasPhase = lam && rs.hasPhase() && bs.hasPhase && rs.carrierPhase != 0.0 && std::isfinite(rs.carrierPhase);
      d.hasCode = rs.hasCode() && bs.hasCode && rs.pseudorange > 1e6 && rs.pseudorange < 1e8;
      if (!d.hasPhase && !d.hasCode) continue;
      if (!(rs.code == bs.code)) ++stats_.crossMode;
      if (d.hasPhase) {
        // Raw tracking phases are referred to the band's reference signal (alignedShift).
        d.roverPhase = *lam * (rs.carrierPhase + alignedShift(roverAlignment_, sys, rs.code));
        d.basePhaseOmc = bs.phaseOmc + *lam * alignedShift(baseAlignment_, sys, bs.code);
        d.roverSlip = roverSlips.flags(so.sat, rs.code);
        d.roverArc = roverSlips.arcStart(so.sat, rs.code).value_or(rover.time);
        d.baseSlip = bs.slipFlags;
        d.baseArc = bs.arcStart;
        d.halfCycle = ((d.roverSlip | d.baseSlip) & kSlipHalfCycle) != 0;
        const auto key = signalKey(so.sat, rs.code);
        auto it = arcs_.find(key);
        d.continuous = prevOk && it != arcs_.end() && it->second.epoch == prevEpoch && it->second.rover == d.roverArc &&
                       it->second.base == d.baseArc && it->second.baseCode == d.baseCode;
        arcs_[key] = Arcs{d.roverArc, d.baseArc, rover.time, d.baseCode};
      }
      if (d.hasCode) {
        d.roverCode = rs.pseudorange;
        d.baseCodeOmc = bs.codeOmc;
      }
      d.phaseVariance = varPhase;
      d.codeVariance = codeWeights.codeVariance(sys, azel.elevation, d.snr) +
                       codeWeights.codeVariance(sys, azel.elevation, d.baseSnr);
      out.sd.push_back(d);
      any = true;
    }
    if (any) ++stats_.used;
  }
  lastEpoch_ = rover.time;
  haveLast_ = true;
  // Forget arcs of signals not seen for a while (bounded memory over long sessions).
  if (arcs_.size() > 4096) {
    for (auto it = arcs_.begin(); it != arcs_.end();) {
      if (rover.time - it->second.epoch > 3600.0) it = arcs_.erase(it);
      else ++it;
    }
  }
  assignGroups(out);
  formDoubleDifferences(out);
}

void DoubleDifferenceBuilder::formDoubleDifferences(DdEpoch& e) {
  e.phase.clear();
  e.code.clear();
  const int n = static_cast<int>(e.sd.size());
  for (std::size_t gi = 0; gi < e.groups.size(); ++gi) {
    DdGroup& g = e.groups[gi];
    const int key = groupKey(g.system, g.band);
    // Phase reference: the previous one while usable, else the highest continuous satellite,
    // else the highest.
    int ref = -1;
    const auto prev = phaseRef_.find(key);
    int bestCont = -1, bestAny = -1;
    for (int i = 0; i < n; ++i) {
      const SingleDifference& d = e.sd[static_cast<std::size_t>(i)];
      if (d.group != static_cast<int>(gi) || !d.hasPhase) continue;
      const bool clean = d.continuous && !(d.roverSlip & kSlipResetMask) && !d.halfCycle;
      if (prev != phaseRef_.end() && d.sat == prev->second && clean) ref = i;
      if (clean && (bestCont < 0 || d.elevation > e.sd[static_cast<std::size_t>(bestCont)].elevation)) bestCont = i;
      if (bestAny < 0 || d.elevation > e.sd[static_cast<std::size_t>(bestAny)].elevation) bestAny = i;
    }
    if (ref < 0) ref = bestCont >= 0 ? bestCont : bestAny;
    g.phaseReference = ref;
    if (ref >= 0) {
      phaseRef_[key] = e.sd[static_cast<std::size_t>(ref)].sat;
      for (int i = 0; i < n; ++i) {
        const SingleDifference& d = e.sd[static_cast<std::size_t>(i)];
        if (i == ref || d.group != static_cast<int>(gi) || !d.hasPhase) continue;
        e.phase.push_back(DoubleDifference{ref, i, std::nullopt, std::nullopt});
      }
    } else {
      phaseRef_.erase(key);
    }
    // Code reference: the phase reference if it has code, else the highest with code.
    int cref = (ref >= 0 && e.sd[static_cast<std::size_t>(ref)].hasCode) ? ref : -1;
    if (cref < 0) {
      for (int i = 0; i < n; ++i) {
        const SingleDifference& d = e.sd[static_cast<std::size_t>(i)];
        if (d.group != static_cast<int>(gi) || !d.hasCode) continue;
        if (cref < 0 || d.elevation > e.sd[static_cast<std::size_t>(cref)].elevation) cref = i;
      }
    }
    g.codeReference = cref;
    if (cref >= 0) {
      for (int i = 0; i < n; ++i) {
        const SingleDifference& d = e.sd[static_cast<std::size_t>(i)];
        if (i == cref || d.group != static_cast<int>(gi) || !d.hasCode) continue;
        e.code.push_back(DoubleDifference{cref, i, std::nullopt, std::nullopt});
      }
    }
  }
}

}  // namespace gvins
