// Contents of the RTCM 3 station and bias messages, as the decoder delivers them and the encoder
// takes them. Observation and ephemeris messages map to gvins::ObsEpoch, gvins::KeplerEphemeris
// and gvins::GlonassEphemeris instead.
#pragma once

#include <optional>
#include <string>

#include <Eigen/Core>

namespace gvins::rtcm {

/// 1005/1006: stationary reference station antenna reference point (RTCM 10403.3, 3.5.3).
struct StationPosition {
  int messageType = 1005;
  int stationId = 0;             ///< DF003
  int itrfYear = 0;              ///< DF021 ITRF realisation year (0 = not specified)
  bool gps = false;              ///< DF022 GPS indicator
  bool glonass = false;          ///< DF023
  bool galileo = false;          ///< DF024
  bool physicalStation = true;   ///< DF141: false = non-physical (virtual) reference station
  bool singleOscillator = false; ///< DF142
  int quarterCycle = 0;          ///< DF364 quarter cycle indicator
  Eigen::Vector3d arp = Eigen::Vector3d::Zero();  ///< ECEF of the antenna reference point, m
  std::optional<double> antennaHeight;            ///< DF028 (1006 only), m above the marker
};

/// 1007/1008 and the antenna part of 1033.
struct AntennaDescriptor {
  int messageType = 1007;
  int stationId = 0;
  std::string descriptor;  ///< DF030 (IGS antenna name, e.g. "TRM59800.00     NONE")
  int setupId = 0;         ///< DF031
  std::string serial;      ///< DF033 (1008, 1033)
};

/// Receiver part of 1033.
struct ReceiverDescriptor {
  int stationId = 0;
  std::string type;      ///< DF228
  std::string firmware;  ///< DF230
  std::string serial;    ///< DF232
};

/// 1230: GLONASS L1/L2 code-phase biases (RTCM 10403.3, 3.5.16), metres.
struct GlonassCodePhaseBiases {
  int stationId = 0;
  bool aligned = false;  ///< DF421: true if the phase observations are already aligned
  std::optional<double> l1ca, l1p, l2ca, l2p;
};

}  // namespace gvins::rtcm
