// GNSS simulator, external checks on a freshly simulated one-minute flight (rover 5 Hz, base 1 Hz
// 3 km away, every default error source on): our SPP and RTKLIB's rnx2rtkp SPP land within the
// simulated errors of the truth; RTKLIB's kinematic RTK (L1+L2, continuous AR) fixes the
// baseline to centimetres; the RINEX files read back as the in-memory epochs; the base's RTCM
// stream decodes to the base RINEX within message resolution; our RtkSolver (gnss/) fixes the
// baseline from the written RINEX files like RTKLIB. The RTKLIB tests skip when rnx2rtkp is absent.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <memory>

#include "gvins/base/constants.hpp"
#include "gvins/base/rinex_obs_reader.hpp"
#include "gvins/ephemeris/antex.hpp"
#include "gvins/ephemeris/ephemeris_store.hpp"
#include "gvins/ephemeris/precise_ephemeris.hpp"
#include "gvins/ephemeris/rinex_clock.hpp"
#include "gvins/ephemeris/sp3.hpp"
#include "gvins/gnss/pos_reader.hpp"
#include "gvins/gnss/rtk.hpp"
#include "gvins/gnss/spp.hpp"
#include "gvins/rtcm/decoder.hpp"
#include "gvins/sim/gnss_epoch_generator.hpp"
#include "gvins/sim/gnss_simulator.hpp"
#include "test_gnss_support.hpp"

