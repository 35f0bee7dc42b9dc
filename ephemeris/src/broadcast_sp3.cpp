#include "gvins/ephemeris/broadcast_sp3.hpp"

#include <stdexcept>

#include "gvins/base/constants.hpp"

namespace gvins {

Sp3Data broadcastSp3(const EphemerisStore& nav, const GpsTime& start, const GpsTime& end, double interval,
                     std::vector<SatId> sats) {
  if (!(interval > 0.0) || end < start) throw std::invalid_argument("broadcastSp3: empty time span or interval <= 0");
  Sp3Data d;
  d.interval = interval;
  d.orbitType = "BCT";
  d.agency = "BRD";
  d.dataUsed = "ORBIT";
  d.satellites = sats.empty() ? nav.satellites() : std::move(sats);
  d.accuracyExponent.assign(d.satellites.size(), 0);
  d.comments = {"broadcast ephemerides (antenna phase centre) sampled by SRI-GVINS"};
  const double c = constants::kSpeedOfLight;
  for (GpsTime t = start; t <= end; t = t + interval) {
    Sp3Epoch ep;
    ep.time = t;
    for (SatId s : d.satellites) {
      Sp3Record r;
      r.sat = s;
      if (const auto st = nav.satelliteState(s, t)) {
        r.position = st->position;
        // SP3 clocks exclude the periodic relativistic term −2 r·v/c² (IS-GPS-200 20.3.3.3.3.1).
        r.clock = st->clockBias + 2.0 * st->position.dot(st->velocity) / (c * c);
      }
      ep.records.push_back(r);
    }
    d.epochs.push_back(std::move(ep));
  }
  return d;
}

}  // namespace gvins
