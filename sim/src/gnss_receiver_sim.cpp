#include "gvins/sim/gnss_receiver_sim.hpp"

#include <algorithm>
#include <cmath>

#include "gvins/base/constants.hpp"
#include "gvins/ephemeris/satellite_antenna.hpp"
#include "gvins/ephemeris/sun_position.hpp"
#include "gvins/gnss/phase_windup.hpp"
#include "gvins/gnss/sagnac.hpp"
#include "gvins/sim/gnss_atmosphere.hpp"

namespace gvins::sim {

const char* toString(GnssReceiverRole r) { return r == GnssReceiverRole::Rover ? "rover" : "base"; }

namespace {

constexpr double kC = constants::kSpeedOfLight;
// Earth's gravitational constant for the Shapiro delay (IERS Conventions 2010, table 1.1).
constexpr double kGmEarth = 3.986004418e14;
// Step of the finite differences that give the atmosphere's rates for the Doppler, s.
constexpr double kRateStep = 1.0;
// Half-interval of the central difference of the phase wind-up for the Doppler, s.
constexpr double kWindupStep = 0.05;

std::string systemLetters(const std::array<bool, kNumSystems>& s) {
  std::string out;
  for (int i = 0; i < kNumSystems; ++i)
    if (s[i]) out += systemLetter(static_cast<System>(i));
  return out;
}

// Light-time solution: satellite state at the true transmit time, rotated into the ECEF frame of
// reception, and the exact range rate.
struct Geometry {
  double tau = 0.0;
  GpsTime transmit;
  GnssSatelliteState sat;          // at the transmit time (ECEF of the transmit time)
  Eigen::Vector3d satRx = Eigen::Vector3d::Zero();     // position in the ECEF frame of reception
  Eigen::Vector3d satRxRate = Eigen::Vector3d::Zero(); // d(satRx)/dt
  double range = 0.0;
  double rangeRate = 0.0;
};

bool solveGeometry(const GnssConstellation& con, SatId sat, const GpsTime& t, const GnssAntennaState& rx,
                   double tauGuess, Geometry& g) {
  double tau = tauGuess;
  GpsTime tEval = t - tau;
  auto s = con.state(sat, tEval);
  if (!s) return false;
  Eigen::Vector3d p, rot;
  double dtx = 0.0;
  for (int it = 0; it < 12; ++it) {
    dtx = (t - tau) - tEval;
    if (std::fabs(dtx) > 1e-5) {  // far from the evaluated state: evaluate again
      tEval = t - tau;
      s = con.state(sat, tEval);
      if (!s) return false;
      dtx = 0.0;
    }
    p = s->position + s->velocity * dtx;
    rot = rotateEarth(p, tau);
    const double newTau = (rot - rx.position).norm() / kC;
    const bool converged = std::fabs(newTau - tau) < 1e-14;
    tau = newTau;
    if (converged) break;
  }
  dtx = (t - tau) - tEval;
  g.tau = tau;
  g.transmit = t - tau;
  g.sat = *s;
  g.sat.position = s->position + s->velocity * dtx;
  g.sat.broadcastPosition = s->broadcastPosition + s->velocity * dtx;
  g.sat.clock = s->clock + s->clockDrift * dtx;
  g.sat.broadcastClock = s->broadcastClock + s->clockDrift * dtx;
  g.satRx = rotateEarth(g.sat.position, tau);
  g.range = (g.satRx - rx.position).norm();
  // d/dt of R(omega tau) r_s(t - tau): A tau_dot + B (1 - tau_dot), with B = R v_s and
  // A = omega R'(omega tau) r_s; rho_dot = e.(B - v_r) / (1 - e.(A - B)/c).
  const double th = constants::kWgs84OmegaE * tau;
  const double c = std::cos(th), sn = std::sin(th);
  const Eigen::Vector3d& r = g.sat.position;
  const Eigen::Vector3d A = constants::kWgs84OmegaE * Eigen::Vector3d(-sn * r.x() + c * r.y(), -c * r.x() - sn * r.y(), 0.0);
  const Eigen::Vector3d B = rotateEarth(g.sat.velocity, tau);
  const Eigen::Vector3d e = (g.satRx - rx.position) / g.range;
  g.rangeRate = e.dot(B - rx.velocity) / (1.0 - e.dot(A - B) / kC);
  const double tauDot = g.rangeRate / kC;
  g.satRxRate = B + tauDot * (A - B);
  return true;
}

double shapiroDelay(const Eigen::Vector3d& sat, const Eigen::Vector3d& rx, double range) {
  const double rs = sat.norm(), rr = rx.norm();
  return 2.0 * kGmEarth / (kC * kC) * std::log((rs + rr + range) / (rs + rr - range));
}

}  // namespace

GnssReceiverSim::GnssReceiverSim(const GnssSimWorld& world, GnssReceiverRole role, GnssAntennaMotion motion)
    : world_(world),
      cfg_(world.config()),
      role_(role),
      rc_(role == GnssReceiverRole::Rover ? world.config().rover : world.config().base.receiver),
      motion_(std::move(motion)),
      clock_(rc_.clock, streamSeed(world.seed(), {0xC1, static_cast<std::uint64_t>(role)})),
      outageActive_(rc_.outages.size(), false) {
  // First tag: the first multiple of 1/rate at or after the start (receiver time).
  const GpsTime s = world.start();
  const double k0 = std::ceil(s.fraction() * rc_.rate - 1e-9);
  gridStart_ = GpsTime::fromSeconds(s.wholeSeconds(), 0.0) + k0 / rc_.rate;
  const auto& sats = world.constellation().satellites();
  sats_.resize(sats.size());
  for (std::size_t i = 0; i < sats.size(); ++i) {
    SatTrack& st = sats_[i];
    st.sat = sats[i];
    const std::uint64_t si = static_cast<std::uint64_t>(satIndex(st.sat));
    st.rng.reseed(streamSeed(world.seed(), {0xC2, static_cast<std::uint64_t>(role), si}));
    st.cn0Offset = st.rng.normal(rc_.cn0.satelliteSigma);
    for (const ObsCode& code : cfg_.signals[systemIndex(st.sat.system)]) {
      if (!cfg_.transmits(st.sat, code)) continue;
      SignalTrack sg;
      sg.code = code;
      sg.rng.reseed(streamSeed(world.seed(), {0xC3, static_cast<std::uint64_t>(role), si,
                                              static_cast<std::uint64_t>(code.band) * 256 + static_cast<std::uint64_t>(code.attr)}));
      st.signals.push_back(sg);
    }
  }
}

std::optional<GpsTime> GnssReceiverSim::peekTag() const {
  if (done_) return std::nullopt;
  const GpsTime tag = gridStart_ + static_cast<double>(k_) / rc_.rate;
  // The true time is within a few ms of the tag; past the end by more than that: finished.
  if (tag - world_.end() > 0.1) return std::nullopt;
  return tag;
}

std::optional<GnssSimEpoch> GnssReceiverSim::next() {
  while (!done_) {
    const GpsTime tag = gridStart_ + static_cast<double>(k_) / rc_.rate;
    if (tag - world_.end() > 0.1) {
      done_ = true;
      break;
    }
    ++k_;
    const GpsTime t = clock_.advanceToTag(tag);
    if (t < world_.start()) continue;
    if (world_.end() < t) {
      done_ = true;
      break;
    }
    GnssSimEpoch out;
    produce(tag, t, out);
    lastTag_ = tag;
    first_ = false;
    ++epochs_;
    return out;
  }
  return std::nullopt;
}

void GnssReceiverSim::loseSignal(SignalTrack& sg, const char* cause) {
  if (!sg.active) return;
  sg.active = false;
  sg.restartCause = cause;
}

void GnssReceiverSim::lose(SatTrack& st, const char* cause) {
  for (SignalTrack& sg : st.signals) loseSignal(sg, cause);
}

/// The stages of GnssReceiverSim::produce for one epoch: the receiver's truth and the epoch's
/// common quantities, then per satellite its events (what is received), its truth and its
/// signals. The random draws happen in a fixed order (the dataset of a seed never changes).
class GnssEpochProducer {
 public:
  using SatTrack = GnssReceiverSim::SatTrack;
  using SignalTrack = GnssReceiverSim::SignalTrack;