namespace gvins::sim {
namespace {

namespace fs = std::filesystem;
using testing::CircleTrajectory;
using testing::nagoyaFrame;
using testing::nagoyaNav;
constexpr double kC = constants::kSpeedOfLight;
constexpr std::uint64_t kSeed = 2024;

GnssSimConfig flightConfig() {
  GnssSimConfig c;
  c.rover.rate = 5.0;
  return c;
}

/// What the simulated errors alone make of a single-point fix: unweighted least squares with one
/// clock per system (QZSS on the GPS clock) on the true residual pseudorange errors (everything
/// the broadcast models leave: atmosphere residuals, Shapiro, multipath, NLOS, noise, orbit and
/// clock errors) of the primary signal of every satellite above 15 degrees. Returns the position
/// error (ECEF) and the GPS clock error (m).
Eigen::Vector4d predictedSppError(const GnssSimEpoch& e) {
  std::vector<Eigen::Vector3d> los;
  std::vector<double> err;
  std::vector<int> sys;
  for (const GnssSatelliteTruth& st : e.truth.sats) {
    if (st.azel.elevation < 15.0 * constants::kDegToRad) continue;
    const GnssSignalTruth& g = st.signals.front();  // primary band
    const double ionoModel = st.ionosphereModelL1 * std::pow(1575.42e6 / g.frequency, 2);
    const Eigen::Vector3d u = (st.satPosition - e.truth.antennaPosition).normalized();
    err.push_back((st.troposphere - st.troposphereModel) + (g.ionosphere - ionoModel) + st.shapiro + g.multipathCode +
                  st.nlosBias + g.codeNoise + g.interFrequencyBias + u.dot(st.orbitError) - kC * st.clockError);
    los.push_back(u);
    sys.push_back(st.sat.system == System::Qzss ? systemIndex(System::Gps) : systemIndex(st.sat.system));
  }
  std::map<int, int> col;
  col.emplace(systemIndex(System::Gps), 3);
  for (int s : sys) col.emplace(s, static_cast<int>(3 + col.size()));
  const int n = static_cast<int>(err.size()), m = 3 + static_cast<int>(col.size());
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(n, m);
  Eigen::VectorXd y(n);
  for (int i = 0; i < n; ++i) {
    H.block<1, 3>(i, 0) = -los[static_cast<std::size_t>(i)].transpose();
    H(i, col[sys[static_cast<std::size_t>(i)]]) = 1.0;
    y[i] = err[static_cast<std::size_t>(i)];
  }
  const Eigen::VectorXd dx = H.colPivHouseholderQr().solve(y);
  return dx.head<4>();
}

/// One simulated flight shared by the tests of this file.
class GnssSimFlight : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::make_unique<fs::path>(fs::temp_directory_path() / ("gvins_sim_gnss_" + std::to_string(::getpid())));
    fs::remove_all(*dir_);
    traj_ = std::make_unique<CircleTrajectory>(60.0, 60.0, 30.0, 6.0, Eigen::Vector2d(40.0, -20.0));
    GnssSimulator sim(flightConfig());
    summary_ = std::make_unique<GnssSimSummary>(sim.run(nagoyaNav(), *traj_, nagoyaFrame(), lever(), kSeed, *dir_));
    // The same epochs in memory, and the horizontal/vertical/clock RMS that the simulated errors
    // alone give a least-squares fix.
    GnssEpochGenerator gen(flightConfig(), nagoyaNav(), *traj_, nagoyaFrame(), lever(), kSeed);
    double h2 = 0, v2 = 0, c2 = 0;
    int n = 0;
    while (auto e = gen.next()) {
      if (e->role != GnssReceiverRole::Rover) continue;
      const Eigen::Vector4d p = predictedSppError(*e);
      const Eigen::Vector3d d = enu(p.head<3>(), e->truth.antennaPosition);
      h2 += d.head<2>().squaredNorm();
      v2 += d.z() * d.z();
      c2 += p[3] * p[3];
      ++n;
    }
    predicted_ = Eigen::Vector3d(std::sqrt(h2 / n), std::sqrt(v2 / n), std::sqrt(c2 / n));
    std::printf("least squares on the simulated errors: horizontal RMS %.2f m, vertical %.2f m, clock %.2f m\n",
                predicted_.x(), predicted_.y(), predicted_.z());
  }
  static void TearDownTestSuite() {
    fs::remove_all(*dir_);
    dir_.reset();
    traj_.reset();
    summary_.reset();
  }
  static Eigen::Vector3d lever() { return {0.05, 0.10, 0.15}; }
  static fs::path gnss(const std::string& f) { return *dir_ / "gnss" / f; }
  /// True antenna position at a GPST instant.
  static Eigen::Vector3d truthAt(const GpsTime& t) {
    return trajectoryAntennaMotion(*traj_, nagoyaFrame(), lever())(t).position;
  }
  static Eigen::Vector3d enu(const Eigen::Vector3d& ecefError, const Eigen::Vector3d& at) {
    const Geodetic g = ecefToGeodetic(at);
    return ecefToEnuRotation(g.lat, g.lon) * ecefError;
  }
  /// RTKLIB is optional at run time: the RTKLIB tests skip when rnx2rtkp is not on the PATH.
  static bool haveRnx2rtkp() { return std::system("command -v rnx2rtkp > /dev/null 2>&1") == 0; }
  static int runRnx2rtkp(const std::string& conf, const std::string& out, const std::string& files) {
    const std::string cmd = "rnx2rtkp -k " + (testing::dataDir() / "reference" / "rtklib-2.4.3" / "conf" / conf).string() +
                            " -o " + out + " " + files + " 2>/dev/null";
    return std::system(cmd.c_str());
  }

  static std::unique_ptr<fs::path> dir_;
  static std::unique_ptr<CircleTrajectory> traj_;
  static std::unique_ptr<GnssSimSummary> summary_;
  static Eigen::Vector3d predicted_;  // RMS horizontal, vertical, clock error of the prediction
};
Eigen::Vector3d GnssSimFlight::predicted_ = Eigen::Vector3d::Zero();
std::unique_ptr<fs::path> GnssSimFlight::dir_;
std::unique_ptr<CircleTrajectory> GnssSimFlight::traj_;
std::unique_ptr<GnssSimSummary> GnssSimFlight::summary_;

