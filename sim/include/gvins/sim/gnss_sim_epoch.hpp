// What the GNSS simulator produces per receiver epoch: the observations as a receiver reports
// them (gvins::ObsEpoch, RINEX conventions) and the truth behind every value, plus the event
// records (ambiguity arcs, cycle slips, NLOS/blockage/outage intervals) of a run.
//
// Measurement model (all terms in the truth; c = speed of light, lambda = c / f):
//   P   = rho + shapiro + c (dtr + isb_sys) + ifb - c (dts - gd) + T + I_f + mp_P + nlos + e_P
//   L   = [rho + shapiro + c (dtr + isb_sys) - c dts + T - I_f + mp_L + nlos + e_L] / lambda + N
//   D   = -d/dt[L lambda] / lambda / (1 + dtr_dot) + e_D / lambda          (RINEX sign: D > 0 approaching)
// rho: geometric range from the true satellite position at the true transmit time, rotated into
// the ECEF frame of reception (Sagnac); dts: true satellite clock (broadcast + error); gd: the
// broadcast group delay of the signal; I_f = I_L1 (f_L1 / f)^2; N: integer ambiguity. The epoch
// time tag is receiver time; the true GPST of the measurement is tag - dtr.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "gvins/base/gnss_time.hpp"
#include "gvins/base/local_frame.hpp"
#include "gvins/base/observation.hpp"

namespace gvins::sim {

enum class GnssReceiverRole : std::uint8_t { Rover, Base };
const char* toString(GnssReceiverRole r);

/// Truth of one signal.
struct GnssSignalTruth {
  ObsCode code;
  double frequency = 0.0;       ///< Hz
  double wavelength = 0.0;      ///< m
  std::int64_t ambiguity = 0;   ///< N, cycles
  double cn0 = 0.0;             ///< dB-Hz as reported
  double groupDelay = 0.0;      ///< broadcast group delay gd, s
  double ionosphere = 0.0;      ///< I_f: code delay = phase advance on this frequency, m
  double interFrequencyBias = 0.0;  ///< GLONASS code IFB, m
  double multipathCode = 0.0;   ///< m
  double multipathPhase = 0.0;  ///< m
  double codeNoise = 0.0;       ///< m
  double phaseNoise = 0.0;      ///< m
  double dopplerNoise = 0.0;    ///< m/s
  double codeSigma = 0.0;       ///< m, standard deviation of the white code noise
  double phaseSigma = 0.0;      ///< m
  bool arcStart = false;        ///< first epoch of a new ambiguity arc
  bool lossOfLock = false;      ///< LLI bit 0 reported
};

/// Truth of one satellite seen by a receiver.
struct GnssSatelliteTruth {
  SatId sat;
  GpsTime transmitTime;            ///< true GPST of transmission
  Eigen::Vector3d satPosition = Eigen::Vector3d::Zero();  ///< true, ECEF at the transmit time
  Eigen::Vector3d satVelocity = Eigen::Vector3d::Zero();
  double satClock = 0.0;           ///< true satellite clock dts, s
  double satClockDrift = 0.0;      ///< s/s
  double broadcastClock = 0.0;     ///< from the records, s
  Eigen::Vector3d orbitError = Eigen::Vector3d::Zero();   ///< true - broadcast position, m
  double clockError = 0.0;         ///< true - broadcast clock, s
  double range = 0.0;              ///< rho, m (Sagnac included)
  double rangeRate = 0.0;          ///< d rho / dt, m/s
  double shapiro = 0.0;            ///< m
  double windup = 0.0;             ///< carrier-phase wind-up, cycles (every frequency)
  AzEl azel;
  double troposphere = 0.0, troposphereModel = 0.0;  ///< slant, m
  double troposphereRate = 0.0;                      ///< m/s
  double ionosphereL1 = 0.0, ionosphereModelL1 = 0.0;  ///< slant at 1575.42 MHz, m
  double ionosphereL1Rate = 0.0;                     ///< m/s
  double nlosBias = 0.0;           ///< extra path of non-line-of-sight reception, m (0 = direct)
  std::vector<GnssSignalTruth> signals;  ///< same order as the observation's signals
};

/// Truth of one receiver epoch.
struct GnssReceiverTruth {
  GpsTime tag;                     ///< receiver time tag (= ObsEpoch::time)
  GpsTime time;                    ///< true GPST of the measurements: tag - clockBias
  Eigen::Vector3d antennaPosition = Eigen::Vector3d::Zero();  ///< ECEF at `time`, m
  Eigen::Vector3d antennaVelocity = Eigen::Vector3d::Zero();  ///< ECEF, m/s
  double clockBias = 0.0;          ///< dtr, s
  double clockDrift = 0.0;         ///< s/s
  std::array<double, kNumSystems> systemClockBias{};  ///< dtr + isb per system, s
  std::vector<GnssSatelliteTruth> sats;  ///< same order as the observation's satellites
};

struct GnssSimEpoch {
  GnssReceiverRole role = GnssReceiverRole::Rover;
  ObsEpoch obs;
  GnssReceiverTruth truth;
};

/// A stretch of continuous carrier tracking with one ambiguity.
struct GnssAmbiguityArc {
  GnssReceiverRole role = GnssReceiverRole::Rover;
  SatId sat;
  ObsCode code;
  GpsTime firstTag, lastTag;
  std::int64_t ambiguity = 0;
  double wavelength = 0.0;
  std::string cause;  ///< why it started: "start", "rise", "slip", "blockage", "outage", "nlos", "cn0"
};

/// A change of the ambiguity while the signal stays tracked (random slip), or a restart after a
/// loss of the signal (then `jump` is the difference of the two arcs' ambiguities).
struct GnssSlipEvent {
  GnssReceiverRole role = GnssReceiverRole::Rover;
  GpsTime tag;
  SatId sat;
  ObsCode code;
  std::int64_t jump = 0;
  bool flagged = true;  ///< the receiver set the loss-of-lock indicator
  std::string cause;
};

/// An interval of non-line-of-sight reception, blockage of a satellite, or outage.
struct GnssEventInterval {
  GnssReceiverRole role = GnssReceiverRole::Rover;
  std::string kind;  ///< "nlos", "blockage", "outage"
  SatId sat;         ///< for "outage": prn 0
  std::string systems;  ///< for "outage": letters of the systems affected
  GpsTime start, end;   ///< true GPST
  double value = 0.0;   ///< nlos: extra path, m
};

}  // namespace gvins::sim