  GnssEpochProducer(GnssReceiverSim& rx, const GpsTime& tag, const GpsTime& t, GnssSimEpoch& out)
      : r_(rx), rc_(rx.rc_), cfg_(rx.cfg_), tag_(tag), t_(t), out_(out) {}

  void run() {
    receiverTruth();
    scheduledOutages();
    windupAxes();
    for (SatTrack& st : r_.sats_) satellite(st);
  }

 private:
  /// The path of one satellite's signal this epoch (path model and random NLOS).
  struct SatPath {
    double bias = 0.0, multipathScale = 1.0;
    bool nlos = false;  ///< reflected by the path model
  };
  /// Rates of the satellite-level terms, for the Doppler.
  struct SatRates {
    double troposphere = 0.0, ionosphereL1 = 0.0, windup = 0.0;  ///< m/s, m/s, cycles/s (true time)
  };

  void receiverTruth();
  void scheduledOutages();
  void windupAxes();
  void satellite(SatTrack& st);
  bool randomBlockage(SatTrack& st, const AzEl& azel);
  bool structurePath(SatTrack& st, const Geometry& g, SatPath& path);
  void randomNlos(SatTrack& st, const AzEl& azel);
  GnssSatelliteTruth satelliteTruth(SatTrack& st, const Geometry& g, const AzEl& azel, const SatPath& path,
                                    GnssAtmosphereDelays& atmo, SatRates& rates);
  bool signal(SatTrack& st, SignalTrack& sg, const Geometry& g, const GnssSatelliteTruth& satTruth,
              const GnssAtmosphereDelays& atmo, const SatRates& rates, const SatPath& path, SignalObs& so,
              GnssSignalTruth& sgt);
  bool track(SatTrack& st, SignalTrack& sg, double code, double phaseNoN, double lambda, double slipDraw,
             std::int64_t slipSize, bool slipNegative, bool slipFlagged, GnssSignalTruth& sgt);