TEST_F(GnssSimFlight, WritesTheDatasetFolder) {
  for (const char* f : {"rover.obs", "base.obs", "base.rtcm3", "nav.rnx", "precise.sp3", "precise.clk", "satellites.atx", "truth/rover_antenna.csv", "truth/rover_clock.csv",
                        "truth/base_clock.csv", "truth/ambiguities.csv", "truth/cycle_slips.csv", "truth/events.csv",
                        "truth/gnss_truth.yaml"}) {
    EXPECT_TRUE(fs::exists(gnss(f))) << f;
    EXPECT_GT(fs::file_size(gnss(f)), 50u) << f;
  }
  EXPECT_EQ(summary_->roverEpochs, 300);
  EXPECT_EQ(summary_->baseEpochs, 60);
  EXPECT_NEAR(summary_->baselineStart, 3000.0, 200.0);
  for (System s : {System::Gps, System::Glonass, System::Galileo, System::BeiDou, System::Qzss})
    EXPECT_GE(summary_->roverSatellites[systemIndex(s)], 3) << systemName(s);
}

// The precise products written with the dataset (precise.sp3, precise.clk, satellites.atx) read back and
// interpolated give the true orbits and clocks of the simulation up to the configured product
// errors (GnssPreciseProductsConfig::sisre, a few cm), where the broadcast records are off by the
// broadcast SISRE; both measured as the range error seen from the rover (LOS orbit error minus
// clock error) over the flight.
TEST_F(GnssSimFlight, PreciseProductsGiveTheTrueOrbitsAndClocks) {
  // Centre-of-mass orbits (as IGS ones) and the ANTEX file of their antenna offsets.
  auto products = std::make_shared<PreciseEphemeris>();
  products->add(readSp3(gnss("precise.sp3").string()));
  products->add(readRinexClock(gnss("precise.clk").string()));
  EphemerisStore centreOfMass, precise;
  centreOfMass.setPrecise(products);
  precise.setPrecise(products);
  precise.setSatelliteAntennas(std::make_shared<AntexData>(readAntex(gnss("satellites.atx").string())));
  double withoutAntex = 0.0;
  GnssEpochGenerator gen(flightConfig(), nagoyaNav(), *traj_, nagoyaFrame(), lever(), kSeed);
  const GnssConstellation& truth = gen.world().constellation();
  EphemerisStore store;
  store.add(nagoyaNav());
  const GpsTime t0 = gen.world().start();
  std::array<double, kNumSystems> p2{}, b2{};
  std::array<int, kNumSystems> n{};
  double maxPos = 0.0;
  const Eigen::Vector3d rx = truthAt(t0);
  for (SatId sat : truth.satellites()) {
    for (double dt = 0.0; dt <= traj_->duration(); dt += 7.3) {
      const GpsTime t = t0 + dt;
      if (!truth.covers(sat, t)) continue;  // a record ending in the run: the satellite sets
      const auto st = truth.state(sat, t);
      const auto p = precise.preciseState(sat, t);
      if (const auto m = centreOfMass.preciseState(sat, t); m && p)
        withoutAntex = std::max(withoutAntex, (m->position - p->position).norm());
      ASSERT_TRUE(st.has_value());
      ASSERT_TRUE(p.has_value()) << sat.str() << " not covered by the products at +" << dt << " s";
      const Eigen::Vector3d u = (st->position - rx).normalized();
      if (u.dot(rx.normalized()) < 0.1) continue;  // below ~6 deg elevation
      const int s = systemIndex(sat.system);
      const double c = constants::kSpeedOfLight;
      p2[s] += std::pow(u.dot(p->position - st->position) - c * (p->clockBias - st->clock), 2);
      maxPos = std::max(maxPos, (p->position - st->position).norm());
      const auto b = store.satelliteState(sat, t);
      if (b) b2[s] += std::pow(u.dot(b->position - st->position) - c * (b->clockBias - st->clock), 2);
      ++n[s];
      // The velocity from the interpolant is the truth's to millimetres per second (measured up to
      // 1.7 mm/s on the BeiDou GEO C60: the truth blends records with a smoothstep, which a
      // degree-10 polynomial over 300 s nodes follows only approximately; the Doppler noise is 0.1 m/s).
      EXPECT_LT((p->velocity - st->velocity).norm(), 5e-3) << sat.str();
    }
  }
  const GnssPreciseProductsConfig cfg = flightConfig().preciseProducts;
  const GnssSatelliteErrorConfig bcfg = flightConfig().satelliteErrors;
  for (System sys : {System::Gps, System::Glonass, System::Galileo, System::BeiDou}) {
    const int s = systemIndex(sys);
    ASSERT_GT(n[s], 20) << systemName(sys);
    const double prms = std::sqrt(p2[s] / n[s]), brms = std::sqrt(b2[s] / n[s]);
    std::printf("%s range error: precise products %.3f m (configured %.3f), broadcast %.3f m (configured %.3f)\n",
                std::string(systemName(sys)).c_str(), prms, cfg.sisre[s], brms, bcfg.sisre[s]);
    EXPECT_LT(prms, 2.5 * cfg.sisre[s]) << systemName(sys);
    EXPECT_GT(prms, 0.2 * cfg.sisre[s]) << systemName(sys);  // the product errors are there
    EXPECT_GT(brms, 5.0 * prms) << systemName(sys);
  }
  EXPECT_LT(maxPos, 0.5);
  // The antenna offsets matter: the centre of mass is 0.5-2.6 m from the phase centre.
  std::printf("largest centre-of-mass to phase-centre distance: %.3f m\n", withoutAntex);
  EXPECT_GT(withoutAntex, 1.0);
  EXPECT_LT(withoutAntex, 2.8);
}

