#include "gvins/ephemeris/ssr_from_products.hpp"

#include <cmath>
#include <optional>

#include <Eigen/Geometry>

#include "gvins/base/constants.hpp"

namespace gvins {

namespace {

int messageType(System s) {
  switch (s) {
    case System::Gps: return 1060;
    case System::Glonass: return 1066;
    case System::Galileo: return 1243;
    case System::Qzss: return 1249;
    case System::BeiDou: return 1261;
    default: return 0;
  }
}

// Broadcast record the receiver holds at `epoch` (nothing transmitted after it) and its state at t.
struct Broadcast {
  int issueOfData = 0;
  SatelliteState at(const GpsTime& t) const {
    return kepler ? keplerSatelliteState(*kepler, t) : glonassSatelliteState(*glonass, t);
  }
  const KeplerEphemeris* kepler = nullptr;
  const GlonassEphemeris* glonass = nullptr;
};

std::optional<Broadcast> heldRecord(const EphemerisStore& nav, SatId sat, const GpsTime& epoch) {
  EphemerisSelection policy;
  policy.futureTolerance = -1.0;
  Broadcast b;
  if (sat.system == System::Glonass) {
    b.glonass = nav.selectGlonass(sat, epoch, policy);
    if (!b.glonass) return std::nullopt;
    b.issueOfData = ssrIssueOfData(*b.glonass);
  } else {
    b.kepler = nav.selectKepler(sat, epoch, policy);
    if (!b.kepler) return std::nullopt;
    b.issueOfData = ssrIssueOfData(*b.kepler);
  }
  return b;
}

// broadcast − precise in the radial / along / cross frame of the broadcast state (the quantity an
// SSR orbit correction carries; applySsr subtracts it again); nullopt for a degenerate velocity.
std::optional<Eigen::Vector3d> racDifference(const SatelliteState& b, const SatelliteState& p) {
  const auto frame = ssrOrbitFrame(b);
  if (!frame) return std::nullopt;
  return Eigen::Vector3d(frame->transpose() * (b.position - p.position));
}

}  // namespace

std::vector<SsrMessage> ssrFromProducts(const EphemerisStore& broadcast, const EphemerisStore& products,
                                        const GpsTime& start, const GpsTime& end, const SsrServiceConfig& config) {
  std::vector<SsrMessage> out;
  if (!(config.interval > 0.0)) return out;
  const std::vector<SatId> sats = broadcast.satellites();
  const double first = std::ceil((start - GpsTime{}) / config.interval) * config.interval;
  for (GpsTime epoch = GpsTime{} + first; epoch <= end; epoch += config.interval) {
    const GpsTime ref = epoch + 0.5 * config.interval;
    for (System sys : {System::Gps, System::Glonass, System::Galileo, System::Qzss, System::BeiDou}) {
      SsrMessage m;
      m.header.messageType = messageType(sys);
      m.header.system = sys;
      m.header.kind = SsrKind::kCombined;
      m.header.epoch = epoch;
      m.header.updateInterval = config.interval;
      m.header.iodSsr = config.iodSsr;
      m.header.providerId = config.providerId;
      m.header.solutionId = config.solutionId;
      for (SatId sat : sats) {
        if (sat.system != sys) continue;
        const auto rec = heldRecord(broadcast, sat, epoch);
        if (!rec) continue;
        const auto p0 = products.preciseState(sat, ref);
        const auto pm = products.preciseState(sat, ref - 0.5);
        const auto pp = products.preciseState(sat, ref + 0.5);
        if (!p0 || !pm || !pp) continue;
        const SatelliteState b0 = rec->at(ref), bm = rec->at(ref - 0.5), bp = rec->at(ref + 0.5);
        const auto d0 = racDifference(b0, *p0), dm = racDifference(bm, *pm), dp = racDifference(bp, *pp);
        if (!d0 || !dm || !dp) continue;
        SsrSatellite s;
        s.sat = sat;
        SsrOrbitCorrection o;
        o.issueOfData = rec->issueOfData;
        if (rec->kepler && sat.system == System::BeiDou) o.iodCrc = ssrBeidouIod(*rec->kepler);
        o.rac = *d0;
        o.racRate = *dp - *dm;
        s.orbit = o;
        SsrClockCorrection c;
        c.c0 = (p0->clockBias - b0.clockBias) * constants::kSpeedOfLight;
        c.c1 = ((pp->clockBias - bp.clockBias) - (pm->clockBias - bm.clockBias)) * constants::kSpeedOfLight;
        s.clock = c;
        m.satellites.push_back(std::move(s));
      }
      if (!m.satellites.empty()) out.push_back(std::move(m));
    }
  }
  return out;
}

}  // namespace gvins
