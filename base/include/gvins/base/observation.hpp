// Raw GNSS observations of one receiver epoch: per satellite, per signal pseudorange, carrier
// phase, Doppler and C/N0 with loss-of-lock flags. Filled by the RINEX and RTCM readers and by the
// simulator; consumed by SPP, RTK and the fusion.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "gvins/base/gnss_time.hpp"
#include "gvins/base/satellite.hpp"
#include "gvins/base/signal.hpp"

namespace gvins {

/// One signal of one satellite.
struct SignalObs {
  ObsCode code;
  double pseudorange = 0.0;   ///< m
  double carrierPhase = 0.0;  ///< cycles; RINEX convention: same sign as the pseudorange
                              ///< (grows as the range grows)
  double doppler = 0.0;       ///< Hz; positive for approaching satellites (range rate = -lambda*D)
  double snr = 0.0;           ///< C/N0, dB-Hz
  /// RINEX loss-of-lock indicator: bit 0 lost lock (cycle slip possible) since the previous
  /// epoch, bit 1 half-cycle ambiguity/opposite wavelength factor, bit 2 BOC tracking / anti-spoofing.
  std::uint8_t lli = 0;
  /// RINEX signal strength indicator 1..9 (0 = unknown) of the phase observation.
  std::uint8_t ssi = 0;
  /// Bit set of which values are present (a RINEX blank field is absent, not zero).
  std::uint8_t present = 0;

  static constexpr std::uint8_t kCode = 1, kPhase = 2, kDoppler = 4, kSnr = 8;
  bool hasCode() const { return present & kCode; }
  bool hasPhase() const { return present & kPhase; }
  bool hasDoppler() const { return present & kDoppler; }
  bool hasSnr() const { return present & kSnr; }
  void setCode(double v) { pseudorange = v; present |= kCode; }
  void setPhase(double v) { carrierPhase = v; present |= kPhase; }
  void setDoppler(double v) { doppler = v; present |= kDoppler; }
  void setSnr(double v) { snr = v; present |= kSnr; }
  bool lossOfLock() const { return lli & 1; }
  bool halfCycle() const { return lli & 2; }
};

/// All signals of one satellite in an epoch.
struct SatObs {
  SatId sat;
  std::vector<SignalObs> signals;

  /// The signal with this code, or nullptr.
  const SignalObs* find(ObsCode code) const;
  SignalObs* find(ObsCode code);
  /// The best signal on a band (by attributePriority) that has the requested values
  /// (a SignalObs::k* mask), or nullptr.
  const SignalObs* bestOnBand(char band, std::uint8_t need = SignalObs::kCode) const;
};

/// RINEX epoch flags (RINEX 3.05, table A13).
enum class EpochFlag : std::uint8_t {
  Ok = 0,
  PowerFailure = 1,
  MovingAntenna = 2,
  NewSite = 3,
  HeaderInformation = 4,
  ExternalEvent = 5,
  CycleSlipRecords = 6,
};

/// One receiver epoch.
struct ObsEpoch {
  GpsTime time;  ///< receiver time tag, GPST
  EpochFlag flag = EpochFlag::Ok;
  std::optional<double> receiverClockOffset;  ///< s, if the receiver reported it
  std::vector<SatObs> sats;

  const SatObs* find(SatId s) const;
  SatObs* find(SatId s);
  /// Appends (or finds) the entry of a satellite.
  SatObs& add(SatId s);
};

/// GLONASS FDMA channel numbers per slot (R01..R27), as given in RINEX "GLONASS SLOT / FRQ #",
/// RTCM 1020 or a navigation message.
class GlonassChannels {
 public:
  void set(int slot, int channel);
  std::optional<int> get(int slot) const;
  bool empty() const;
  /// Fills slots that are missing here from another table.
  void mergeMissing(const GlonassChannels& other);

 private:
  std::array<std::int8_t, 28> k_{};
  std::array<bool, 28> known_{};
};

/// What a receiver/station says about itself (RINEX header, RTCM 1005-1008/1033).
struct StationInfo {
  std::string markerName;
  std::string markerNumber;
  std::string receiverType;
  std::string receiverNumber;
  std::string receiverVersion;
  std::string antennaType;
  std::string antennaNumber;
  std::optional<Eigen::Vector3d> approxPosition;   ///< ECEF, m
  Eigen::Vector3d antennaDeltaHen = Eigen::Vector3d::Zero();  ///< height, east, north of the ARP, m
};

}  // namespace gvins
