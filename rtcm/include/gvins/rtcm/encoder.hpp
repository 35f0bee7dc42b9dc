// RTCM 3 encoder: station position (1005/1006), MSM4/MSM7 observations of every system, the
// broadcast ephemeris messages (1019, 1020, 1042, 1044, 1045, 1046) and the SSR corrections
// (1057-1068, 1240-1251, 1258-1263). Used by the simulator's base-station stream and by the
// round-trip tests; each function returns complete frames (preamble, length, payload, CRC-24Q).
//
// MSM. One message per system and epoch (split by satellites if the 64-cell or 1023-byte limits
// would be exceeded); the multiple-message bit is set on every message of the epoch but the last.
// Per satellite the rough range is the first signal's pseudorange (or phase) rounded to 1/1024 ms;
// every value is then carried as a fine value against it at the message's resolution (MSM4: code
// 2^-24 ms, phase 2^-29 ms, C/N0 1 dB-Hz; MSM7: code 2^-29 ms, phase 2^-31 ms, Doppler 0.0001 m/s,
// C/N0 1/16 dB-Hz). Values that do not fit their field are sent as "invalid". A carrier phase
// farther than the fine phase field reaches (about 1171 m) from the rough range is moved by a whole
// number of cycles, chosen when lock starts and kept while lock lasts; moving it again restarts
// the lock time, as a receiver would. Lock time counts from the first epoch of a signal, from the
// last epoch whose loss-of-lock flag (bit 0) is set, or from a gap of the signal, and is sent as the
// DF402/DF407 indicator, so a decoder recovers the loss-of-lock flags.
#pragma once

#include <cstdint>
#include <span>
#include <unordered_map>
#include <vector>

#include "gvins/base/observation.hpp"
#include "gvins/ephemeris/glonass_ephemeris.hpp"
#include "gvins/ephemeris/kepler_ephemeris.hpp"
#include "gvins/ephemeris/ssr_message.hpp"
#include "gvins/rtcm/messages.hpp"

namespace gvins::rtcm {

class Encoder {
 public:
  explicit Encoder(int stationId = 0) : stationId_(stationId) {}

  /// GLONASS FDMA channels: needed for GLONASS phase and Doppler (cycles and Hz to metres) and
  /// sent in the MSM7 extended satellite information.
  void setGlonassChannels(const GlonassChannels& channels) { channels_ = channels; }
  int stationId() const { return stationId_; }

  /// 1005, or 1006 when `p.antennaHeight` is set. Throws MessageError if a value does not fit.
  std::vector<std::uint8_t> stationPosition(const StationPosition& p) const;

  /// MSM4 (`msmType` 4) or MSM7 (7) frames for one epoch, systems in gvins::System order. Signals
  /// without an MSM signal ID are left out. Updates the lock-time state, so call it once per epoch
  /// in time order.
  std::vector<std::uint8_t> msm(const ObsEpoch& epoch, int msmType);

  /// 1019 (GPS LNAV), 1044 (QZSS), 1042 (BeiDou D1/D2), 1045 (Galileo F/NAV) or 1046 (I/NAV) by
  /// the record's message. Throws MessageError if a value does not fit its field.
  std::vector<std::uint8_t> ephemeris(const KeplerEphemeris& e) const;
  /// 1020. The four-year interval N4 and day NT are sent, so a decoder learns the absolute date.
  std::vector<std::uint8_t> ephemeris(const GlonassEphemeris& g) const;

  /// One SSR message (RTCM 10403.3, 3.5.12) in one frame: the message number follows from
  /// m.header.system and m.header.kind (GPS, GLONASS, Galileo, QZSS, BeiDou; header.messageType
  /// is checked if set). Values are rounded to their field's resolution; the epoch must be a
  /// whole second and the update interval one of the DF391 values. Splitting into several
  /// messages (DF388) is the caller's: at most 63 satellites and 1023 bytes. Throws
  /// std::invalid_argument naming the field ("DF365 delta radial: ...") if a value does not fit
  /// its field, a satellite is of another system, the kind's correction is missing or a code
  /// bias signal has no identifier.
  std::vector<std::uint8_t> ssr(const SsrMessage& m) const;

  /// Wraps a payload (at most 1023 bytes) in a frame.
  static std::vector<std::uint8_t> frame(std::span<const std::uint8_t> payload);

 private:
  struct Track {
    GpsTime lockStart;
    GpsTime last;
    double phaseOffset = 0.0;  // whole cycles added to the phase
  };
  int stationId_;
  GlonassChannels channels_;
  std::unordered_map<std::uint32_t, Track> tracks_;
  GpsTime lastEpoch_[7];
  bool haveEpoch_[7] = {};
};

}  // namespace gvins::rtcm
