// Single point positioning. Observation equation for a pseudorange P of satellite s on the
// system clock of constellation k:
//   P = |r_s(t_tx) - r| + sagnac + c dt_k - c (dt_s - gd_s) + I + T + e,
// with the transmit time t_tx = t_rx - P/c - dt_s (independent of the receiver clock), the
// satellite position in the ECEF frame of t_tx and the Earth rotation during the signal travel
// applied as the Sagnac range term. Solved by Gauss-Newton iterations of weighted least squares.
#include "gvins/gnss/spp.hpp"

#include <algorithm>
#include <cmath>

#include "gvins/base/constants.hpp"
#include "gvins/base/geodetic.hpp"
#include "gvins/gnss/ionosphere_free.hpp"
#include "gvins/gnss/klobuchar.hpp"
#include "gvins/gnss/sagnac.hpp"
#include "gvins/gnss/satellite_observation_model.hpp"
#include "gvins/gnss/signal_choice.hpp"
#include "gvins/gnss/zero_difference.hpp"
#include "normal_equations.hpp"
#include "spp_reported_covariance.hpp"

namespace gvins {

namespace {
constexpr double kC = constants::kSpeedOfLight;
constexpr int kMaxUnknowns = 4 + kNumSystems;  // position, clocks, zenith ionosphere
using MatN = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxUnknowns, kMaxUnknowns>;
using VecN = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxUnknowns, 1>;
/// Sigma (m) of the vertical L1 ionospheric delay when no broadcast model is available (a receiver
/// that has not yet decoded the parameters): about 30 TECU (1 TECU = 0.162 m on L1), a daytime
/// value; the reported covariance's error model maps it to each line of sight.
constexpr double kUnmodelledVerticalIonosphere = 5.0;

/// Whether an ECEF position is near the Earth's surface (-1000 km .. +1000 km from the ellipsoid
/// sphere approximation), i.e. converged enough for elevations and atmospheric models.
bool nearSurface(const Eigen::Vector3d& x) {
  const double r = x.norm();
  return r > 5.3e6 && r < 7.4e6;
}
}  // namespace

const char* toString(SppStatus s) {
  switch (s) {
    case SppStatus::Ok: return "ok";
    case SppStatus::NoObservations: return "no observations";
    case SppStatus::NotEnoughSatellites: return "not enough satellites";
    case SppStatus::NoConvergence: return "no convergence";
    case SppStatus::GdopTooLarge: return "GDOP too large";
    case SppStatus::TestFailed: return "residual test failed";
  }
  return "?";
}

PositionSolution SppSolution::toPositionSolution() const {
  PositionSolution p;
  p.time = solutionTime;
  p.quality = valid() ? SolutionQuality::Single : SolutionQuality::None;
  p.position = position;
  p.positionCovariance = positionCovariance;
  p.numSatellites = numSatellites;
  if (valid()) {
    p.residualTest = status == SppStatus::TestFailed ? ResidualTest::Failed
                                                     : (dof < 1 ? ResidualTest::Untestable : ResidualTest::Passed);
  }
  if (velocity.valid) {
    p.velocity = velocity.velocity;
    p.velocityCovariance = velocity.covariance;
  }
  return p;
}

struct SppSolver::Measurement {
  SatId sat;
  int sys = 0;
  int result = 0;  // index into SppSolution::satellites
  double pseudorange = 0.0;
  double frequency = 0.0;  // of the primary signal (ionosphere scaling)
  bool ionosphereFree = false;
  // The combination a1 P1 + a2 P2 of the pseudorange (ionosphere-free: both; else a1 = 1, a2 = 0)
  // and the C/N0 of its signals (0: unknown), for its noise variance.
  double a1 = 1.0, a2 = 0.0;
  double snr = 0.0, snr2 = 0.0;
  SatelliteState state;
  double satClock = 0.0;  // s, clock bias minus group delay
  // Doppler
  bool hasDoppler = false;
  double rangeRate = 0.0;
  // Model values of the last iteration.
  AzEl azel{0.0, 0.5 * constants::kPi};
  double iono = 0.0, tropo = 0.0, variance = 1.0;
  // Error budget of the reported covariance (ReportedErrorModel): variances of the noise and of
  // the broadcast orbit/clock, the slant broadcast-ionosphere error sigma, its pierce point, the
  // troposphere residual's mapping; the residual of the fit before robust re-weighting.
  double noiseVariance = 0.0, ephemerisVariance = 0.0, ionosphereSigma = 0.0, troposphereMap = 0.0;
  Eigen::Vector3d piercePoint = Eigen::Vector3d::UnitZ();
  double priorResidual = 0.0;
  bool active = true;  // above the mask in the last iteration
  double inflation = 1.0;  // variance factor from robust re-weighting
  double ionoMap = 0.0;    // partial of the delay w.r.t. a zenith L1 ionosphere correction
};

SppSolver::SppSolver(const EphemerisStore& nav, SppConfig config)
    : nav_(nav), config_(std::move(config)), ephemerides_(nav_, config_.ephemeris) {}

void SppSolver::setGlonassChannels(const GlonassChannels& channels) { channels_ = channels; }
void SppSolver::setInitialPosition(const Eigen::Vector3d& ecef) { initial_ = ecef; }
void SppSolver::reset() {
  last_.reset();
  isb_ = {};
}

bool SppSolver::gatherMeasurements(const ObsEpoch& epoch, SppSolution& sol, std::vector<Measurement>& meas) {
  const SppConfig& cfg = config_;
  for (const SatObs& so : epoch.sats) {
    SatelliteResidual r;
    r.sat = so.sat;
    const int result = static_cast<int>(sol.satellites.size());
    sol.satellites.push_back(r);
    SatelliteResidual& out = sol.satellites.back();
    if (!cfg.useSystem(so.sat.system) || !so.sat.valid()) {
      out.use = SatelliteUse::SystemDisabled;
      continue;
    }
    const int sys = systemIndex(so.sat.system);
    std::optional<int> channel;
    if (so.sat.system == System::Glonass) {
      channel = channels_.get(so.sat.prn);
      if (!channel) channel = nav_.glonassChannels().get(so.sat.prn);
    }
    // Bands considered, in order of preference: the first usable code, paired with the next
    // usable band of the list (the pairing every user shares: satellite_observation_model.hpp).
    const std::string& bands = cfg.bands[sys];
    const std::size_t nb = std::min<std::size_t>(bands.size(), static_cast<std::size_t>(std::clamp(cfg.frequencies, 1, 3)));
    std::optional<CodeSignal> c1, c2;
    c1 = primaryCode(so, bands, nb, channel);  // with fallback beyond the list (signal_choice.hpp)
    if (c1) signalNotices_.record(so.sat.system, bands.empty() ? primaryBand(so.sat.system) : bands[0], c1->signal->code);
    if (c1) c2 = secondCode(so, bands, nb, c1->signal->code.band, channel);
    const SignalObs* s1 = c1 ? c1->signal : nullptr;
    const SignalObs* s2 = c2 ? c2->signal : nullptr;
    const double f1 = c1 ? c1->frequency : 0.0;
    const double f2 = c2 ? c2->frequency : 0.0;
    if (!s1) {
      out.use = SatelliteUse::NoSignal;
      continue;
    }
    if (cfg.snrMask > 0.0 && s1->hasSnr() && s1->snr < cfg.snrMask) {
      out.use = SatelliteUse::LowSnr;
      continue;
    }
    Measurement m;
    m.sat = so.sat;
    // Clock group: QZSS time is steered to GPST and its L1/L2/L5 signals share GPS's
    // (IS-QZSS-PNT-005, 3.2.1), so QZSS can use the GPS receiver clock instead of its own.
    m.sys = so.sat.system == System::Qzss && cfg.qzssUsesGpsClock ? systemIndex(System::Gps) : sys;
    m.result = result;
    m.frequency = f1;
    m.snr = s1->hasSnr() ? s1->snr : 0.0;
    m.pseudorange = s1->pseudorange;
    IonosphereFreeCoefficients ifc;
    if (cfg.ionosphere == IonosphereOption::DualFrequency && s2) {
      ifc = ionosphereFreeCoefficients(f1, f2);
      m.pseudorange = ifc.a1 * s1->pseudorange + ifc.a2 * s2->pseudorange;
      m.ionosphereFree = true;
      m.a1 = ifc.a1;
      m.a2 = ifc.a2;
      m.snr2 = s2->hasSnr() ? s2->snr : 0.0;
    }
    // Transmit time, satellite state (broadcast, precise or SSR) and group delays: the one
    // satellite-source choice (zero_difference.hpp), with this solver's record cache.
    const auto tx = satelliteAtTransmit(nav_, so.sat, epoch.time, m.pseudorange, cfg.ephemeris, &ephemerides_);
    if (!tx) {
      out.use = SatelliteUse::NoEphemeris;
      continue;
    }
    m.state = tx->state;
    double gd = transmitGroupDelay(nav_, *tx, so.sat, s1->code);
    if (m.ionosphereFree) gd = ifc.a1 * gd + ifc.a2 * transmitGroupDelay(nav_, *tx, so.sat, s2->code);
    m.satClock = m.state.clockBias - gd;
    // Doppler: the primary signal's, else any signal with a known wavelength.
    const SignalObs* d = s1->hasDoppler() ? s1 : nullptr;
    double fd = f1;
    if (!d) {
      for (const auto& s : so.signals) {
        if (!s.hasDoppler()) continue;
        const auto f = carrierFrequency(so.sat.system, s.code.band, channel);
        if (f) {
          d = &s;
          fd = *f;
          break;
        }
      }
    }
    if (d && std::abs(d->doppler) < 1e5) {
      m.hasDoppler = true;
      m.rangeRate = -kC / fd * d->doppler;
    }
    out.ionosphereFree = m.ionosphereFree;
    meas.push_back(m);
  }
  return !meas.empty();
}

namespace {

/// A weighted least-squares fit of the measurements flagged in `use`.
struct LsqResult {
  bool ok = false;
  VecN x;     // state increment or state
  MatN cov;   // (H^T W H)^-1, computed with the statistics (wantResiduals) only
  double chi2 = 0.0;
  int nObs = 0;
  int nUnknowns = 0;
  std::vector<double> normResidual;
};

}  // namespace

/// One epoch's solution (SppSolver::solve): the model values of the measurements, the clock
/// columns, the Gauss-Newton iterations, fault exclusion, robust re-weighting and the outputs.
class SppSolver::Fit {
 public:
  using SparseRow = detail::NormalEquations<kMaxUnknowns>::SparseRow;

