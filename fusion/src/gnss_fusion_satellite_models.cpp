// The fusion's per-satellite models of a rover epoch (the shared gnss observation model plus
// the fusion's weights and band choice) and the receiver clocks started from their residuals.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "gvins/base/constants.hpp"
#include "gvins/fusion/gnss_clock_init.hpp"
#include "gvins/fusion/gnss_fusion.hpp"
#include "gvins/gnss/ionosphere_free.hpp"
#include "gvins/gnss/measurement_weighting.hpp"
#include "gvins/gnss/satellite_observation_model.hpp"
#include "gvins/gnss/signal_choice.hpp"
#include "gvins/gnss/zero_difference.hpp"

namespace gvins::fusion {
namespace {

constexpr double kC = constants::kSpeedOfLight;

/// The code noise model of the shared weighting (measurement_weighting.hpp) at zenith sigma
/// `sigma` split evenly: `elevation` weighting, sigma² (½ + ½ / sin² el); `elevation-cn0`, the
/// elevation + C/N0 model (falls back to the elevation model without a C/N0). No system factor:
/// the ephemeris error carries the system's part here.
MeasurementWeighting codeWeighting(const GnssFusionConfig& c, double sigma) {
  return MeasurementWeighting::evenSplit(
      c.codeWeighting == GnssCodeWeighting::kElevationCn0 ? WeightingScheme::ElevationSnr : WeightingScheme::Elevation,
      sigma);
}

/// C/N0 of a signal, dB-Hz (0 unknown).
double cn0Of(const SignalObs& s) { return s.hasSnr() ? s.snr : 0.0; }

}  // namespace

template <typename Scalar>
int GnssFusion<Scalar>::clockIndex(SatId sat) const {
  return clocks_.index(sat);
}

template <typename Scalar>
std::vector<SatelliteModel> GnssFusion<Scalar>::satelliteModels(const ObsEpoch& rover, const EphemerisStore& nav,
                                                                 const Eigen::Vector3d& x, TransmitStates* states) const {
  std::vector<SatelliteModel> out;
  // The shared per-satellite model (satellite_observation_model.hpp): standard-atmosphere
  // troposphere, the broadcast ionosphere where asked for, the Shapiro delay, the phase wind-up
  // (vio+dopp+ppp).
  ObservationModelOptions options;
  options.broadcastIonosphere = true;
  options.shapiro = true;
  const SatelliteObservationModel model(x, rover.time, options, &nav.ionosphere());
  for (const SatObs& so : rover.sats) {
    if (!so.sat.valid() || !config_.useSystem(so.sat.system)) continue;
    std::optional<int> channel;
    if (so.sat.system == System::Glonass) channel = nav.glonassChannels().get(so.sat.prn);
    // The system's primary band, else the next tracked one (signal_choice.hpp: the band order of
    // `bands` after the primary band, then the system's fallback order), noticed once.
    const std::string& order = config_.bands[static_cast<std::size_t>(systemIndex(so.sat.system))];
    const char preferred = primaryBand(so.sat.system);
    const auto primary = primaryCode(so, std::string(1, preferred) + order, 1, channel);
    if (!primary) continue;
    const SignalObs* s = primary->signal;
    const char band = s->code.band;
    signalNotices_.record(so.sat.system, preferred, s->code);
    const std::optional<double> f = primary->frequency;
    const auto tx = transmitState(states, nav, so.sat, rover.time, s->pseudorange);
    if (!tx) continue;
    SatelliteModel m;
    m.sat = so.sat;
    m.code = s->code;
    m.clock = clockIndex(so.sat);
    m.transmitTime = tx->transmitTime;
    m.position = tx->state.position;
    m.velocity = tx->state.velocity;
    m.clockBias = tx->state.clockBias;
    m.clockDrift = tx->state.clockDrift;
    m.precise = tx->state.precise;
    m.ssr = tx->state.ssr;
    m.groupDelay = transmitGroupDelay(nav, *tx, so.sat, s->code);
    m.wavelength = kC / *f;
    m.azel = model.azimuthElevation(m.position);
    if (m.azel.elevation < config_.elevationMaskDeg * constants::kDegToRad) continue;
    // The broadcast ionosphere is asked for (frequency) only where it is used: single frequency.
    const bool singleFrequency = config_.ionosphere != GnssIonosphere::kDualFrequency;
    const SatelliteModelTerms terms = model.terms(m.position, m.azel, so.sat.system, singleFrequency ? *f : 0.0);
    m.troposphere = terms.troposphere.slant;
    m.mapWet = terms.troposphere.mapWet;
    m.shapiro = terms.shapiro;
    m.pseudorange = s->pseudorange;
    m.cn0 = cn0Of(*s);
    const double sinEl = std::max(std::sin(m.azel.elevation), 0.1);
    // Code variance (below: single frequency after the pair search, the pair inside it): white
    // noise and multipath growing with 1/sin(el), and the ephemeris error.
    // Broadcast orbit/clock error (SISRE) of the system: a bias per satellite, in the variance so
    // that systems with poorer broadcast products weigh less.
    // Precise products (SP3/RINEX clock) or SSR corrections where the store has them: centimetres
    // instead.
    // SSR-corrected states (real-time streams) count as precise: their orbit/clock error is that
    // of real-time products, a few centimetres.
    const auto& ephemerisError =
        tx->state.precise || tx->state.ssr ? config_.preciseEphemerisError : config_.ephemerisError;
    const double ephemerisVariance = std::pow(ephemerisError[static_cast<std::size_t>(systemIndex(so.sat.system))], 2);
    m.ephemerisVariance = ephemerisVariance;
    // Carrier-smoothed code: noise and multipath averaged over the arc (CarrierSmoother), down
    // to `smoothed_code_factor` of the raw sigma.
    const double smoothingFactor =
        smoother_ ? std::max(config_.smoothedCodeFactor, smoother_->noiseFactor(so.sat)) : 1.0;
    const MeasurementWeighting weighting = codeWeighting(config_, config_.codeSigma * smoothingFactor);
    // Dual frequency: the ionosphere-free pair with the first other band tracked (`bands`: the
    // SPP band order; secondCode: GPS/QZSS L2C, L5, then L2 P(Y)), group delays combined alike;
    // its noise is a1² var(P1) + a2² var(P2), each band with its own C/N0 (the SPP's combination
    // variance; 2.98² times one band's for L1/L2 at equal C/N0), and it carries no ionospheric
    // model error.
    if (config_.ionosphere == GnssIonosphere::kDualFrequency) {
      if (const auto second = secondCode(so, order, order.size(), band, channel)) {
        const SignalObs* s2 = second->signal;
        const double* f2 = &second->frequency;
        const char b2 = s2->code.band;
        const IonosphereFreeCoefficients c = ionosphereFreeCoefficients(*f, *f2);
        m.pseudorange = c.a1 * s->pseudorange + c.a2 * s2->pseudorange;
        m.groupDelay = c.a1 * m.groupDelay + c.a2 * transmitGroupDelay(nav, *tx, so.sat, s2->code);
        m.ionosphere = 0.0;
        m.ionosphereFree = true;
        m.code2 = s2->code;
        m.ifA1 = c.a1;
        m.ifA2 = c.a2;
        const double cn02 = cn0Of(*s2);
        m.codeVariance =
            weighting.combinationCodeVariance(so.sat.system, m.azel.elevation, c.a1, m.cn0, c.a2, cn02) +
            ephemerisVariance;
        // The pair's C/N0 (the C/N0 mask): the lower of the two bands where both are known.
        if (cn02 > 0.0 && (m.cn0 <= 0.0 || cn02 < m.cn0)) m.cn0 = cn02;
        // vio+dopp+ppp: the ionosphere-free phase of the same bands (the phase of another
        // tracking mode on a band only shifts the float ambiguity).
        if (config_.mode == GnssFusionMode::kDoppPpp) {
          const SignalObs* p1 = so.bestOnBand(band, SignalObs::kPhase);
          const SignalObs* p2 = so.bestOnBand(b2, SignalObs::kPhase);
          if (p1 && p2 && p1->carrierPhase != 0.0 && p2->carrierPhase != 0.0) {
            m.hasCarrier = true;
            m.carrierRange = c.a1 * (kC / *f) * p1->carrierPhase + c.a2 * (kC / *f2) * p2->carrierPhase;
            m.phaseVariance = std::pow(config_.phaseSigma * c.noiseFactor(), 2) * (0.5 + 0.5 / (sinEl * sinEl));
            m.windupWavelength = c.a1 * (kC / *f) + c.a2 * (kC / *f2);
            if (config_.phaseWindup) m.windup = model.phaseWindup(m.position);
          }
        }
      }
    }
    if (!m.ionosphereFree) {
      // Single frequency (broadcast ionosphere, or no second band tracked): the broadcast model,
      // evaluated only here (an ionosphere-free pair needs none), and 30 % of it in the code
      // variance (Klobuchar corrects about half of the delay; IS-GPS-200N 20.3.3.5.2.5).
      m.ionosphere = singleFrequency ? terms.ionosphere.slant : model.ionosphere(so.sat.system, m.azel, *f).slant;
      m.codeVariance = weighting.codeVariance(so.sat.system, m.azel.elevation, m.cn0) +
                       std::pow(0.3 * m.ionosphere, 2) + ephemerisVariance;
    }
    m.dopplerVariance = std::pow(config_.dopplerSigma, 2) * (0.5 + 0.5 / (sinEl * sinEl));
    const SignalObs* d = s->hasDoppler() ? s : nullptr;
    if (d && std::abs(d->doppler) < 1e5) {
      m.hasDoppler = true;
      m.rangeRate = -m.wavelength * d->doppler;
    }
    out.push_back(m);
  }
  return out;
}

template <typename Scalar>
bool GnssFusion<Scalar>::initClocks(vio::EstimatorBackend<Scalar>& est, const std::vector<SatelliteModel>& models,
                                    const AntennaKinematics& k, const GpsTime& t) {
  std::vector<SatId> sats;
  for (const SatelliteModel& m : models) sats.push_back(m.sat);
  if (!clocks_.setSystems(sats)) return false;
  const int n = static_cast<int>(clocks_.systems().size());
  std::vector<ClockRow> rows;
  for (const SatelliteModel& m : models) {
    // Residuals of the measurement models at zero receiver clock and drift.
    rows.push_back({clockIndex(m.sat), pseudorangeRow(m, k, 0.0).residual, config_.clockRansacThreshold});
    if (m.hasDoppler) rows.push_back({n, dopplerRow(m, k, 0.0).residual, std::max(0.5, 10.0 * config_.dopplerSigma)});
  }
  const ClockInitResult r = initializeClocksRansac(rows, n + 1, 64, 1, 7);
  if (r.inliers[static_cast<std::size_t>(n)] == 0) return false;  // no drift
  std::vector<double> x(static_cast<std::size_t>(n + 1)), sigma(x.size());
  for (int i = 0; i <= n; ++i) {
    const auto u = static_cast<std::size_t>(i);
    x[u] = r.x[u];
    // The antenna position error (SPP level after the frame initialisation) enters the bias.
    sigma[u] = i < n ? std::max(r.sigma[u], 5.0) : std::max(r.sigma[u], 0.3);
    if (r.inliers[u] == 0) sigma[u] = 1e3;
  }
  // The prior on the receiver clock and the inter-system biases (GnssClockStates::create).
  clocks_.create(est, x, sigma, t);
  return true;
}

template <typename Scalar>
void GnssFusion<Scalar>::addLateClockSystems(vio::EstimatorBackend<Scalar>& est, const std::vector<SatelliteModel>& models,
                                             const AntennaKinematics& k, const GpsTime& t) {
  // A system whose satellites had no ephemeris yet when the clocks started (a cold start
  // decoding its own navigation messages: BeiDou and Galileo records take 30 s or more) joins
  // with its inter-system bias from its code residuals at the current state, instead of never
  // contributing a pseudorange.
  std::vector<System> late;
  for (const SatelliteModel& m : models) {
    const System s = clockSystemOf(m.sat.system);
    if (clockIndex(m.sat) < 0 && std::find(late.begin(), late.end(), s) == late.end()) late.push_back(s);
  }
  for (const System s : late) {
    std::vector<double> b;  // c·dt_s implied by each satellite of s (residual at zero clock)
    for (const SatelliteModel& m : models)
      if (clockSystemOf(m.sat.system) == s) b.push_back(pseudorangeRow(m, k, 0.0).residual);
    if (static_cast<int>(b.size()) < config_.lateSystemMinSatellites) continue;
    std::sort(b.begin(), b.end());
    const double median = b[b.size() / 2];
    std::vector<double> dev;
    for (double x : b) dev.push_back(std::abs(x - median));
    std::sort(dev.begin(), dev.end());
    const double sigma = std::max(5.0, 1.4826 * dev[dev.size() / 2]);  // as initClocks: SPP-level position error
    const double isb = median - clocks_.values(est)[0];
    clocks_.addSystem(est, s, isb, sigma, t, config_);
    char buf[200];
    std::snprintf(buf, sizeof buf,
                  "GNSS clocks: %s joins late (%zu satellites; its ephemerides arrived after the clocks started), "
                  "inter-system bias %.1f m",
                  std::string(systemName(s)).c_str(), b.size(), isb);
    clockNotices_.emplace_back(buf);
  }
}

#define GVINS_INSTANTIATE(S)                                                                                  \
  template int GnssFusion<S>::clockIndex(SatId) const;                                                        \
  template std::vector<SatelliteModel> GnssFusion<S>::satelliteModels(const ObsEpoch&, const EphemerisStore&,  \
                                                                      const Eigen::Vector3d&, TransmitStates*) \
      const;                                                                                                   \
  template bool GnssFusion<S>::initClocks(vio::EstimatorBackend<S>&, const std::vector<SatelliteModel>&,       \
                                          const AntennaKinematics&, const GpsTime&);                            \
  template void GnssFusion<S>::addLateClockSystems(vio::EstimatorBackend<S>&, const std::vector<SatelliteModel>&, \
                                                   const AntennaKinematics&, const GpsTime&);
GVINS_INSTANTIATE(float)
GVINS_INSTANTIATE(double)
#undef GVINS_INSTANTIATE

}  // namespace gvins::fusion