TEST_F(GnssSimFlight, OurSppAndDopplerVelocityLandWithinTheSimulatedErrors) {
  GnssEpochGenerator gen(flightConfig(), nagoyaNav(), *traj_, nagoyaFrame(), lever(), kSeed);
  EphemerisStore store;
  store.add(nagoyaNav());
  SppSolver spp(store);
  double h2 = 0.0, v2 = 0.0, vel2 = 0.0, clk2 = 0.0, isb2 = 0.0;
  int n = 0, nIsb = 0;
  while (auto e = gen.next()) {
    if (e->role != GnssReceiverRole::Rover) continue;
    const SppSolution sol = spp.solve(e->obs);
    if (!sol.valid()) continue;
    ++n;
    const Eigen::Vector3d d = enu(sol.position - e->truth.antennaPosition, e->truth.antennaPosition);
    h2 += d.head<2>().squaredNorm();
    v2 += d.z() * d.z();
    // The solution time is the receiver tag minus the estimated clock: the true GPST.
    EXPECT_NEAR(sol.solutionTime - e->truth.time, 0.0, 5e-8);
    ASSERT_TRUE(sol.velocity.valid);
    vel2 += (sol.velocity.velocity - e->truth.antennaVelocity).squaredNorm();
    const double gpsClock = kC * e->truth.systemClockBias[systemIndex(System::Gps)];
    clk2 += std::pow(*sol.clockBias[systemIndex(System::Gps)] - gpsClock, 2);
    for (System s : {System::Galileo, System::BeiDou}) {
      if (!sol.clockBias[systemIndex(s)]) continue;
      const double isb = *sol.clockBias[systemIndex(s)] - *sol.clockBias[systemIndex(System::Gps)];
      isb2 += std::pow(isb - kC * (e->truth.systemClockBias[systemIndex(s)] - e->truth.systemClockBias[0]), 2);
      ++nIsb;
    }
  }
  ASSERT_GE(n, 295);
  const double h = std::sqrt(h2 / n), v = std::sqrt(v2 / n), clk = std::sqrt(clk2 / n);
  std::printf("our SPP: horizontal RMS %.2f m, vertical %.2f m, clock %.2f m, inter-system bias %.2f m; "
              "velocity RMS %.3f m/s\n",
              h, v, clk, std::sqrt(isb2 / std::max(nIsb, 1)), std::sqrt(vel2 / n));
  // The fix is as far from the truth as the simulated errors push a least-squares solution
  // (weighting and outlier rejection may do better, never much worse).
  EXPECT_LT(h, 1.5 * predicted_.x() + 0.5);
  EXPECT_LT(v, 1.5 * predicted_.y() + 0.5);
  EXPECT_LT(clk, 1.5 * predicted_.z() + 1.0);
  EXPECT_GT(std::hypot(h, v), 0.3 * predicted_.head<2>().norm());
  // Inter-system biases as simulated, up to the satellite-specific errors (the common ones cancel).
  EXPECT_LT(std::sqrt(isb2 / std::max(nIsb, 1)), 2.0);
  EXPECT_LT(std::sqrt(vel2 / n), 0.10);
}

