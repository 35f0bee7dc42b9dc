// UBX-RXM-RAWX (class 0x02, id 0x15): the receiver's raw measurements of one epoch, as
// transmitted (u-blox M8 protocol 20+, ZED-F9P HPG 1.32 and X20 HPG 2.00 interface descriptions,
// "UBX-RXM-RAWX"). Payload: 16-byte header, then 32 bytes per measurement.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace gvins::ubx {

inline constexpr std::uint8_t kClassRxm = 0x02;
inline constexpr std::uint8_t kIdRawx = 0x15;

struct RawxMeasurement {
  double prMes = 0.0;   ///< pseudorange, m
  double cpMes = 0.0;   ///< carrier phase, cycles (same sign as the pseudorange)
  float doMes = 0.0f;   ///< Doppler, Hz, positive for approaching satellites
  std::uint8_t gnssId = 0, svId = 0, sigId = 0;
  std::uint8_t freqId = 0;     ///< GLONASS: FDMA channel + 7 (0..13)
  std::uint16_t locktime = 0;  ///< carrier phase locktime, ms (saturates at 64500)
  std::uint8_t cno = 0;        ///< C/N0, dB-Hz
  std::uint8_t prStdev = 0;    ///< 0.01 m * 2^n (bits 0-3)
  std::uint8_t cpStdev = 0;    ///< 0.004 cycles * n (bits 0-3); 15 = invalid
  std::uint8_t doStdev = 0;    ///< 0.002 Hz * 2^n (bits 0-3)
  std::uint8_t trkStat = 0;    ///< bit 0 prValid, 1 cpValid, 2 halfCyc (valid), 3 subHalfCyc

  bool prValid() const { return trkStat & 1; }
  bool cpValid() const { return trkStat & 2; }
  /// Half-cycle ambiguity resolved (phase usable without a half-cycle uncertainty).
  bool halfCycleValid() const { return trkStat & 4; }
  /// A half cycle has been subtracted from the phase.
  bool halfCycleSubtracted() const { return trkStat & 8; }
  double pseudorangeStdDev() const { return 0.01 * static_cast<double>(1u << (prStdev & 0x0F)); }
  double phaseStdDev() const { return 0.004 * (cpStdev & 0x0F); }
  double dopplerStdDev() const { return 0.002 * static_cast<double>(1u << (doStdev & 0x0F)); }
};

struct RawxMessage {
  double rcvTow = 0.0;      ///< receiver time of week, s (GPS time scale)
  std::uint16_t week = 0;   ///< GPS week (full)
  std::int8_t leapS = 0;    ///< GPS - UTC leap seconds
  std::uint8_t recStat = 0; ///< bit 0 leapSec (leapS determined), bit 1 clkReset
  std::uint8_t version = 0;
  std::vector<RawxMeasurement> meas;

  bool leapSecondsKnown() const { return recStat & 1; }
  bool clockReset() const { return recStat & 2; }
};

/// Parses a RXM-RAWX payload. Throws rtcm::MessageError naming the field when the payload is
/// shorter than its numMeas announces (16 + 32 * numMeas bytes) or when rcvTow is not a time of
/// week (not finite or outside 0..604800 s). Bytes after the last measurement are ignored.
RawxMessage parseRawx(std::span<const std::uint8_t> payload);

}  // namespace gvins::ubx
