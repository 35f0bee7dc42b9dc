// Options of the GNSS half of the dataset simulator and their YAML form (the `gnss:` section of a
// gvins-sim scenario). Every default below is a realistic value with its source; a scenario
// only lists what it changes.
#pragma once

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "gvins/base/satellite.hpp"
#include "gvins/base/signal.hpp"

namespace YAML {
class Node;
}

namespace gvins::sim {

/// One horizontal Gaussian random field (a residual of an atmosphere model), moved by a constant
/// wind (frozen flow): value(x, t) = f(x - w t).
struct GnssRandomFieldConfig {
  enum class Covariance { Exponential, Gaussian };
  double sigma = 0.0;             ///< standard deviation (unit of the field: m or TECU)
  double correlationLength = 1e5; ///< m: exp(-d/L) or exp(-d^2/L^2)
  Covariance covariance = Covariance::Gaussian;
  double speed = 0.0;             ///< m/s of the frozen-flow drift (direction drawn per run)
};

/// Receiver oscillator and inter-system biases.
struct GnssClockConfig {
  /// Power-law coefficients of the fractional frequency noise, S_y(f) = h0 + h_-2 f^-2 (white
  /// and random-walk frequency noise; flicker is neglected as in the two-state model of Brown &
  /// Hwang, "Introduction to Random Signals and Applied Kalman Filtering", 4th ed., 2012, 9.3).
  /// Defaults: the VCTCXO of NovAtel's OEM7 clock model (EXTERNALCLOCK command documentation,
  /// table "Clock Type": h0 = 1.0e-21, h_-2 = 1.0e-20). The OCXO there has h0 = 2.51e-26,
  /// h_-2 = 2.51e-22.
  double h0 = 1.0e-21;
  double hMinus2 = 1.0e-20;
  /// Initial clock bias drawn uniformly in [-max, max], s (receivers set their clock to GPST
  /// within about a millisecond and then let it run).
  double initialBiasMax = 5.0e-4;
  /// Initial frequency offset (clock drift), drawn N(0, sigma), s/s (TCXO tolerance ~0.1-0.5 ppm).
  double initialDriftSigma = 1.0e-7;
  /// Inter-system code/phase biases (receiver hardware delays per constellation, plus the
  /// systems' time offsets to GPST), drawn N(0, sigma) per system, s. GPS is the reference (0);
  /// QZSS shares the GPS signals and time scale (0 by default).
  std::array<double, kNumSystems> isbSigma{0.0, 50e-9, 10e-9, 20e-9, 0.0, 0.0, 0.0};
  /// GLONASS FDMA code inter-frequency bias per frequency channel number k, m/k (0 = off).
  double glonassIfbPerChannel = 0.0;
  /// Write the receiver's own clock offset estimate into each RINEX epoch record (true bias plus
  /// N(0, reportSigma)); RTKLIB and gvins-spp ignore that field.
  bool reportOffset = true;
  double reportSigma = 20e-9;
};

/// Carrier-to-noise density model: C/N0 = zenith - (zenith - horizon) (1 - sin el)^2 + per-signal
/// offset + per-satellite constant + white noise.
struct GnssCn0Config {
  double zenith = 48.0;   ///< dB-Hz at 90 deg
  double horizon = 34.0;  ///< dB-Hz at 0 deg
  double satelliteSigma = 1.5;  ///< dB, constant per satellite and receiver
  double noise = 0.5;           ///< dB, white per epoch
  double minimum = 20.0;        ///< below it the receiver loses the signal
};

/// Thermal noise at 45 dB-Hz; scales as 10^((45 - C/N0)/20) (thermal DLL/PLL jitter is
/// proportional to 1/sqrt(C/N0), Kaplan & Hegarty, "Understanding GPS/GNSS", 3rd ed., 8.4).
struct GnssNoiseConfig {
  double code = 0.25;       ///< m (L1 C/A DLL, 0.1-chip correlator: ~0.26 m at 45 dB-Hz)
  double phase = 0.004;     ///< cycles (PLL 10 Hz: 0.003 cycles at 45 dB-Hz, plus oscillator)
  double doppler = 0.03;    ///< m/s
};

/// Correlated multipath: first-order Gauss-Markov per satellite and signal with standard
/// deviation sigma / sin(el) (capped at 10 sigma).
struct GnssMultipathConfig {
  double code = 0.15;          ///< m at zenith
  double phase = 0.0015;       ///< m at zenith
  double timeConstant = 10.0;  ///< s
};

/// Non-line-of-sight reception: events start at `ratePerMinute` for each satellite below
/// `maxElevation`, last an exponential time, delay code and phase by a positive extra path and
/// lower C/N0. Carrier tracking is lost at the start and the end (new ambiguity).
struct GnssNlosConfig {
  double ratePerMinute = 0.0;
  double maxElevationDeg = 40.0;
  double meanDuration = 4.0;  ///< s
  double biasMin = 10.0;      ///< m
  double biasMax = 50.0;      ///< m
  double cn0Drop = 10.0;      ///< dB
};

/// Blockage of single satellites (all signals lost, reacquired with new ambiguities).
struct GnssBlockageConfig {
  double ratePerMinute = 0.0;
  double maxElevationDeg = 90.0;
  double meanDuration = 5.0;  ///< s
};

/// Random cycle slips per signal (not caused by blockage or NLOS).
struct GnssSlipConfig {
  double ratePerMinute = 0.0;
  int maxCycles = 10;           ///< jumps are uniform in [-max, max] \ {0}
  double flaggedFraction = 0.8; ///< probability the receiver sets the loss-of-lock flag
};

/// A scheduled outage (flight time from the start). Empty `systems` = every system.
struct GnssOutage {
  double start = 0.0;
  double duration = 0.0;
  std::array<bool, kNumSystems> systems{true, true, true, true, true, true, true};
};

/// Everything that differs between the rover and the base receiver.
struct GnssReceiverConfig {
  double rate = 10.0;                 ///< Hz
  double elevationMaskDeg = 5.0;
  GnssClockConfig clock;
  GnssCn0Config cn0;
  GnssNoiseConfig noise;
  GnssMultipathConfig multipath;
  GnssNlosConfig nlos;
  GnssBlockageConfig blockage;
  GnssSlipConfig slips;
  std::vector<GnssOutage> outages;
  std::string markerName = "ROVER";
  std::string receiverType = "GVINS-SIM";
  std::string antennaType = "GVINS-SIM-ANT";
};

struct GnssBaseConfig {
  bool enabled = true;
  double distance = 3000.0;   ///< m from the local origin
  double azimuthDeg = 45.0;   ///< clockwise from north
  double height = 0.0;        ///< m above the origin's ellipsoidal height
  std::optional<Eigen::Vector3d> positionLlh;  ///< deg, deg, m; overrides distance/azimuth/height
  GnssReceiverConfig receiver;
};

struct GnssRtcmConfig {
  int msm = 7;                  ///< 4 or 7
  int stationId = 1;
  double stationInterval = 10.0;    ///< s between 1005/1006
  std::optional<double> antennaHeight;  ///< set: 1006 with this height (m), else 1005
  double ephemerisInterval = 60.0;  ///< s between repetitions of a satellite's ephemeris
};

struct GnssTroposphereConfig {
  double relativeHumidity = 0.5;       ///< of the standard atmosphere behind the model
  /// True zenith delays = model (1 + e), e ~ N(0, sigma) drawn once per run: hydrostatic
  /// (Saastamoinen is good to ~1 %, mostly the surface pressure) and wet (standard-atmosphere
  /// humidity is typically off by tens of percent).
  double hydrostaticScaleSigma = 0.01;
  double wetScaleSigma = 0.3;
  /// Height (m above the receiver) of the layer where slant paths sample the residual field.
  double layerHeight = 1500.0;
  /// Zenith wet delay residual fields, m. Four Gaussian scales (0.5, 2, 8, 32 km) with
  /// sigma = 2.5 mm sqrt(L / 2 km) add up to a structure function whose RMS difference grows as
  /// about 2.5 mm sqrt(d / km) (1.7 mm at 0.5 km, 4.7 mm at 3 km, 11 mm at 20 km), the power law
  /// that Emardson, Simons & Webb (2003, J. Geophys. Res. 108(B5), 2231) fit to GPS zenith wet
  /// delay differences; drifting with a 10 m/s wind.
  std::vector<GnssRandomFieldConfig> residual{
      {0.00125, 0.5e3, GnssRandomFieldConfig::Covariance::Gaussian, 10.0},
      {0.0025, 2e3, GnssRandomFieldConfig::Covariance::Gaussian, 10.0},
      {0.005, 8e3, GnssRandomFieldConfig::Covariance::Gaussian, 10.0},
      {0.010, 32e3, GnssRandomFieldConfig::Covariance::Gaussian, 10.0}};
};

struct GnssIonosphereConfig {
  /// True slant TEC = GPS Klobuchar (1 + e) + mapped vertical residual field; e ~ N(0, sigma)
  /// once per run (the model is designed to remove at least half of the delay, IS-GPS-200N
  /// 20.3.3.5.2.5; at mid-latitudes it typically leaves 20-40 %).
  double modelScaleSigma = 0.25;
  double shellHeight = 350e3;  ///< m, single-layer model height of the residual field
  /// Vertical TEC residual fields, TECU: a large-scale part and travelling ionospheric
  /// disturbances; together about 1 ppm of differential delay on L1 (3 mm at 3 km).
  std::vector<GnssRandomFieldConfig> residual{
      {3.0, 1000e3, GnssRandomFieldConfig::Covariance::Gaussian, 50.0},
      {0.5, 150e3, GnssRandomFieldConfig::Covariance::Gaussian, 150.0}};
};

/// Differences between the true satellite orbits/clocks and the broadcast ephemerides.
struct GnssSatelliteErrorConfig {
  /// The true orbit and clock follow the broadcast records, blended smoothly from one record's
  /// reference time to the next (true: continuous over any span), or the one record selected at
  /// the start (false).
  bool blendRecords = true;
  /// Signal-in-space range error per system, m (orbit error vector and clock error drawn per
  /// satellite). Defaults after Montenbruck, Steigenberger & Hauschild (2018, Adv. Space Res.
  /// 61(12)): GPS ~0.5, GLONASS ~1.5, Galileo ~0.25, BeiDou ~0.8, QZSS ~0.5 m.
  std::array<double, kNumSystems> sisre{0.5, 1.5, 0.25, 0.8, 0.5, 1.0, 1.0};
};

/// Precise orbit and clock products written with the broadcast navigation file (gnss/precise.sp3,
/// gnss/precise.clk), as a user would download IGS/MGEX final products or decode real-time SSR:
/// the true orbits and clocks of the simulation plus small per-satellite errors (a constant and a
/// drift, split over radial/along/cross/clock like the broadcast SISRE).
struct GnssPreciseProductsConfig {
  bool write = true;
  double orbitInterval = 300.0;  ///< s (MGEX final orbits: 300 s; IGS final: 900 s)
  double clockInterval = 30.0;   ///< s (IGS final clocks: 30 s)
  /// Signal-in-space range error of the products per system, m. Defaults after the IGS final
  /// products' stated accuracy (orbits ~2.5 cm, clocks ~75 ps; igs.org/products) for GPS and the
  /// MGEX assessments for the others (Montenbruck et al. 2017, Adv. Space Res. 59(7)).
  std::array<double, kNumSystems> sisre{0.02, 0.04, 0.03, 0.06, 0.05, 0.1, 0.1};
  /// Orbits as IGS products give them: satellite centres of mass, with the antenna phase-centre
  /// offsets in gnss/satellites.atx (ANTEX). The offsets are invented per satellite within the
  /// range of the real ones (z 0.5-2.6 m, x within ±0.4 m; e.g. igs20.atx); false: the orbits are
  /// the phase-centre positions the ranges are simulated to, and no ANTEX file is written.
  bool centreOfMass = true;
  /// Also write gnss/ssr.rtcm3: SSR corrections (RTCM 1060/1066/1243/1249/1261, combined orbit and
  /// clock) every ssrInterval seconds that turn the broadcast records into these products' states
  /// (gvins/ephemeris/ssr_from_products.hpp). One of the RTCM update intervals (1, 2, 5, 10, 15,
  /// 30, 60 s ...); 0: no SSR stream.
  double ssrInterval = 5.0;
};

/// Satellites that transmit a signal (e.g. BeiDou B2I only from BDS-2 satellites C01-C18: BDS-3
/// broadcasts B1I and B3I but not B2I, BDS-SIS-ICD-B1I 3.0 and B3I 1.0).
struct GnssSignalSatellites {
  System system = System::Gps;
  ObsCode code;
  std::vector<std::uint8_t> prns;
};

struct GnssSimConfig {
  /// Broadcast ephemerides (RINEX 2/3/4 navigation file). Relative paths in a scenario are
  /// relative to the scenario file's folder.
  std::filesystem::path navigationFile;
  std::array<bool, kNumSystems> systems{true, true, true, true, true, false, false};
  /// Signals per system (index systemIndex).
  std::array<std::vector<ObsCode>, kNumSystems> signals{
      std::vector<ObsCode>{{'1', 'C'}, {'2', 'W'}, {'5', 'Q'}},  // GPS L1 C/A, L2 P(Y), L5 Q
      std::vector<ObsCode>{{'1', 'C'}, {'2', 'C'}},              // GLONASS G1, G2 C/A
      std::vector<ObsCode>{{'1', 'C'}, {'5', 'Q'}, {'7', 'Q'}},  // Galileo E1C, E5aQ, E5bQ
      std::vector<ObsCode>{{'2', 'I'}, {'7', 'I'}, {'6', 'I'}},  // BeiDou B1I, B2I, B3I
      std::vector<ObsCode>{{'1', 'C'}, {'2', 'L'}, {'5', 'Q'}},  // QZSS L1 C/A, L2C(L), L5 Q
      std::vector<ObsCode>{},
      std::vector<ObsCode>{}};
  std::vector<GnssSignalSatellites> signalSatellites{
      {System::BeiDou, {'7', 'I'}, {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18}}};
  bool includeUnhealthy = false;
  /// C/N0 offsets per signal relative to the receiver's model (dB), e.g. semi-codeless L2 P(Y).
  std::vector<std::pair<std::pair<System, ObsCode>, double>> cn0Offsets{
      {{System::Gps, {'2', 'W'}}, -6.0}, {{System::Gps, {'5', 'Q'}}, 1.0},
      {{System::Galileo, {'5', 'Q'}}, 1.0}, {{System::BeiDou, {'6', 'I'}}, 1.0},
      {{System::Qzss, {'2', 'L'}}, -1.0}, {{System::Qzss, {'5', 'Q'}}, 1.0},
      {{System::Glonass, {'2', 'C'}}, -1.0}};
  /// Code noise factors per signal relative to GnssNoiseConfig::code (wideband L5/E5 signals
  /// have a ten times higher chipping rate than L1 C/A).
  std::vector<std::pair<std::pair<System, ObsCode>, double>> codeNoiseFactors{
      {{System::Gps, {'5', 'Q'}}, 0.5}, {{System::Galileo, {'5', 'Q'}}, 0.5},
      {{System::Galileo, {'7', 'Q'}}, 0.5}, {{System::BeiDou, {'6', 'I'}}, 0.6},
      {{System::Qzss, {'5', 'Q'}}, 0.5}, {{System::Gps, {'2', 'W'}}, 1.5},
      {{System::Glonass, {'1', 'C'}}, 1.4}, {{System::Glonass, {'2', 'C'}}, 1.4}};
  GnssSatelliteErrorConfig satelliteErrors;
  GnssPreciseProductsConfig preciseProducts;
  GnssTroposphereConfig troposphere;
  GnssIonosphereConfig ionosphere;
  /// Shapiro (relativistic) signal delay, ~2 cm (IERS Conventions 2010, eq. 11.17).
  bool shapiroDelay = true;
  /// Carrier-phase wind-up (gvins/gnss/phase_windup.hpp, Wu et al. 1993): satellites in nominal
  /// yaw steering, the rover antenna along the body axes (z the boresight), the base level (x
  /// north, y west). Added to every phase (the same cycles on every frequency); the Doppler is
  /// left without its rate (common to all satellites under a yaw turn, which the clock drift
  /// takes).
  bool phaseWindup = true;
  GnssReceiverConfig rover = defaultRover();
  GnssBaseConfig base = defaultBase();
  GnssRtcmConfig rtcm;
  /// Also write gnss/truth/{rover,base}_errors.csv (every term of every measurement).
  bool writeErrorTerms = false;