  Fit(const SppSolver& solver, const ObsEpoch& epoch, std::vector<Measurement>& meas, SppSolution& sol)
      : cfg(solver.config_),
        epoch(epoch),
        meas(meas),
        sol(sol),
        isb(solver.isb_),
        ionoPar(solver.nav_.ionosphere()),
        n(static_cast<int>(meas.size())),
        // Zenith ionosphere correction to the broadcast model as an extra unknown (with a prior).
        estIono(cfg.ionosphereEstimation.enabled && cfg.ionosphere != IonosphereOption::Off && ionoPar.gps.has_value()) {}

  /// Updates az/el, atmospheric delays, variances and the mask flag of every measurement at x.
  /// Model values change by < 1 mm when the position moves by less than a metre (elevations by
  /// < 2e-7 rad), so they are refreshed only after larger moves.
  void updateModels(const Eigen::Vector3d& x);
  /// Clock columns for the systems with active measurements.
  void assignColumns(const std::vector<char>& use);
  /// Reference clock: GPS when present, else the system with the most measurements.
  int referenceSystem(const std::vector<char>& use) const;
  /// One Gauss-Newton step at state (x, clocks) using the frozen model values.
  /// Returns the increment and the statistics of the linearisation point.
  LsqResult lsqStep(const Eigen::Vector3d& x, const VecN& clk, double ion, const std::vector<char>& use,
                    bool wantResiduals);
  /// Full iteration to convergence for a subset; models are refreshed when `refresh` is set.
  LsqResult iterate(std::vector<char>& use, bool refresh, int maxIter, Eigen::Vector3d& xs, VecN& clks, double& ion);
  /// Fault detection and exclusion from the converged solution; false (sol.status set) if the
  /// solution on the remaining measurements fails.
  bool excludeFaults();
  /// Robust re-weighting of the measurements used (RobustEstimation).
  void reweight();
  /// Position, covariance, clocks and residuals into sol; false (sol.status set) if the
  /// geometry is too weak.
  bool writeSolution();
  /// Doppler velocity at the solution from the measurements used.
  void solveVelocity();
  /// Keeps the residuals and the ionosphere correction of the fit before robust re-weighting
  /// (the reported covariance's variance factor is taken from them).
  void keepPriorResiduals();
  /// Removed by fault exclusion (and of a system that keeps a clock column).
  bool excludedByFde(int i) const;
  /// The reported covariance under SppConfig::reportedError (spp_reported_covariance.hpp).
  void reportCovariance();