TEST_F(GnssSimFlight, RinexFilesReadBackAsTheInMemoryEpochs) {
  // The same seed gives the same epochs (reproducibility), and the writer keeps them to the
  // format's resolution.
  GnssEpochGenerator gen(flightConfig(), nagoyaNav(), *traj_, nagoyaFrame(), lever(), kSeed);
  RinexObsReader rover(gnss("rover.obs").string()), base(gnss("base.obs").string());
  EXPECT_EQ(rover.header().station.markerName, "ROVER");
  ASSERT_TRUE(base.header().station.approxPosition);
  EXPECT_LT((*base.header().station.approxPosition - summary_->basePosition).norm(), 1e-4);
  EphemerisStore store;
  store.add(nagoyaNav());
  for (int slot = 1; slot <= 27; ++slot) EXPECT_EQ(rover.header().glonassChannels.get(slot), store.glonassChannels().get(slot));
  ObsEpoch fileEpoch;
  int epochs = 0;
  std::int64_t values = 0;
  while (auto e = gen.next()) {
    RinexObsReader& r = e->role == GnssReceiverRole::Rover ? rover : base;
    if (e->obs.sats.empty()) continue;
    ASSERT_TRUE(r.next(fileEpoch));
    ASSERT_EQ(fileEpoch.time, e->obs.time);
    ASSERT_TRUE(fileEpoch.receiverClockOffset);
    EXPECT_NEAR(*fileEpoch.receiverClockOffset, *e->obs.receiverClockOffset, 1e-12);
    ASSERT_EQ(fileEpoch.sats.size(), e->obs.sats.size());
    for (std::size_t i = 0; i < e->obs.sats.size(); ++i) {
      const SatObs& a = e->obs.sats[i];
      const SatObs* b = fileEpoch.find(a.sat);
      ASSERT_NE(b, nullptr) << a.sat.str();
      ASSERT_EQ(b->signals.size(), a.signals.size());
      for (const SignalObs& sa : a.signals) {
        const SignalObs* sb = b->find(sa.code);
        ASSERT_NE(sb, nullptr);
        EXPECT_NEAR(sb->pseudorange, sa.pseudorange, 0.0005 + 1e-7);  // 1 mm rounding of values up to 4e7 m
        EXPECT_NEAR(sb->carrierPhase, sa.carrierPhase, 0.0005 + 1e-6);
        EXPECT_NEAR(sb->doppler, sa.doppler, 0.0005 + 1e-9);
        EXPECT_NEAR(sb->snr, sa.snr, 0.0005 + 1e-9);
        EXPECT_EQ(sb->lli & 1, sa.lli & 1);
        EXPECT_EQ(sb->ssi, sa.ssi);
        values += 4;
      }
    }
    ++epochs;
  }
  EXPECT_FALSE(rover.next(fileEpoch));
  EXPECT_FALSE(base.next(fileEpoch));
  EXPECT_EQ(epochs, 360);
  EXPECT_GT(values, 50000);
}

