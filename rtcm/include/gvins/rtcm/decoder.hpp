// Streaming RTCM 3 decoder: bytes in (any chunk size), observation epochs, ephemerides, SSR
// corrections and station descriptions out.
//
// Observations. Legacy messages 1001-1004 (GPS, SBAS), 1009-1012 (GLONASS) and MSM1-MSM7 of GPS,
// GLONASS, Galileo, SBAS, QZSS and BeiDou become gvins::ObsEpoch in GPST with RINEX 3 signal
// codes. Messages of one epoch are merged while the multiple-message bit (MSM DF393, legacy DF005)
// announces more; an epoch is also closed when a message with a different time arrives, so a
// stream that never clears the bit still yields epochs (one epoch late). Lock-time indicators
// become RINEX loss-of-lock flags (bit 0) per satellite and signal, the MSM half-cycle flag becomes
// bit 1. A signal is flagged when its lock-time indicator decreases, when the indicator's upper
// bound is not longer than the time since the signal's last observation (re-acquired after a
// gap), and at its first observation in a running stream (not in the stream's first epoch,
// where only a zero lock time is flagged). Legacy phase-range rollovers of +-1500 cycles (RTCM 10403.3, DF012 note) are undone.
//
// Ephemerides and SSR. 1019 (GPS), 1020 (GLONASS), 1042 (BeiDou), 1044 (QZSS), 1045/1046
// (Galileo F/NAV, I/NAV) become gvins::KeplerEphemeris / gvins::GlonassEphemeris; 1230 the GLONASS
// code-phase biases. The SSR messages of RTCM 10403.3 section 3.5.12 (orbit, clock, code bias,
// combined orbit and clock, URA, high-rate clock) of GPS 1057-1062, GLONASS 1063-1068, Galileo
// 1240-1245, QZSS 1246-1251 and BeiDou 1258-1263 become one gvins::SsrMessage each (no merging of
// multiple messages), with the epoch time resolved to GPST like the observation times and
// code-bias signal identifiers mapped to RINEX codes (reserved identifiers are skipped and counted
// in DecoderStats::unknownBiasSignals). SBAS SSR (1252-1257), phase biases (1265-1270), VTEC
// (1264) and IGS SSR (4076) are not decoded.
//
// Time. Times of week (GPS, Galileo, QZSS, SBAS; BeiDou BDT = GPST - 14 s), GLONASS times of day
// (Moscow time) and truncated week numbers are resolved to the instant nearest a reference time.
// The reference is DecoderOptions::referenceTime, then follows the decoded observation and SSR
// epochs (so week rollovers are crossed naturally). Without an option the host clock is used until the stream
// gives an absolute time: a Galileo (12-bit GST week) or BeiDou (13-bit BDT week) ephemeris, or a
// GLONASS 1020 with its four-year interval N4 and day NT; epochs decoded before that carry the
// host-clock week.
//
// BeiDou time stamped as GPS time. Some receivers (e.g. the GMSD log of RTKLIB's test data) fill
// the BeiDou MSM epoch time with GPS time of week instead of BDT. Read as BDT such an epoch lands
// exactly 14 s after the epoch of the other systems it belongs to. The decoder therefore checks
// every BeiDou MSM time against the open (or just closed) epoch of the other systems: if reading
// it as GPST makes the two coincide (within 1 ms) while reading it as BDT does not, it is read as
// GPST, merged into that epoch and counted in DecoderStats::beidouGpstEpochs. If the BeiDou
// message comes first in its epoch, the BeiDou-only epoch it opened (read as BDT) is retimed when
// the other systems' messages arrive exactly 14 s earlier. Once seen, GPST stamping is assumed for
// BeiDou messages that have no epoch of another system to compare with (until a BeiDou time
// matches as BDT again), so the order of messages within an epoch does not matter. BeiDou SSR
// epoch times (DF465) are always read as BDT.
//
// Errors. Frames with bad CRCs are skipped by the framer and counted. A frame with a good CRC but
// impossible content (too short for its satellite/cell counts, out-of-range fields) is skipped and
// recorded as a DecodeIssue naming its byte offset, message type, field and what was wrong; with
// DecoderOptions::strict it throws gvins::ParseError instead. No input makes the decoder crash,
// hang or grow without bound.
#pragma once

#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include "gvins/base/gnss_time.hpp"
#include "gvins/base/observation.hpp"
#include "gvins/ephemeris/glonass_ephemeris.hpp"
#include "gvins/ephemeris/kepler_ephemeris.hpp"
#include "gvins/ephemeris/ssr_message.hpp"
#include "gvins/rtcm/framer.hpp"
#include "gvins/rtcm/messages.hpp"

