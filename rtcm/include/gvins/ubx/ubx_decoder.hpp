// Streaming u-blox UBX decoder: bytes in (any chunk size; UBX mixed with NMEA and RTCM 3 as a
// receiver port or log carries them), observation epochs and the receiver's own solutions out.
//
// Observations. UBX-RXM-RAWX (gvins/ubx/rawx.hpp) becomes a gvins::ObsEpoch: time = GPS week +
// rcvTow (GPST, as the receiver tags it, not rounded); satellites and RINEX 3 codes from
// gvins/ubx/ubx_signals.hpp (unknown gnssId/svId/sigId are skipped and counted); pseudorange if
// trkStat.prValid, carrier phase if trkStat.cpValid, Doppler and C/N0 as given (u-blox and RINEX
// share the sign conventions: phase grows with the range, Doppler is positive for approaching
// satellites; tests/ubx check it against the phase rate). GLONASS freqId - 7 is the FDMA channel
// and fills glonassChannels().
// Loss of lock (RINEX 3.04 table 5.7, LLI bit 0) is flagged on a phase when its locktime
// decreased, when the locktime is shorter than the time since the signal's previous phase (lost
// and re-acquired in between), when the half-cycle-subtracted state changed (the phase jumped by
// half a cycle), at its first phase in a running stream (in the stream's first epoch only for a
// zero locktime), and on every phase of an epoch whose recStat announces a receiver clock reset
// (counted in DecoderStats::clockResets). LLI bit 1 (half-cycle ambiguity) is set while
// trkStat.halfCyc says the half cycle is not resolved.
//
// Other messages. NAV-PVT, NAV-CLOCK, NAV-TIMEGPS (gvins/ubx/nav_solution.hpp) and ESF-RAW /
// ESF-MEAS IMU samples (gvins/ubx/esf.hpp) are delivered as decoded. RXM-SFRBX messages go
// through gvins::ubx::NavigationAssembler (gvins/ubx/navigation_assembler.hpp) with the time of
// the latest RAWX epoch; the ephemerides and ionosphere parameters they complete are delivered as
// a NavDataUpdate (SFRBX before the first RAWX epoch goes in with "time not known yet", which the
// assembler resolves from the navigation data itself where it can). Every other message is only
// counted.
//
// Errors. Frames with bad checksums are skipped by the splitter and counted. A frame with a good
// checksum but impossible content (numMeas larger than the payload, rcvTow not a time of week,
// week 0) is skipped and recorded as a DecodeIssue naming its byte offset, message, field and
// what was wrong; with DecoderOptions::strict it throws gvins::ParseError instead. No input makes
// the decoder crash, hang or grow without bound.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "gvins/base/gnss_time.hpp"
#include "gvins/base/observation.hpp"
#include "gvins/ubx/esf.hpp"
#include "gvins/ubx/nav_solution.hpp"
#include "gvins/ubx/navigation_assembler.hpp"
#include "gvins/ubx/stream_splitter.hpp"