TEST_F(GnssSimFlight, RtcmStreamDecodesToTheBaseRinex) {
  std::ifstream f(gnss("base.rtcm3"), std::ios::binary);
  const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  rtcm::DecoderOptions opt;
  opt.referenceTime = nagoyaFrame().startTime;
  opt.strict = true;
  rtcm::Decoder dec(opt);
  dec.feed(bytes);
  dec.finish();
  std::vector<ObsEpoch> epochs;
  std::vector<rtcm::StationPosition> stations;
  int kepler = 0, glonass = 0;
  while (auto d = dec.poll()) {
    if (auto* e = std::get_if<ObsEpoch>(&*d)) epochs.push_back(*e);
    if (auto* s = std::get_if<rtcm::StationPosition>(&*d)) stations.push_back(*s);
    if (std::holds_alternative<KeplerEphemeris>(*d)) ++kepler;
    if (std::holds_alternative<GlonassEphemeris>(*d)) ++glonass;
  }
  EXPECT_EQ(dec.stats().framing.crcFailures, 0);
  EXPECT_EQ(dec.stats().malformed, 0);
  EXPECT_EQ(dec.stats().glonassNoChannel, 0);  // 1020 and MSM7 carry the channels
  // Station position every 10 s, ephemerides of every tracked satellite.
  ASSERT_EQ(stations.size(), 6u);
  for (const auto& s : stations) EXPECT_LT((s.arp - summary_->basePosition).norm(), 1e-4);
  EXPECT_GE(kepler, 40);
  EXPECT_GE(glonass, 6);

  RinexObsReader base(gnss("base.obs").string());
  ObsEpoch r;
  ASSERT_EQ(epochs.size(), 60u);
  double maxCode = 0, maxPhase = 0, maxDoppler = 0, maxSnr = 0;
  std::int64_t n = 0;
  for (const ObsEpoch& e : epochs) {
    ASSERT_TRUE(base.next(r));
    ASSERT_EQ(e.time, r.time);
    ASSERT_EQ(e.sats.size(), r.sats.size());
    for (const SatObs& sr : r.sats) {
      const SatObs* sd = e.find(sr.sat);
      ASSERT_NE(sd, nullptr) << sr.sat.str();
      const std::optional<int> ch = sr.sat.system == System::Glonass ? base.header().glonassChannels.get(sr.sat.prn)
                                                                      : std::optional<int>();
      for (const SignalObs& gr : sr.signals) {
        const SignalObs* gd = sd->find(gr.code);
        ASSERT_NE(gd, nullptr) << sr.sat.str() << " " << gr.code.str();
        const double lambda = *carrierWavelength(sr.sat.system, gr.code.band, ch);
        maxCode = std::max(maxCode, std::abs(gd->pseudorange - gr.pseudorange));
        maxPhase = std::max(maxPhase, std::abs(gd->carrierPhase - gr.carrierPhase) * lambda);
        maxDoppler = std::max(maxDoppler, std::abs(gd->doppler - gr.doppler) * lambda);
        maxSnr = std::max(maxSnr, std::abs(gd->snr - gr.snr));
        // Loss-of-lock flags survive the lock-time indicators, except in the stream's first epoch:
        // there every lock has just started (lock time 0), which a decoder must flag, while RINEX
        // has no previous epoch to lose lock against.
        if (&e == &epochs.front()) EXPECT_EQ(gd->lli & 1, 1);
        else EXPECT_EQ(gd->lli & 1, gr.lli & 1) << sr.sat.str() << " " << gr.code.str() << " " << e.time.toString();
        ++n;
      }
    }
  }
  EXPECT_GT(n, 5000);
  // MSM7 resolution (code 2^-29 ms = 0.56 mm, phase 2^-31 ms = 0.14 mm, Doppler 0.1 mm/s,
  // C/N0 1/16 dB-Hz) plus RINEX rounding (1 mm, 0.001 cycle, 0.001 Hz, 0.001 dB-Hz).
  EXPECT_LT(maxCode, 0.0009);
  EXPECT_LT(maxPhase, 0.0003);
  EXPECT_LT(maxDoppler, 0.0003);
  EXPECT_LT(maxSnr, 1.0 / 32 + 0.001);
}

TEST_F(GnssSimFlight, RtklibSppLandsWithinTheSimulatedErrors) {
  if (!haveRnx2rtkp()) GTEST_SKIP() << "rnx2rtkp (RTKLIB 2.4.3, Debian package rtklib) not installed";
  const std::string out = (*dir_ / "rtklib_spp.pos").string();
  ASSERT_EQ(runRnx2rtkp("sim_spp.conf", out, gnss("rover.obs").string() + " " + gnss("nav.rnx").string()), 0)
      << "rnx2rtkp failed";
  const PosFile pos = readPosFile(out);
  ASSERT_GE(pos.solutions.size(), 290u);
  double h2 = 0, v2 = 0;
  for (const PositionSolution& s : pos.solutions) {
    const Eigen::Vector3d truth = truthAt(s.time);
    const Eigen::Vector3d d = enu(s.position - truth, truth);
    h2 += d.head<2>().squaredNorm();
    v2 += d.z() * d.z();
  }
  const double h = std::sqrt(h2 / pos.solutions.size()), v = std::sqrt(v2 / pos.solutions.size());
  std::printf("RTKLIB SPP: horizontal RMS %.2f m, vertical RMS %.2f m (%zu epochs)\n", h, v, pos.solutions.size());
  // Within what the simulated errors give a least-squares fix.
  EXPECT_LT(h, 1.5 * predicted_.x() + 0.5);
  EXPECT_LT(v, 1.5 * predicted_.y() + 0.5);
}

