// The base station's RTCM 3 stream as a caster would serve it: 1005 (or 1006 with an antenna
// height) every `stationInterval`, the broadcast ephemeris of every tracked satellite (1019 GPS,
// 1020 GLONASS, 1042 BeiDou, 1044 QZSS, 1045/1046 Galileo F/NAV and I/NAV) when first tracked,
// when its issue of data changes and then every `ephemerisInterval` (staggered per satellite, so
// a 60 s cycle sends a few messages each second), and MSM4 or MSM7 observations of every epoch.
// Ephemerides are those a receiver could have decoded by then (transmission time not after the
// epoch).
#pragma once

#include <cstdint>
#include <map>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>

#include "gvins/ephemeris/ephemeris_store.hpp"
#include "gvins/rtcm/encoder.hpp"
#include "gvins/sim/gnss_sim_config.hpp"

namespace gvins::sim {

class GnssRtcmStream {
 public:
  /// `nav` must outlive the stream. `arp`: antenna reference point (ECEF, m).
  GnssRtcmStream(const GnssRtcmConfig& config, const EphemerisStore& nav, const Eigen::Vector3d& arp,
                 const GlonassChannels& channels);

  /// Appends the frames due at this base epoch (station and ephemeris messages first, then MSM).
  void addEpoch(const ObsEpoch& epoch, std::vector<std::uint8_t>& out);

  /// Frames written per message number.
  const std::map<int, std::int64_t>& messageCounts() const { return counts_; }
  /// Ephemeris records that did not fit their message fields (left out).
  std::int64_t skippedEphemerides() const { return skipped_; }

 private:
  void append(const std::vector<std::uint8_t>& frames, std::vector<std::uint8_t>& out);
  void ephemerides(const ObsEpoch& epoch, std::vector<std::uint8_t>& out);

  struct Sent {
    GpsTime time;
    GpsTime toe;
    int iode = -1;
    std::int64_t cycle = -1;
  };
  GnssRtcmConfig config_;
  const EphemerisStore& nav_;
  Eigen::Vector3d arp_;
  rtcm::Encoder encoder_;
  bool started_ = false;
  GpsTime lastStation_;
  std::unordered_map<std::uint32_t, Sent> sent_;  // key: satIndex * 8 + message kind
  std::map<int, std::int64_t> counts_;
  std::int64_t skipped_ = 0;
};

}  // namespace gvins::sim