  GnssReceiverSim& r_;
  const GnssReceiverConfig& rc_;
  const GnssSimConfig& cfg_;
  GpsTime tag_, t_;
  GnssSimEpoch& out_;
  // The epoch's common quantities.
  GnssAntennaState rx_, rxAhead_;
  Geodetic rxGeo_, rxGeoAhead_;
  GpsTime tAhead_;
  double dt_ = 0.0, flight_ = 0.0, mask_ = 0.0;
  std::array<bool, kNumSystems> outSys_{};
  // Phase wind-up: Sun for the satellites' yaw steering; the antenna's axes (level x north, y west
  // when the motion gives none) and the antenna ±kWindupStep around t, for the wind-up rate in the
  // Doppler (central difference).
  Eigen::Vector3d sun_ = Eigen::Vector3d::Zero();
  Eigen::Matrix3d rxAxes_;
  GnssAntennaState rxBefore_, rxAfter_;
};

void GnssEpochProducer::receiverTruth() {
  out_.role = r_.role_;
  ObsEpoch& obs = out_.obs;
  GnssReceiverTruth& tr = out_.truth;
  obs.time = tag_;
  if (rc_.clock.reportOffset) obs.receiverClockOffset = r_.clock_.reportedOffset();
  tr.tag = tag_;
  tr.time = t_;
  tr.clockBias = r_.clock_.bias();
  tr.clockDrift = r_.clock_.drift();
  for (int s = 0; s < kNumSystems; ++s) tr.systemClockBias[s] = r_.clock_.systemBias(static_cast<System>(s));

  rx_ = r_.motion_(t_);
  tr.antennaPosition = rx_.position;
  tr.antennaVelocity = rx_.velocity;
  rxGeo_ = ecefToGeodetic(rx_.position);
  rxAhead_ = GnssAntennaState{rx_.position + rx_.velocity * kRateStep, rx_.velocity};
  rxGeoAhead_ = ecefToGeodetic(rxAhead_.position);
  tAhead_ = t_ + kRateStep;
  dt_ = r_.first_ ? 0.0 : tag_ - r_.lastTag_;
  flight_ = t_ - r_.world_.start();
  mask_ = rc_.elevationMaskDeg * constants::kDegToRad;
}

void GnssEpochProducer::scheduledOutages() {
  for (std::size_t i = 0; i < rc_.outages.size(); ++i) {
    const GnssOutage& o = rc_.outages[i];
    const bool on = flight_ >= o.start && flight_ < o.start + o.duration;
    if (on)
      for (int s = 0; s < kNumSystems; ++s) outSys_[s] = outSys_[s] || o.systems[s];
    r_.outageActive_[i] = on;
  }
}

void GnssEpochProducer::windupAxes() {
  rxAxes_ = rx_.axes;
  if (!cfg_.phaseWindup) return;
  sun_ = sunPositionEcef(t_);
  if (rxAxes_.isZero(0.0)) rxAxes_ = levelAntennaAxes(rxGeo_.lat, rxGeo_.lon);
  rxBefore_ = r_.motion_(t_ - kWindupStep);
  rxAfter_ = r_.motion_(t_ + kWindupStep);
  for (GnssAntennaState* a : {&rxBefore_, &rxAfter_}) {
    if (a->axes.isZero(0.0)) {
      const Geodetic ga = ecefToGeodetic(a->position);
      a->axes = levelAntennaAxes(ga.lat, ga.lon);
    }
  }
}

void GnssEpochProducer::satellite(SatTrack& st) {
  const SatId sat = st.sat;
  Geometry g;
  if (!solveGeometry(r_.world_.constellation(), sat, t_, rx_, st.tauValid ? st.tau : 0.075, g)) {
    GnssReceiverSim::lose(st, nullptr);
    st.tauValid = false;
    return;
  }
  st.tau = g.tau;
  st.tauValid = true;
  const AzEl azel = azimuthElevation(rxGeo_, rx_.position, g.satRx);
  if (azel.elevation < mask_) {
    GnssReceiverSim::lose(st, nullptr);
    st.pathState = 0;  // an open path event ended at the last epoch above the mask
    st.pathEvent = -1;
    return;
  }
  if (randomBlockage(st, azel)) {
    GnssReceiverSim::lose(st, "blockage");
    return;
  }
  if (outSys_[systemIndex(sat.system)]) {
    GnssReceiverSim::lose(st, "outage");
    return;
  }
  SatPath path;
  if (!structurePath(st, g, path)) return;
  randomNlos(st, azel);

  GnssAtmosphereDelays atmo;
  SatRates rates;
  GnssSatelliteTruth satTruth = satelliteTruth(st, g, azel, path, atmo, rates);
  SatObs satObs;
  satObs.sat = sat;
  for (SignalTrack& sg : st.signals) {
    SignalObs so;
    GnssSignalTruth sgt;
    if (!signal(st, sg, g, satTruth, atmo, rates, path, so, sgt)) continue;
    satObs.signals.push_back(so);
    satTruth.signals.push_back(sgt);
  }
  if (satObs.signals.empty()) return;
  out_.obs.sats.push_back(std::move(satObs));
  out_.truth.sats.push_back(std::move(satTruth));
}

/// Random blockage of a low satellite (events "blockage"); true while it lasts.
bool GnssEpochProducer::randomBlockage(SatTrack& st, const AzEl& azel) {
  const double rateFactor = dt_ / 60.0;
  if (st.blocked && !(t_ < st.blockEnd)) {
    st.blocked = false;
    r_.events_[static_cast<std::size_t>(st.blockEvent)].end = t_;
  } else if (!st.blocked && dt_ > 0.0 && rc_.blockage.ratePerMinute > 0.0 &&
             azel.elevation < rc_.blockage.maxElevationDeg * constants::kDegToRad &&
             st.rng.bernoulli(1.0 - std::exp(-rc_.blockage.ratePerMinute * rateFactor))) {
    st.blocked = true;
    st.blockEnd = t_ + std::max(st.rng.exponential(rc_.blockage.meanDuration), 0.5 * dt_);
    st.blockEvent = static_cast<int>(r_.events_.size());
    r_.events_.push_back({r_.role_, "blockage", st.sat, "", t_, st.blockEnd, 0.0});
  }
  return st.blocked;
}

/// Structure between the antenna and the satellite (path model): false when it blocks the
/// satellite; a change of path restarts the carrier and opens or closes an event.
bool GnssEpochProducer::structurePath(SatTrack& st, const Geometry& g, SatPath& path) {
  if (!r_.pathModel_) return true;
  const UrbanSignalPath sp = r_.pathModel_(rx_.position, (g.satRx - rx_.position) / g.range);
  const int state = sp.kind == UrbanSignalPath::Kind::Blocked ? 2 : sp.kind == UrbanSignalPath::Kind::Reflected ? 1 : 0;
  if (state != st.pathState) {
    if (st.pathEvent >= 0) r_.events_[static_cast<std::size_t>(st.pathEvent)].end = t_;
    st.pathEvent = -1;
    if (state != 0) {
      st.pathEvent = static_cast<int>(r_.events_.size());
      r_.events_.push_back({r_.role_, state == 2 ? "blockage" : "nlos", st.sat, "", t_, t_, state == 1 ? sp.extraPath : 0.0});
    }
    GnssReceiverSim::lose(st, state == 2 ? "blockage" : "nlos");
    st.pathState = state;
  } else if (st.pathEvent >= 0) {
    r_.events_[static_cast<std::size_t>(st.pathEvent)].end = t_;
  }
  if (state == 2) return false;
  path.nlos = state == 1;
  path.bias = sp.extraPath;
  path.multipathScale = sp.multipathScale;
  return true;
}

/// Random non-line-of-sight reception of a low satellite (events "nlos"): a range bias while it
/// lasts; the carrier loop loses lock when the direct path goes or comes back.
void GnssEpochProducer::randomNlos(SatTrack& st, const AzEl& azel) {
  const double rateFactor = dt_ / 60.0;
  bool nlosChange = false;
  if (st.nlos && !(t_ < st.nlosEnd)) {
    st.nlos = false;
    st.nlosBias = 0.0;
    r_.events_[static_cast<std::size_t>(st.nlosEvent)].end = t_;
    nlosChange = true;
  } else if (!st.nlos && dt_ > 0.0 && rc_.nlos.ratePerMinute > 0.0 &&
             azel.elevation < rc_.nlos.maxElevationDeg * constants::kDegToRad &&
             st.rng.bernoulli(1.0 - std::exp(-rc_.nlos.ratePerMinute * rateFactor))) {
    st.nlos = true;
    st.nlosEnd = t_ + std::max(st.rng.exponential(rc_.nlos.meanDuration), 0.5 * dt_);
    st.nlosBias = st.rng.uniform(rc_.nlos.biasMin, rc_.nlos.biasMax);
    st.nlosEvent = static_cast<int>(r_.events_.size());
    r_.events_.push_back({r_.role_, "nlos", st.sat, "", t_, st.nlosEnd, st.nlosBias});
    nlosChange = true;
  }
  if (nlosChange) GnssReceiverSim::lose(st, "nlos");
}

/// The satellite's truth: geometry, atmosphere and its rate (forward difference over kRateStep
/// along the predicted geometry), NLOS bias, phase wind-up and its rate.
GnssSatelliteTruth GnssEpochProducer::satelliteTruth(SatTrack& st, const Geometry& g, const AzEl& azel,
                                                     const SatPath& path, GnssAtmosphereDelays& atmo, SatRates& rates) {
  const GnssAtmosphere& atm = r_.world_.atmosphere();
  atmo = atm.delays(rxGeo_, rx_.position, azel, t_);
  const Eigen::Vector3d satAhead = g.satRx + g.satRxRate * kRateStep;
  const AzEl azelAhead = azimuthElevation(rxGeoAhead_, rxAhead_.position, satAhead);
  const GnssAtmosphereDelays atmoAhead = atm.delays(rxGeoAhead_, rxAhead_.position, azelAhead, tAhead_);
  rates.troposphere = (atmoAhead.troposphere - atmo.troposphere) / kRateStep;
  rates.ionosphereL1 = (atmoAhead.ionosphereL1 - atmo.ionosphereL1) / kRateStep;

  GnssSatelliteTruth satTruth;
  satTruth.sat = st.sat;
  satTruth.transmitTime = g.transmit;
  satTruth.satPosition = g.sat.position;
  satTruth.satVelocity = g.sat.velocity;
  satTruth.satClock = g.sat.clock;
  satTruth.satClockDrift = g.sat.clockDrift;
  satTruth.broadcastClock = g.sat.broadcastClock;
  satTruth.orbitError = g.sat.orbitError;
  satTruth.clockError = g.sat.clockError;
  satTruth.range = g.range;
  satTruth.rangeRate = g.rangeRate;
  satTruth.shapiro = cfg_.shapiroDelay ? shapiroDelay(g.sat.position, rx_.position, g.range) : 0.0;
  satTruth.azel = azel;
  satTruth.troposphere = atmo.troposphere;
  satTruth.troposphereModel = atmo.troposphereModel;
  satTruth.troposphereRate = rates.troposphere;
  satTruth.ionosphereL1 = atmo.ionosphereL1;
  satTruth.ionosphereModelL1 = atmo.ionosphereModelL1;
  satTruth.ionosphereL1Rate = rates.ionosphereL1;
  satTruth.nlosBias = st.nlos ? st.nlosBias : 0.0;
  if (path.nlos) satTruth.nlosBias += path.bias;
  if (cfg_.phaseWindup) {
    const Eigen::Matrix3d satAxes = yawSteeringAxes(g.satRx, sun_);
    st.windup = phaseWindupCycles(g.satRx, rx_.position, satAxes, rxAxes_, st.windup);
    satTruth.windup = *st.windup;
    // d/dt of the wind-up over ±kWindupStep of the antenna's motion and the satellite's (its
    // yaw-steering axes change far more slowly than a vehicle turns; held).
    const Eigen::Vector3d ds = g.sat.velocity * kWindupStep;
    const double w0 = phaseWindupCycles(g.satRx - ds, rxBefore_.position, satAxes, rxBefore_.axes, st.windup);
    const double w1 = phaseWindupCycles(g.satRx + ds, rxAfter_.position, satAxes, rxAfter_.axes, st.windup);
    rates.windup = (w1 - w0) / (2.0 * kWindupStep);
  }
  return satTruth;
}

/// One signal: C/N0, multipath, noise, tracking (arcs, slips) and the observation; false when
/// it is not tracked (no frequency, C/N0 below the minimum).
bool GnssEpochProducer::signal(SatTrack& st, SignalTrack& sg, const Geometry& g, const GnssSatelliteTruth& satTruth,
                               const GnssAtmosphereDelays& atmo, const SatRates& rates, const SatPath& path,
                               SignalObs& so, GnssSignalTruth& sgt) {
  const SatId sat = st.sat;
  const GnssConstellation& con = r_.world_.constellation();
  const std::optional<int> channel = con.glonassChannel(sat);
  const auto freq = carrierFrequency(sat.system, sg.code.band, channel);
  if (!freq) return false;
  const double lambda = kC / *freq;
  const double sinEl = std::sin(satTruth.azel.elevation);
  const double elFactor = 1.0 / std::max(sinEl, 0.1);
  // C/N0.
  const double oneMinus = 1.0 - sinEl;
  double cn0 = rc_.cn0.zenith - (rc_.cn0.zenith - rc_.cn0.horizon) * oneMinus * oneMinus +
               cfg_.cn0Offset(sat.system, sg.code) + st.cn0Offset + sg.rng.normal(rc_.cn0.noise);
  if (st.nlos) cn0 -= rc_.nlos.cn0Drop;
  if (path.nlos) cn0 -= rc_.nlos.cn0Drop;
  // Multipath (advanced even while the signal is not tracked: it belongs to the geometry).
  const double a = sg.mpStarted ? std::exp(-std::max(t_ - sg.mpTime, 0.0) / rc_.multipath.timeConstant) : 0.0;
  const double wc = sg.rng.normal(), wp = sg.rng.normal();
  sg.mpCode = sg.mpStarted ? a * sg.mpCode + std::sqrt(1.0 - a * a) * wc : wc;
  sg.mpPhase = sg.mpStarted ? a * sg.mpPhase + std::sqrt(1.0 - a * a) * wp : wp;
  sg.mpStarted = true;
  sg.mpTime = t_;
  const double nc = sg.rng.normal(), np = sg.rng.normal(), nd = sg.rng.normal();
  const double slipDraw = sg.rng.uniform();
  const std::int64_t slipSize = sg.rng.integer(1, std::max(rc_.slips.maxCycles, 1));
  const bool slipNegative = sg.rng.bernoulli(0.5);
  const bool slipFlagged = sg.rng.bernoulli(rc_.slips.flaggedFraction);
  if (cn0 < rc_.cn0.minimum) {
    GnssReceiverSim::loseSignal(sg, "cn0");
    return false;
  }

  sgt.code = sg.code;
  sgt.frequency = *freq;
  sgt.wavelength = lambda;
  sgt.cn0 = cn0;
  sgt.groupDelay = con.groupDelay(sat, sg.code, g.transmit);
  const double ionoScale = (kGnssSimL1Frequency / *freq) * (kGnssSimL1Frequency / *freq);
  sgt.ionosphere = atmo.ionosphereL1 * ionoScale;
  sgt.interFrequencyBias = channel ? rc_.clock.glonassIfbPerChannel * *channel : 0.0;
  sgt.multipathCode = rc_.multipath.code * elFactor * sg.mpCode;
  sgt.multipathPhase = std::clamp(rc_.multipath.phase * elFactor * sg.mpPhase, -0.25 * lambda, 0.25 * lambda);
  if (r_.pathModel_) {  // larger near facades
    sgt.multipathCode *= path.multipathScale;
    sgt.multipathPhase =
        std::clamp(rc_.multipath.phase * path.multipathScale * elFactor * sg.mpPhase, -0.25 * lambda, 0.25 * lambda);
  }
  const double thermal = std::pow(10.0, (45.0 - cn0) / 20.0);
  sgt.codeSigma = rc_.noise.code * cfg_.codeNoiseFactor(sat.system, sg.code) * thermal;
  sgt.phaseSigma = rc_.noise.phase * lambda * thermal;
  sgt.codeNoise = sgt.codeSigma * nc;
  sgt.phaseNoise = sgt.phaseSigma * np;
  sgt.dopplerNoise = rc_.noise.doppler * thermal * nd;

  const double clockTerm = kC * r_.clock_.systemBias(sat.system);
  const double common = g.range + satTruth.shapiro + clockTerm - kC * g.sat.clock + atmo.troposphere + satTruth.nlosBias;
  const double code =
      common + sgt.interFrequencyBias + kC * sgt.groupDelay + sgt.ionosphere + sgt.multipathCode + sgt.codeNoise;
  const double phaseNoN = (common - sgt.ionosphere + sgt.multipathPhase + sgt.phaseNoise) / lambda + satTruth.windup;
  const bool lli = track(st, sg, code, phaseNoN, lambda, slipDraw, slipSize, slipNegative, slipFlagged, sgt);

  // Doppler: -(d/dt of the phase range) / lambda per unit of receiver time.
  const double clockRate = kC * r_.clock_.drift();
  const double phaseRangeRate =
      g.rangeRate + clockRate - kC * g.sat.clockDrift + rates.troposphere - rates.ionosphereL1 * ionoScale;
  // The phase also carries the wind-up (cycles): its rate enters as −ẇ.
  const double doppler = -(phaseRangeRate / (1.0 + r_.clock_.drift()) + sgt.dopplerNoise) / lambda -
                         rates.windup / (1.0 + r_.clock_.drift());

  so.code = sg.code;
  so.setCode(code);
  so.setPhase(phaseNoN + static_cast<double>(sg.ambiguity));
  so.setDoppler(doppler);
  so.setSnr(cn0);
  so.lli = lli ? 1 : 0;
  so.ssi = static_cast<std::uint8_t>(std::clamp(static_cast<int>(std::floor(cn0 / 6.0)), 1, 9));
  return true;
}

/// Carrier tracking: (re)acquisition of a signal not tracked (the receiver aligns the phase with
/// its pseudorange: a new ambiguity arc) or a random cycle slip; returns the loss-of-lock flag.
bool GnssEpochProducer::track(SatTrack& st, SignalTrack& sg, double code, double phaseNoN, double lambda,
                              double slipDraw, std::int64_t slipSize, bool slipNegative, bool slipFlagged,
                              GnssSignalTruth& sgt) {
  const SatId sat = st.sat;
  bool lli = false;
  if (!sg.active) {
    const std::int64_t n = std::llround(code / lambda - phaseNoN);
    const char* cause = r_.first_ ? "start" : (sg.restartCause ? sg.restartCause : "rise");
    if (sg.arc >= 0 && sg.restartCause) r_.slips_.push_back({r_.role_, tag_, sat, sg.code, n - sg.ambiguity, true, cause});
    sg.restartCause = nullptr;
    sg.active = true;
    sg.ambiguity = n;
    sg.arc = static_cast<int>(r_.arcs_.size());
    r_.arcs_.push_back({r_.role_, sat, sg.code, tag_, tag_, n, lambda, cause});
    sgt.arcStart = true;
    lli = !r_.first_;
  } else if (rc_.slips.ratePerMinute > 0.0 && dt_ > 0.0 &&
             slipDraw < 1.0 - std::exp(-rc_.slips.ratePerMinute * dt_ / 60.0)) {
    const std::int64_t jump = slipNegative ? -slipSize : slipSize;
    sg.ambiguity += jump;
    sg.arc = static_cast<int>(r_.arcs_.size());
    r_.arcs_.push_back({r_.role_, sat, sg.code, tag_, tag_, sg.ambiguity, lambda, "slip"});
    r_.slips_.push_back({r_.role_, tag_, sat, sg.code, jump, slipFlagged, "slip"});
    sgt.arcStart = true;
    lli = slipFlagged;
  }
  r_.arcs_[static_cast<std::size_t>(sg.arc)].lastTag = tag_;
  sgt.ambiguity = sg.ambiguity;
  sgt.lossOfLock = lli;
  return lli;
}

void GnssReceiverSim::produce(const GpsTime& tag, const GpsTime& t, GnssSimEpoch& out) {
  GnssEpochProducer(*this, tag, t, out).run();
}

void GnssReceiverSim::finish() {
  for (SatTrack& st : sats_) {
    if (st.blocked) events_[static_cast<std::size_t>(st.blockEvent)].end = std::min(st.blockEnd, world_.end());
    if (st.nlos) events_[static_cast<std::size_t>(st.nlosEvent)].end = std::min(st.nlosEnd, world_.end());
  }
  for (const GnssOutage& o : rc_.outages) {
    if (o.start > world_.duration()) continue;
    GnssEventInterval e;
    e.role = role_;
    e.kind = "outage";
    e.systems = systemLetters(o.systems);
    e.start = world_.start() + o.start;
    e.end = world_.start() + std::min(o.start + o.duration, world_.duration());
    events_.push_back(e);
  }
}

}  // namespace gvins::sim