namespace gvins::ubx {

inline constexpr std::uint8_t kIdSfrbx = 0x13;

struct DecoderOptions {
  /// Name used in error messages (file name, "-").
  std::string streamName = "UBX stream";
  /// Throw gvins::ParseError on the first malformed message instead of recording it.
  bool strict = false;
  /// How many DecodeIssue records to keep (later ones are only counted).
  std::size_t maxIssues = 64;
  /// Phases whose reported standard deviation (cpStdev * 0.004 cycles) exceeds this are left out
  /// (counted in DecoderStats::noisyPhases). Default: keep every phase trkStat marks valid.
  /// RTKLIB's convbin uses 0.020 (cpStdev > 5 dropped).
  std::optional<double> maxPhaseStdDev;
  /// Assemble ephemerides from RXM-SFRBX (false: SFRBX is only counted).
  bool decodeNavigation = true;
  /// Largest UBX payload accepted (longer lengths are treated as corruption).
  std::size_t maxPayload = Framer::kDefaultMaxPayload;
};

using Decoded = std::variant<ObsEpoch, NavPvt, NavClock, NavTimeGps, ImuSample, NavDataUpdate>;

/// A malformed message (good checksum, bad content).
struct DecodeIssue {
  std::int64_t offset = 0;  ///< byte offset of the frame's first sync char
  int type = 0;             ///< class << 8 | id
  std::string field;
  std::string what;
};

struct DecoderStats {
  SplitterStats stream;                  ///< UBX/RTCM/NMEA frames and failures
  std::map<int, std::int64_t> messages;  ///< good UBX frames per class << 8 | id
  std::int64_t decoded = 0;              ///< messages decoded (RAWX, NAV-*, ESF-*, SFRBX)
  std::int64_t malformed = 0;            ///< good frames whose content was invalid
  std::int64_t epochs = 0;               ///< observation epochs delivered
  std::int64_t emptyEpochs = 0;          ///< RAWX without any usable measurement (not delivered)
  std::int64_t measurements = 0;         ///< RAWX measurement blocks read
  std::int64_t signalsDelivered = 0;     ///< signals in delivered epochs
  std::map<std::pair<int, int>, std::int64_t> signalIds;  ///< delivered signals per (gnssId, sigId)
  std::int64_t unknownSatellites = 0;    ///< measurements of IMES, unknown gnssId or svId
  std::int64_t unknownSignals = 0;       ///< measurements of unknown sigId
  std::map<std::pair<int, int>, std::int64_t> unknownSignalIds;  ///< (gnssId, sigId) -> count
  std::int64_t noisyPhases = 0;          ///< phases left out by DecoderOptions::maxPhaseStdDev
  std::int64_t clockResets = 0;          ///< RAWX epochs with recStat.clkReset
  std::int64_t slips = 0;                ///< phases flagged LLI bit 0
  std::int64_t halfCycleUnresolved = 0;  ///< phases flagged LLI bit 1
  std::int64_t sfrbx = 0;                ///< SFRBX messages read
  std::int64_t sfrbxUndated = 0;         ///< SFRBX before the first RAWX epoch (no receive time)
  std::int64_t ephemerides = 0;          ///< ephemeris records delivered (NavDataUpdate)
  std::int64_t imuSamples = 0;           ///< ESF samples delivered
  std::optional<GpsTime> firstEpoch, lastEpoch;
  std::optional<int> leapSeconds;        ///< GPS - UTC from RAWX (leapSec flag) or NAV-TIMEGPS
  std::vector<DecodeIssue> issues;       ///< the first DecoderOptions::maxIssues malformed frames
};

class Decoder {
 public:
  explicit Decoder(DecoderOptions options = {});
  ~Decoder();
  Decoder(Decoder&&) noexcept;
  Decoder& operator=(Decoder&&) noexcept;

  /// Feeds bytes and decodes every frame completed by them. Results queue up for poll().
  void feed(std::span<const std::uint8_t> bytes);
  /// End of stream: decodes complete frames after a truncated one and counts the truncated frame.
  void finish();
  /// Next decoded item, in stream order.
  std::optional<Decoded> poll();

  /// Decodes one UBX message (class, id, payload without header and checksum), e.g. from another
  /// transport. `offset` is used in error reports.
  void decodeMessage(std::uint8_t msgClass, std::uint8_t msgId, std::span<const std::uint8_t> payload,
                     std::int64_t offset = 0);

  const DecoderStats& stats() const;
  /// GLONASS FDMA channels seen in RAWX freqId.
  const GlonassChannels& glonassChannels() const;
  /// Counters of the navigation message assembler (parity/CRC failures etc.).
  NavigationCounts navigationCounts() const;
  /// The assembler itself: counters per system and per gnssId/sigId.
  const NavigationAssembler& navigationAssembler() const;
  /// Time of the latest RAWX epoch.
  std::optional<GpsTime> lastEpochTime() const;

  struct State;

 private:
  std::unique_ptr<State> s_;
};

}  // namespace gvins::ubx