namespace gvins::rtcm {

struct DecoderOptions {
  /// A time within a few days of the data (e.g. the session date); see the file comment.
  std::optional<GpsTime> referenceTime;
  /// Name used in error messages (file name, URL).
  std::string streamName = "RTCM stream";
  /// Throw gvins::ParseError on the first malformed message instead of recording it.
  bool strict = false;
  /// GLONASS FDMA channels known beforehand (e.g. from a navigation file); 1020 messages and
  /// MSM5/MSM7 extended satellite information add to them.
  GlonassChannels glonassChannels;
  /// How many DecodeIssue records to keep (later ones are only counted).
  std::size_t maxIssues = 64;
};

/// What the decoder delivers.
using Decoded = std::variant<ObsEpoch, StationPosition, AntennaDescriptor, ReceiverDescriptor,
                             KeplerEphemeris, GlonassEphemeris, GlonassCodePhaseBiases, SsrMessage>;

/// A malformed message (good CRC, bad content).
struct DecodeIssue {
  std::int64_t offset = 0;  ///< byte offset of the frame's preamble
  int type = 0;             ///< message number
  std::string field;        ///< data field being read
  std::string what;
};

struct DecoderStats {
  FramerStats framing;
  std::map<int, std::int64_t> messages;  ///< good-CRC frames per message number (-1: empty)
  std::int64_t decoded = 0;              ///< messages decoded
  std::int64_t unsupported = 0;          ///< good frames of types this decoder does not decode
  std::int64_t malformed = 0;            ///< good frames whose content was invalid
  std::int64_t epochs = 0;               ///< observation epochs delivered
  std::int64_t beidouGpstEpochs = 0;     ///< BeiDou MSM messages found stamped in GPST
  std::int64_t glonassNoChannel = 0;     ///< GLONASS signals whose phase/Doppler was dropped
                                         ///< because the FDMA channel was unknown
  std::int64_t unknownSatellites = 0;    ///< observation cells of satellites out of range
  std::int64_t unknownSignals = 0;       ///< MSM cells of reserved signal IDs
  std::int64_t unresolvedRanges = 0;     ///< 1001/1003/1009/1011 satellites and MSM1-3 cells
                                         ///< dropped: whole milliseconds of the range unknown
                                         ///< (no recent full range of the satellite)
  std::int64_t ephemerides = 0;          ///< ephemeris records delivered
  std::int64_t ssrMessages = 0;          ///< SSR messages delivered
  std::int64_t unknownBiasSignals = 0;   ///< SSR code biases of reserved signal identifiers
                                         ///< (skipped)
  std::optional<GpsTime> firstEpoch, lastEpoch;
  std::vector<DecodeIssue> issues;       ///< the first DecoderOptions::maxIssues malformed frames
};

class Decoder {
 public:
  explicit Decoder(DecoderOptions options = {});
  ~Decoder();
  Decoder(Decoder&&) noexcept;
  Decoder& operator=(Decoder&&) noexcept;

  /// Feeds bytes and decodes every frame completed by them. Results queue up for poll(); feed
  /// chunks (e.g. 64 KiB) and poll in between to keep the queue short.
  void feed(std::span<const std::uint8_t> bytes);
  /// End of stream: decodes complete frames after a truncated one, counts the truncated frame
  /// and delivers the pending epoch.
  void finish();
  /// Next decoded item, in stream order.
  std::optional<Decoded> poll();

  /// Decodes one message payload (no transport header/CRC), e.g. from another transport.
  /// `offset` is used in error reports.
  void decodeMessage(std::span<const std::uint8_t> payload, std::int64_t offset = 0);

  const DecoderStats& stats() const;
  /// Station description accumulated from 1005-1008 and 1033 (approxPosition is the marker:
  /// the ARP lowered by the 1006 antenna height along the ellipsoid normal).
  const StationInfo& station() const;
  /// Latest 1005/1006.
  const std::optional<StationPosition>& stationPosition() const;
  /// GLONASS channels from the options, 1020 and MSM5/MSM7.
  const GlonassChannels& glonassChannels() const;
  /// Latest 1230.
  const std::optional<GlonassCodePhaseBiases>& glonassBiases() const;
  /// Current reference time (the last epoch once epochs have been decoded).
  GpsTime referenceTime() const;
  /// Whether the reference came from the options or from an absolute time in the stream (rather
  /// than from the host clock).
  bool referenceIsAbsolute() const;

  struct State;

 private:
  std::unique_ptr<State> s_;
};

}  // namespace gvins::rtcm