  const SppConfig& cfg;
  const ObsEpoch& epoch;
  std::vector<Measurement>& meas;
  SppSolution& sol;
  const std::array<Isb, kNumSystems>& isb;
  const IonosphereParameters& ionoPar;
  const int n;
  const bool estIono;
  double ionoPriorVar = 1.0;
  double ionBeforeRobust = 0.0;
  std::optional<Eigen::Vector3d> modelPoint;
  std::array<int, kNumSystems> col{};
  std::vector<int> colSystems;
  detail::NormalEquations<kMaxUnknowns> ne;
  std::vector<std::pair<SparseRow, double>> rows;  // for residual normalisation
  std::vector<double> resid;
  // The solution: position, clocks, zenith ionosphere, the measurements used, the last fit.
  Eigen::Vector3d x = Eigen::Vector3d::Zero();
  VecN clk;
  double ion = 0.0;
  std::vector<char> use;
  LsqResult last;
};

namespace {
SppStatus statusForFailure(const LsqResult& r) {
  return r.nObs < r.nUnknowns ? SppStatus::NotEnoughSatellites : SppStatus::NoConvergence;
}
}  // namespace

void SppSolver::Fit::updateModels(const Eigen::Vector3d& x) {
  if (modelPoint && (x - *modelPoint).norm() < 0.5) return;
  modelPoint = x;
  const bool surface = nearSurface(x);
  // Station-dependent parts of the models, computed once for all satellites.
  std::optional<SatelliteObservationModel> model;
  if (surface) {
    ObservationModelOptions mo;
    mo.troposphere = cfg.troposphere != TroposphereOption::Saastamoinen ? TroposphereMeteo::Off
                     : cfg.climatologicalMeteo                         ? TroposphereMeteo::Climatology
                                                                       : TroposphereMeteo::StandardAtmosphere;
    mo.relativeHumidity = cfg.relativeHumidity;
    mo.broadcastIonosphere = cfg.ionosphere != IonosphereOption::Off;
    model.emplace(x, epoch.time, mo, &ionoPar);
  }
  double zenithIono = 0.0;  // broadcast model's zenith delay on L1 at the receiver, m
  if (surface && ionoPar.gps) {
    zenithIono = klobucharDelayL1(*ionoPar.gps, model->geodetic(), AzEl{0.0, 0.5 * constants::kPi}, epoch.time);
  }
  if (surface && estIono && ionoPar.gps) {
    const double iz = zenithIono;
    ionoPriorVar = std::pow(std::max(cfg.ionosphereEstimation.priorFraction * iz, cfg.ionosphereEstimation.minPriorSigma), 2);
  }
  for (Measurement& m : meas) {
    m.iono = 0.0;
    m.tropo = 0.0;
    double ionoVar = 0.0, tropoVar = 0.0;
    m.ionoMap = 0.0;
    m.troposphereMap = 0.0;
    if (surface) {
      // An ionosphere-free pseudorange (frequency 0) gets no ionosphere term.
      const SatelliteModelTerms t = model->terms(m.state.position, m.sat.system, m.ionosphereFree ? 0.0 : m.frequency);
      m.azel = t.azel;
      m.active = m.azel.elevation >= cfg.elevationMask;
      if (model->troposphere().valid()) {
        m.tropo = t.troposphere.slant;
        m.troposphereMap = t.troposphere.mapHydrostatic;
        const double e = cfg.troposphereZenithError * m.troposphereMap;
        tropoVar = e * e;
      }
      if (!m.ionosphereFree && cfg.ionosphere != IonosphereOption::Off) {
        m.iono = t.ionosphere.slant;
        const double e = cfg.ionosphereModelError * m.iono;
        ionoVar = e * e;
        if (m.iono == 0.0) ionoVar = 25.0;  // no model available: ~5 m slant delay unaccounted
        m.ionoMap = t.ionosphere.mapL1;  // the obliquity scaled to the frequency
      }
    } else {
      m.azel = AzEl{0.0, 0.5 * constants::kPi};
      m.active = true;
    }
    // The noise of both signals of an ionosphere-free pseudorange, each by the weighting model.
    const double noiseVar =
        cfg.weighting.combinationCodeVariance(m.sat.system, m.azel.elevation, m.a1, m.snr, m.a2, m.snr2);
    double var = noiseVar + ionoVar + tropoVar;
    double eph = m.state.precise || m.state.ssr ? cfg.preciseEphemerisError[systemIndex(m.sat.system)]
                                 : cfg.ephemerisError[systemIndex(m.sat.system)];
    if (!m.state.precise && !m.state.ssr && m.state.accuracy > cfg.ephemerisAlarmAccuracy && cfg.ephemerisAlarmAccuracy > 0.0) {
      eph = std::max(eph, std::min(m.state.accuracy, 1000.0));
    }
    var += eph * eph;
    m.variance = var * m.inflation;
    m.noiseVariance = noiseVar;
    m.ephemerisVariance = eph * eph;
    // The reported model's ionosphere error: a field of vertical errors of one sigma (the model
    // error times the zenith delay at the receiver) seen through each line's obliquity.
    // Without a broadcast model the whole delay is the error: kUnmodelledVerticalIonosphere.
    if (m.ionoMap > 0.0 && zenithIono > 0.0 && m.iono != 0.0) {
      m.ionosphereSigma = cfg.ionosphereModelError * zenithIono * m.ionoMap;
    } else if (m.ionoMap > 0.0 && m.iono == 0.0) {
      m.ionosphereSigma = kUnmodelledVerticalIonosphere * m.ionoMap;
    } else {
      m.ionosphereSigma = std::sqrt(ionoVar);
    }
    if (surface) m.piercePoint = detail::ionosphericPiercePoint(x, m.state.position, 350e3);
  }
}

void SppSolver::Fit::assignColumns(const std::vector<char>& use) {
  col.fill(-1);
  colSystems.clear();
  for (int i = 0; i < n; ++i) {
    if (!use[i]) continue;
    if (col[meas[i].sys] < 0) {
      col[meas[i].sys] = static_cast<int>(colSystems.size());
      colSystems.push_back(meas[i].sys);
    }
  }
}

int SppSolver::Fit::referenceSystem(const std::vector<char>& use) const {
  if (col[systemIndex(System::Gps)] >= 0) return systemIndex(System::Gps);
  std::array<int, kNumSystems> cnt{};
  for (int i = 0; i < n; ++i) cnt[meas[i].sys] += use[i] ? 1 : 0;
  return static_cast<int>(std::max_element(cnt.begin(), cnt.end()) - cnt.begin());
}

LsqResult SppSolver::Fit::lsqStep(const Eigen::Vector3d& x, const VecN& clk, double ion, const std::vector<char>& use,
                                  bool wantResiduals) {
  LsqResult r;
  const int nc = static_cast<int>(colSystems.size());
  const int m = 3 + nc + (estIono ? 1 : 0);
  r.nUnknowns = m;
  // Normal equations accumulated row by row (rows have 4-5 non-zero entries).
  ne.reset(m);
  SparseRow h;
  rows.clear();
  resid.assign(wantResiduals ? n : 0, 0.0);
  double chi2 = 0.0;
  int nobs = 0;
  for (int i = 0; i < n; ++i) {
    if (!use[i]) continue;
    const Measurement& mm = meas[i];
    const Eigen::Vector3d d = mm.state.position - x;
    const double rho = d.norm();
    const Eigen::Vector3d e = d / rho;
    const int c = col[mm.sys];
    const double pred = rho + sagnacRangeCorrection(mm.state.position, x) + clk[c] - kC * mm.satClock + mm.iono +
                        mm.ionoMap * ion + mm.tropo;
    const double v = mm.pseudorange - pred;
    const double w = 1.0 / mm.variance;
    h.nnz = 0;
    h.push(0, -e.x());
    h.push(1, -e.y());
    h.push(2, -e.z());
    h.push(3 + c, 1.0);
    if (estIono) h.push(3 + nc, mm.ionoMap);
    ne.addRow(h, v, w);
    chi2 += w * v * v;
    ++nobs;
    if (wantResiduals) {
      resid[i] = v;
      rows.emplace_back(h, mm.variance);
    }
  }
  // Inter-system bias priors: clk_s - clk_ref = isb_s - isb_ref.
  const int ref = referenceSystem(use);
  const bool refKnown = ref == systemIndex(System::Gps) || isb[ref].known;
  if (cfg.isbPriorSigma > 0.0 && refKnown) {
    for (int s : colSystems) {
      if (s == ref || !isb[s].known) continue;
      const double dt = std::abs(epoch.time - isb[s].time);
      double var = isb[s].variance + cfg.isbRandomWalk * dt;
      double target = isb[s].value;
      if (ref != systemIndex(System::Gps)) {
        var += isb[ref].variance + cfg.isbRandomWalk * std::abs(epoch.time - isb[ref].time);
        target -= isb[ref].value;
      }
      var = std::max(var, cfg.isbPriorSigma * cfg.isbPriorSigma);
      const double v = target - (clk[col[s]] - clk[col[ref]]);
      const double w = 1.0 / var;
      h.nnz = 0;
      if (col[s] < col[ref]) {  // columns ascending
        h.push(3 + col[s], 1.0);
        h.push(3 + col[ref], -1.0);
      } else {
        h.push(3 + col[ref], -1.0);
        h.push(3 + col[s], 1.0);
      }
      ne.addRow(h, v, w);
      chi2 += w * v * v;
      ++nobs;
    }
  }
  if (estIono) {
    const double v = -ion;
    const double w = 1.0 / ionoPriorVar;
    h.nnz = 0;
    h.push(3 + nc, 1.0);
    ne.addRow(h, v, w);
    chi2 += w * v * v;
    ++nobs;
  }
  r.nObs = nobs;
  r.chi2 = chi2;
  if (nobs < m) return r;
  if (!ne.factor(1e-12)) return r;
  r.x.resize(m);
  ne.solve(r.x.data());
  if (!r.x.allFinite()) return r;
  if (wantResiduals) {
    // The covariance only with the statistics: the iterations use the increment alone.
    r.cov.resize(m, m);
    ne.inverse(r.cov.data(), m);
    if (!r.cov.allFinite()) return r;
  }
  r.ok = true;
  if (wantResiduals) {
    // Normalised post-fit residuals of the linearised problem: v_post = v - H dx,
    // var(v_post) = sigma^2 - h Q h^T.
    r.normResidual.assign(n, 0.0);
    int k = 0;
    for (int i = 0; i < n; ++i) {
      if (!use[i]) continue;
      const auto& [hr, var] = rows[k++];
      const double post = resid[i] - hr.dot(r.x.data());
      const double q = var - detail::NormalEquations<kMaxUnknowns>::quadraticForm(hr, r.cov.data(), m);
      r.normResidual[i] = std::abs(post) / std::sqrt(std::max(q, 1e-6 * var));
    }
  }
  return r;
}

LsqResult SppSolver::Fit::iterate(std::vector<char>& use, bool refresh, int maxIter, Eigen::Vector3d& xs, VecN& clks,
                                  double& ion) {
  LsqResult res;
  bool converged = false;
  int it = 0;
  std::vector<char> active(n);
  for (; it < maxIter; ++it) {
    if (refresh) updateModels(xs);
    for (int i = 0; i < n; ++i) active[i] = use[i] && meas[i].active;
    // Keep clock estimates of systems that stay; new systems start at 0 m.
    std::array<double, kNumSystems> prev{};
    std::array<bool, kNumSystems> had{};
    for (std::size_t c = 0; c < colSystems.size(); ++c) {
      if (static_cast<int>(c) < clks.size()) {
        prev[colSystems[c]] = clks[static_cast<int>(c)];
        had[colSystems[c]] = true;
      }
    }
    assignColumns(active);
    clks = VecN::Zero(static_cast<int>(colSystems.size()));
    for (std::size_t c = 0; c < colSystems.size(); ++c) {
      if (had[colSystems[c]]) clks[static_cast<int>(c)] = prev[colSystems[c]];
    }
    res = lsqStep(xs, clks, ion, active, false);
    if (!res.ok) break;
    const int ncol = static_cast<int>(colSystems.size());
    xs += res.x.head<3>();
    clks += res.x.segment(3, ncol);
    if (estIono) ion += res.x[3 + ncol];
    if (res.x.head<3>().norm() < 1e-4 && (nearSurface(xs) || !refresh)) {
      converged = true;
      ++it;
      break;
    }
  }
  sol.iterations += it;
  // Without convergence the fit is not used; its size (nObs, nUnknowns) is that of the last step.
  if (!res.ok || !converged) {
    res.ok = false;
    return res;
  }
  // Statistics at the converged point.
  res = lsqStep(xs, clks, ion, active, true);
  use = active;
  return res;
}

bool SppSolver::Fit::excludeFaults() {
  // Fault detection and exclusion with frozen models (geometry re-linearised in each fit).
  const Eigen::Vector3d xConv = x;
  const VecN clkConv = clk;
  const double ionConv = ion;
  const std::vector<int> colsConv = colSystems;
  auto subsetFit = [&](const std::vector<char>& u) {
    SubsetFit f;
    Eigen::Vector3d xs = xConv;
    VecN cs = clkConv;
    double is = ionConv;
    colSystems = colsConv;
    std::vector<char> uu = u;
    // A few iterations suffice from the converged point.
    LsqResult r = iterate(uu, false, 5, xs, cs, is);
    f.ok = r.ok;
    f.chi2 = r.chi2;
    f.dof = r.nObs - r.nUnknowns;
    f.normalizedResidual = std::move(r.normResidual);
    return f;
  };
  FaultExclusionResult fde;
  {
    SubsetFit f0;
    f0.ok = true;
    f0.chi2 = last.chi2;
    f0.dof = last.nObs - last.nUnknowns;
    f0.normalizedResidual = last.normResidual;
    bool first = true;
    auto fitFn = [&](const std::vector<char>& u) {
      if (first) {
        first = false;
        return f0;
      }
      return subsetFit(u);
    };
    fde = detectAndExclude(use, fitFn, cfg.faultExclusion);
  }
  for (int i : fde.excluded) {
    sol.satellites[meas[i].result].use = SatelliteUse::Excluded;
    sol.excluded.push_back(meas[i].sat);
  }
  x = xConv;
  clk = clkConv;
  ion = ionConv;
  colSystems = colsConv;
  if (!fde.excluded.empty()) {
    // Final solution on the remaining measurements with the full models.
    last = iterate(use, true, std::max(cfg.maxIterations, 4), x, clk, ion);
    if (!last.ok) {
      sol.status = statusForFailure(last);
      return false;
    }
  } else {
    // `last` holds the statistics at x for the active set `use` (nothing changed since: the
    // exclusion fits froze the models); only the clock columns are restored.
    assignColumns(use);
  }
  return true;
}

void SppSolver::Fit::reweight() {
  // Robust re-weighting (IGG-III, Yang et al. 2002, J. Geodesy 76: equivalent weights from
  // standardised residuals): measurements that disagree with the rest by more than k0 robust
  // scales lose weight progressively, beyond k1 almost all of it. The scale is the median
  // absolute standardised residual (x 1.4826), floored so that consistent data keep full weight.
  const RobustEstimation& rb = cfg.robust;
  if (rb.enabled && sol.dof >= 2) {
    for (int it = 0; it < rb.maxIterations; ++it) {
      std::vector<double> u;
      for (int i = 0; i < n; ++i) {
        if (use[i]) u.push_back(last.normResidual[i] * std::sqrt(meas[i].inflation));
      }
      std::nth_element(u.begin(), u.begin() + static_cast<long>(u.size() / 2), u.end());
      const double scale = std::max(1.4826 * u[u.size() / 2], rb.minScale);
      const double k0 = sol.testPassed ? rb.k0 : rb.k0Failed, k1 = sol.testPassed ? rb.k1 : rb.k1Failed;
      bool changed = false;
      for (int i = 0; i < n; ++i) {
        if (!use[i]) continue;
        const double z = last.normResidual[i] * std::sqrt(meas[i].inflation) / scale;
        double w = 1.0;
        if (z > k1) w = 1e-4;
        else if (z > k0) w = std::max(1e-4, k0 / z * std::pow((k1 - z) / (k1 - k0), 2));
        const double infl = 1.0 / w;
        if (std::abs(infl - meas[i].inflation) > 0.05 * meas[i].inflation) changed = true;
        meas[i].variance *= infl / meas[i].inflation;
        meas[i].inflation = infl;
      }
      if (!changed) break;
      // The geometry moves by far less than a metre between passes: one Gauss-Newton step from
      // the current point is converged, and its post-fit residuals drive the next pass.
      const LsqResult rr = lsqStep(x, clk, ion, use, true);
      if (!rr.ok) break;
      const int ncol = static_cast<int>(colSystems.size());
      x += rr.x.head<3>();
      clk += rr.x.segment(3, ncol);
      if (estIono) ion += rr.x[3 + ncol];
      ++sol.iterations;
      last = rr;
    }
  }
}

bool SppSolver::Fit::writeSolution() {
  // Outputs. The reported covariance is scaled by the a-posteriori variance factor of the
  // residual test's statistic (after fault exclusion, before the robust weights, which shrink it
  // by down-weighting the very residuals that show the weights to be optimistic;
  // CovarianceScaling); the inter-system bias priors below keep the a-priori covariance.
  sol.position = x;
  const CovarianceScaling& cs = cfg.covarianceScaling;
  if (cs.enabled) {
    const double k = sol.dof >= 1 ? (sol.chi2 + cs.priorDof) / (sol.dof + cs.priorDof) : 1.0;
    sol.varianceFactor = std::max(k, 1.0);
  }
  sol.positionCovariance = sol.varianceFactor * last.cov.topLeftCorner<3, 3>();
  for (std::size_t c = 0; c < colSystems.size(); ++c) {
    sol.clockBias[colSystems[c]] = clk[static_cast<int>(c)];
    sol.clockBiasVariance[colSystems[c]] = sol.varianceFactor * last.cov(3 + static_cast<int>(c), 3 + static_cast<int>(c));
  }
  const int gi = systemIndex(System::Gps), ji = systemIndex(System::Qzss);
  if (cfg.qzssUsesGpsClock && sol.clockBias[gi]) {
    sol.clockBias[ji] = sol.clockBias[gi];
    sol.clockBiasVariance[ji] = sol.clockBiasVariance[gi];
  }
  if (estIono) sol.ionosphereCorrection = ion;
  const int ref = referenceSystem(use);
  if (col[ref] >= 0) sol.solutionTime = epoch.time - clk[col[ref]] / kC;
  std::vector<Eigen::Vector3d> losEnu;
  std::vector<int> clockIdx;
  const Geodetic g = ecefToGeodetic(x);
  const Eigen::Matrix3d rEnu = ecefToEnuRotation(g.lat, g.lon);
  for (int i = 0; i < n; ++i) {
    SatelliteResidual& out = sol.satellites[meas[i].result];
    const Measurement& m = meas[i];
    out.azel = m.azel;
    out.sigma = std::sqrt(m.variance / m.inflation);
    out.weightFactor = 1.0 / m.inflation;
    const double rho = geometricRange(m.state.position, x);
    const double c = col[m.sys] >= 0 ? clk[col[m.sys]] : 0.0;
    out.residual = m.pseudorange - (rho + c - kC * m.satClock + m.iono + m.ionoMap * ion + m.tropo);
    if (!use[i]) continue;
    out.use = SatelliteUse::Used;
    ++sol.numSatellites;
    losEnu.push_back(rEnu * (m.state.position - x).normalized());
    clockIdx.push_back(col[m.sys]);
  }
  if (cfg.reportedError.enabled) reportCovariance();
  sol.dop = computeDop(losEnu, clockIdx, static_cast<int>(colSystems.size()));
  if (!sol.dop.valid || sol.dop.gdop > cfg.maxGdop) {
    sol.status = SppStatus::GdopTooLarge;
    return false;
  }
  sol.status = sol.testPassed ? SppStatus::Ok : SppStatus::TestFailed;
  return true;
}

void SppSolver::Fit::solveVelocity() {
  std::vector<RangeRateMeasurement> rr;
  for (int i = 0; i < n; ++i) {
    const Measurement& m = meas[i];
    if (!use[i] || !m.hasDoppler) continue;
    RangeRateMeasurement d;
    d.sat = m.sat;
    d.satPosition = m.state.position;
    d.satVelocity = m.state.velocity;
    d.satClockDrift = m.state.clockDrift;
    d.rangeRate = m.rangeRate;
    d.variance = cfg.weighting.dopplerVariance(m.sat.system, m.azel.elevation, m.snr);
    rr.push_back(d);
  }
  if (rr.size() >= 4) sol.velocity = solveDopplerVelocity(rr, x, cfg.faultExclusion);
}

SppSolution SppSolver::solve(const ObsEpoch& epoch) {
  SppSolution sol;
  sol.time = epoch.time;
  sol.solutionTime = epoch.time;
  const SppConfig& cfg = config_;
  std::vector<Measurement> meas;
  meas.reserve(epoch.sats.size());
  if (!gatherMeasurements(epoch, sol, meas)) {
    sol.status = SppStatus::NoObservations;
    return sol;
  }
  const int n = static_cast<int>(meas.size());
  Fit fit(*this, epoch, meas, sol);

  // Starting point: last solution within 10 minutes, else the a-priori position, else the centre.
  Eigen::Vector3d x0 = Eigen::Vector3d::Zero();
  if (last_ && std::abs(epoch.time - lastTime_) < 600.0) x0 = *last_;
  else if (initial_) x0 = *initial_;

  fit.x = x0;
  fit.use.assign(n, 1);
  const int maxIter = std::max(cfg.maxIterations, 4) + (nearSurface(x0) ? 0 : 8);
  fit.last = fit.iterate(fit.use, true, maxIter, fit.x, fit.clk, fit.ion);
  if (!fit.last.ok) {
    sol.status = statusForFailure(fit.last);
    for (int i = 0; i < n; ++i) {
      if (!meas[i].active) sol.satellites[meas[i].result].use = SatelliteUse::BelowMask;
    }
    return sol;
  }
  for (int i = 0; i < n; ++i) {
    if (!fit.use[i] && !meas[i].active) sol.satellites[meas[i].result].use = SatelliteUse::BelowMask;
  }
  if (!fit.excludeFaults()) return sol;
  sol.chi2 = fit.last.chi2;
  sol.dof = fit.last.nObs - fit.last.nUnknowns;
  sol.testPassed = sol.dof < 1 || sol.chi2 <= globalTestThreshold(sol.dof, cfg.faultExclusion.falseAlarmProbability);
  fit.keepPriorResiduals();
  fit.reweight();
  if (!fit.writeSolution()) return sol;

  // Inter-system biases for the next epochs (from epochs that pass the test, relative to GPS).
  if (sol.testPassed) {
    Eigen::MatrixXd cov = fit.last.cov;
    updateIsb(sol, cov, fit.colSystems);
  }
  last_ = fit.x;
  lastTime_ = epoch.time;

  // Doppler velocity.
  if (cfg.velocity) fit.solveVelocity();
  return sol;
}

bool SppSolver::Fit::excludedByFde(int i) const {
  return !use[i] && sol.satellites[meas[i].result].use == SatelliteUse::Excluded && col[meas[i].sys] >= 0;
}

void SppSolver::Fit::keepPriorResiduals() {
  ionBeforeRobust = ion;
  for (int i = 0; i < n; ++i) {
    Measurement& m = meas[i];
    if (!use[i] && !excludedByFde(i)) continue;
    const double pred = geometricRange(m.state.position, x) + clk[col[m.sys]] - kC * m.satClock + m.iono +
                        m.ionoMap * ion + m.tropo;
    m.priorResidual = m.pseudorange - pred;
  }
}

void SppSolver::Fit::reportCovariance() {
  const int nc = static_cast<int>(colSystems.size());
  const int nu = static_cast<int>(last.cov.rows());
  const ReportedErrorModel& re = cfg.reportedError;
  detail::ReportedInputs in;
  in.q = last.cov;
  for (int i = 0; i < n; ++i) {
    if (!use[i] && !excludedByFde(i)) continue;
    const Measurement& m = meas[i];
    detail::ReportedRow row;
    row.excluded = !use[i];
    row.h = Eigen::VectorXd::Zero(nu);
    row.h.head<3>() = -(m.state.position - x).normalized();
    row.h[3 + col[m.sys]] = 1.0;
    if (estIono) row.h[3 + nc] = m.ionoMap;
    row.weight = 1.0 / m.variance;
    row.priorWeight = 1.0 / (m.variance / m.inflation);
    row.independentVariance = re.noiseScale * re.noiseScale * m.noiseVariance + m.ephemerisVariance;
    row.ionosphereSigma = m.ionosphereSigma;
    row.piercePoint = m.piercePoint;
    row.troposphereMap = m.troposphereMap;
    row.residual = m.priorResidual;
    in.rows.push_back(std::move(row));
  }
  if (estIono) {
    in.ionosphereColumn = 3 + nc;
    in.ionosphereCorrection = ionBeforeRobust;
    in.ionospherePriorWeight = 1.0 / ionoPriorVar;
  }
  in.troposphereZenithSigma = cfg.troposphereZenithError;
  in.ionosphereCorrelationLength = re.ionosphereCorrelationLength;
  in.dof = sol.dof;
  in.minVarianceFactor = re.minVarianceFactor;
  in.excessCorrelation = re.excessCorrelation;
  const detail::ReportedCovariance rc = detail::reportedCovariance(in, cfg.covarianceScaling);
  sol.varianceFactor = rc.varianceFactor;
  sol.positionCovariance = rc.covariance.topLeftCorner<3, 3>();
  for (int c = 0; c < nc; ++c) sol.clockBiasVariance[colSystems[c]] = rc.covariance(3 + c, 3 + c);
  const int gi = systemIndex(System::Gps), ji = systemIndex(System::Qzss);
  if (cfg.qzssUsesGpsClock && sol.clockBias[gi]) sol.clockBiasVariance[ji] = sol.clockBiasVariance[gi];
}

void SppSolver::updateIsb(const SppSolution& sol, const Eigen::MatrixXd& cov, const std::vector<int>& clockSystems) {
  const int g = systemIndex(System::Gps);
  int cg = -1;
  for (std::size_t c = 0; c < clockSystems.size(); ++c) {
    if (clockSystems[c] == g) cg = static_cast<int>(c);
  }
  if (cg < 0) return;
  for (std::size_t c = 0; c < clockSystems.size(); ++c) {
    const int s = clockSystems[c];
    if (s == g) continue;
    const int i = 3 + static_cast<int>(c), j = 3 + cg;
    Isb& b = isb_[s];
    b.known = true;
    b.value = *sol.clockBias[s] - *sol.clockBias[g];
    b.variance = std::max(cov(i, i) + cov(j, j) - 2.0 * cov(i, j), 0.0);
    b.time = sol.time;
  }
}

}  // namespace gvins
