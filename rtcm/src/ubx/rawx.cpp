#include "gvins/ubx/rawx.hpp"

#include <cmath>
#include <string>

#include "payload_reader.hpp"

namespace gvins::ubx {

RawxMessage parseRawx(std::span<const std::uint8_t> payload) {
  const detail::PayloadReader r(payload);
  RawxMessage m;
  m.rcvTow = r.r8(0, "rcvTow");
  m.week = r.u2(8, "week");
  m.leapS = r.i1(10, "leapS");
  const std::size_t numMeas = r.u1(11, "numMeas");
  m.recStat = r.u1(12, "recStat");
  m.version = r.u1(13, "version");
  r.need(14, 2, "reserved1");
  if (!std::isfinite(m.rcvTow) || m.rcvTow < 0.0 || m.rcvTow > 604800.0) {
    throw rtcm::MessageError("rcvTow", "not a time of week: " + std::to_string(m.rcvTow));
  }
  if (payload.size() < 16 + 32 * numMeas) {
    throw rtcm::MessageError("numMeas", std::to_string(numMeas) + " measurements need " +
                                            std::to_string(16 + 32 * numMeas) + " bytes, payload has " +
                                            std::to_string(payload.size()));
  }
  m.meas.resize(numMeas);
  for (std::size_t i = 0; i < numMeas; ++i) {
    const std::size_t o = 16 + 32 * i;
    RawxMeasurement& x = m.meas[i];
    x.prMes = r.r8(o, "prMes");
    x.cpMes = r.r8(o + 8, "cpMes");
    x.doMes = r.r4(o + 16, "doMes");
    x.gnssId = r.u1(o + 20, "gnssId");
    x.svId = r.u1(o + 21, "svId");
    x.sigId = r.u1(o + 22, "sigId");
    x.freqId = r.u1(o + 23, "freqId");
    x.locktime = r.u2(o + 24, "locktime");
    x.cno = r.u1(o + 26, "cno");
    x.prStdev = r.u1(o + 27, "prStdev");
    x.cpStdev = r.u1(o + 28, "cpStdev");
    x.doStdev = r.u1(o + 29, "doStdev");
    x.trkStat = r.u1(o + 30, "trkStat");
  }
  return m;
}

}  // namespace gvins::ubx
