#include "gvins/sim/gnss_rtcm_stream.hpp"

#include <cmath>

#include "gvins/rtcm/message_error.hpp"
#include "gvins/rtcm/messages.hpp"

namespace gvins::sim {

GnssRtcmStream::GnssRtcmStream(const GnssRtcmConfig& config, const EphemerisStore& nav, const Eigen::Vector3d& arp,
                               const GlonassChannels& channels)
    : config_(config), nav_(nav), arp_(arp), encoder_(config.stationId) {
  encoder_.setGlonassChannels(channels);
}

void GnssRtcmStream::append(const std::vector<std::uint8_t>& frames, std::vector<std::uint8_t>& out) {
  // Count the frames by message number (RTCM 10403.3, 4: preamble, 10-bit length, payload, CRC).
  std::size_t i = 0;
  while (i + 6 <= frames.size()) {
    const std::size_t len = (static_cast<std::size_t>(frames[i + 1] & 0x03) << 8) | frames[i + 2];
    const int type = len >= 2 ? (frames[i + 3] << 4) | (frames[i + 4] >> 4) : -1;
    ++counts_[type];
    i += len + 6;
  }
  out.insert(out.end(), frames.begin(), frames.end());
}

void GnssRtcmStream::ephemerides(const ObsEpoch& epoch, std::vector<std::uint8_t>& out) {
  EphemerisSelection realTime;
  realTime.futureTolerance = -1.0;  // only what has been broadcast by now
  const GpsTime t = epoch.time;
  const double interval = config_.ephemerisInterval;
  for (const SatObs& so : epoch.sats) {
    const SatId sat = so.sat;
    // A fixed phase per satellite spreads the repetitions over the cycle.
    const double phase = std::fmod(static_cast<double>(satIndex(sat)) * 7.919, 1.0) * interval;
    const std::int64_t cycle = static_cast<std::int64_t>(std::floor((t.toSecondsApprox() + phase) / interval));
    auto send = [&](int kind, const GpsTime& toe, int iode, auto&& encode) {
      Sent& s = sent_[static_cast<std::uint32_t>(satIndex(sat)) * 8u + static_cast<std::uint32_t>(kind)];
      if (s.iode == iode && s.toe == toe && s.cycle == cycle) return;
      try {
        append(encode(), out);
      } catch (const rtcm::MessageError&) {
        ++skipped_;
      }
      s.iode = iode;
      s.toe = toe;
      s.cycle = cycle;
      s.time = t;
    };
    if (sat.system == System::Glonass) {
      if (const GlonassEphemeris* g = nav_.selectGlonass(sat, t, realTime))
        send(0, g->toe, g->iode, [&] { return encoder_.ephemeris(*g); });
    } else if (sat.system == System::Galileo) {
      EphemerisSelection inav = realTime, fnav = realTime;
      fnav.preferGalileoInav = false;
      const KeplerEphemeris* a = nav_.selectKepler(sat, t, inav);
      const KeplerEphemeris* b = nav_.selectKepler(sat, t, fnav);
      if (a) send(static_cast<int>(a->message), a->toe, a->iode, [&] { return encoder_.ephemeris(*a); });
      if (b && b != a) send(static_cast<int>(b->message), b->toe, b->iode, [&] { return encoder_.ephemeris(*b); });
    } else if (sat.system != System::Sbas && sat.system != System::Navic) {
      if (const KeplerEphemeris* e = nav_.selectKepler(sat, t, realTime))
        send(1, e->toe, e->iode, [&] { return encoder_.ephemeris(*e); });
    }
  }
}

void GnssRtcmStream::addEpoch(const ObsEpoch& epoch, std::vector<std::uint8_t>& out) {
  if (!started_ || epoch.time - lastStation_ >= config_.stationInterval - 1e-6) {
    rtcm::StationPosition p;
    p.stationId = config_.stationId;
    p.gps = p.glonass = p.galileo = true;
    p.arp = arp_;
    if (config_.antennaHeight) {
      p.messageType = 1006;
      p.antennaHeight = *config_.antennaHeight;
    }
    append(encoder_.stationPosition(p), out);
    lastStation_ = epoch.time;
    started_ = true;
  }
  ephemerides(epoch, out);
  if (!epoch.sats.empty()) append(encoder_.msm(epoch, config_.msm), out);
}

}  // namespace gvins::sim