TEST_F(GnssSimFlight, RtklibKinematicRtkFixesTheBaseline) {
  if (!haveRnx2rtkp()) GTEST_SKIP() << "rnx2rtkp (RTKLIB 2.4.3, Debian package rtklib) not installed";
  const std::string out = (*dir_ / "rtklib_rtk.pos").string();
  ASSERT_EQ(runRnx2rtkp("sim_rtk_kin.conf", out,
                        gnss("rover.obs").string() + " " + gnss("base.obs").string() + " " + gnss("nav.rnx").string()),
            0);
  const PosFile pos = readPosFile(out);
  ASSERT_GE(pos.solutions.size(), 290u);
  int fixed = 0, afterTen = 0;
  double sum2 = 0.0, worst = 0.0;
  for (const PositionSolution& s : pos.solutions) {
    if (s.time - nagoyaFrame().startTime < 10.0) continue;
    ++afterTen;
    if (s.quality != SolutionQuality::Fix) continue;
    ++fixed;
    const double e = (s.position - truthAt(s.time)).norm();
    sum2 += e * e;
    worst = std::max(worst, e);
  }
  const double rate = static_cast<double>(fixed) / afterTen;
  std::printf("RTKLIB RTK: %.1f %% fixed after 10 s, fixed 3D RMS %.4f m, max %.4f m\n", 100.0 * rate,
              std::sqrt(sum2 / std::max(fixed, 1)), worst);
  EXPECT_GT(rate, 0.9);
  EXPECT_LT(std::sqrt(sum2 / std::max(fixed, 1)), 0.02);
  EXPECT_LT(worst, 0.05);
}


TEST_F(GnssSimFlight, OurKinematicRtkFixesTheBaseline) {
  // gnss/'s RtkSolver with its defaults (kinematic, continuous AR) on the written rover and base
  // RINEX and navigation files; the base position from the summary (= the RINEX header).
  EphemerisStore store;
  store.add(readRinexNav(gnss("nav.rnx").string()));
  const std::vector<ObsEpoch> rover = readRinexObs(gnss("rover.obs").string());
  const std::vector<ObsEpoch> base = readRinexObs(gnss("base.obs").string());
  ASSERT_EQ(rover.size(), 300u);
  RtkSolver rtk(store);
  rtk.setBasePosition(summary_->basePosition);
  std::size_t b = 0;
  int fixed = 0, afterTen = 0;
  double sum2 = 0.0, worst = 0.0;
  for (const ObsEpoch& r : rover) {
    // Base epochs up to and one past the rover epoch.
    while (b < base.size() && base[b].time - r.time <= 1.0) rtk.addBaseEpoch(base[b++]);
    const RtkSolution sol = rtk.process(r);
    if (r.time - nagoyaFrame().startTime < 10.0) continue;
    ++afterTen;
    if (sol.quality != SolutionQuality::Fix) continue;
    ++fixed;
    const double e = (sol.position - truthAt(sol.time)).norm();
    sum2 += e * e;
    worst = std::max(worst, e);
  }
  const double rate = static_cast<double>(fixed) / afterTen;
  std::printf("our RTK: %.1f %% fixed after 10 s, fixed 3D RMS %.4f m, max %.4f m\n", 100.0 * rate,
              std::sqrt(sum2 / std::max(fixed, 1)), worst);
  EXPECT_GT(rate, 0.9);
  EXPECT_LT(std::sqrt(sum2 / std::max(fixed, 1)), 0.02);
  EXPECT_LT(worst, 0.05);
}

}  // namespace
}  // namespace gvins::sim
