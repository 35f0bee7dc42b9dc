// Reads the SSR corrections of a recorded RTCM 3 stream (e.g. a correction service's mountpoint
// saved by str2str or gvins-rtcm, or gvins-sim's gnss/ssr.rtcm3) for post-processing: every SSR
// message of the file, in stream order. EphemerisStore::addSsr keeps them as a time series, so a
// replay still sees at each epoch only what had arrived by then. Other messages (observations,
// ephemerides) are skipped.
#pragma once

#include <string>
#include <vector>

#include "gvins/base/gnss_time.hpp"
#include "gvins/ephemeris/ssr_message.hpp"
#include "gvins/rtcm/decoder.hpp"

namespace gvins::rtcm {

struct SsrFile {
  std::vector<SsrMessage> messages;
  DecoderStats stats;  ///< framing, malformed frames (with their offsets), message counts
};

/// `reference`: a time within a few days of the data (the rover's first epoch) to resolve the
/// SSR epoch times of week/day. Throws ParseError if the file cannot be opened or holds no RTCM 3
/// frame at all; malformed frames are skipped and listed in stats.issues.
SsrFile readSsrFile(const std::string& path, const GpsTime& reference);

/// RTCM 3 frames of the messages, in order. A message with more satellites than fit one frame (at
/// most 63 satellites and 1023 bytes of payload) is split into several with the multiple-message
/// bit (DF388) set on all but the last. Throws std::invalid_argument as Encoder::ssr does.
std::vector<std::uint8_t> encodeSsrFrames(const std::vector<SsrMessage>& messages);

}  // namespace gvins::rtcm