  bool useSystem(System s) const { return systems[systemIndex(s)]; }
  /// Whether a satellite transmits a signal (signalSatellites rules).
  bool transmits(SatId sat, ObsCode code) const;
  double cn0Offset(System s, ObsCode code) const;
  double codeNoiseFactor(System s, ObsCode code) const;

  /// Rover defaults: a small UAV antenna (weaker C/N0), multipath, NLOS, occasional blockage
  /// and slips.
  static GnssReceiverConfig defaultRover();
  /// Base defaults: a geodetic antenna on a mast, 1 Hz, little multipath, no NLOS or slips.
  static GnssBaseConfig defaultBase();
};

/// Reads the `gnss:` section of a scenario (a YAML map) on top of the defaults. `file` is the
/// scenario's path: it names errors and anchors relative paths. Every key must be known; wrong
/// types, out-of-range values and unknown keys throw gvins::ParseError naming the file, the line
/// and the key (e.g. "gnss.rover.noise.code_m").
GnssSimConfig parseGnssSimConfig(const YAML::Node& gnssSection, const std::string& file);
/// Same from YAML text (the text holds a top-level `gnss:` map); for tests and tools.
GnssSimConfig parseGnssSimConfigText(const std::string& yaml, const std::string& file);

}  // namespace gvins::sim
