#include "gvins/gnss/broadcast_record_change.hpp"

#include "gvins/base/constants.hpp"
#include "gvins/ephemeris/satellite_state.hpp"

namespace gvins {

std::optional<BroadcastRecord> selectedBroadcastRecord(const EphemerisStore& nav, SatId sat, const GpsTime& t) {
  if (sat.system == System::Glonass) {
    if (const GlonassEphemeris* g = nav.selectGlonass(sat, t)) return BroadcastRecord{*g};
    return std::nullopt;
  }
  if (const KeplerEphemeris* e = nav.selectKepler(sat, t)) return BroadcastRecord{*e};
  return std::nullopt;
}

bool sameBroadcastRecord(const BroadcastRecord& a, const BroadcastRecord& b) {
  if (a.record.index() != b.record.index()) return false;
  if (const auto* ka = std::get_if<KeplerEphemeris>(&a.record)) {
    const auto& kb = std::get<KeplerEphemeris>(b.record);
    return ka->sat == kb.sat && ka->message == kb.message && ka->toe == kb.toe && ka->iode == kb.iode &&
           ka->toc == kb.toc;
  }
  const auto& ga = std::get<GlonassEphemeris>(a.record);
  const auto& gb = std::get<GlonassEphemeris>(b.record);
  return ga.sat == gb.sat && ga.toe == gb.toe && ga.iode == gb.iode;
}

namespace {

double modelledRange(const BroadcastRecord& r, const GpsTime& t, const Eigen::Vector3d& receiver) {
  const SatelliteState s = std::visit(
      [&](const auto& rec) -> SatelliteState {
        using T = std::decay_t<decltype(rec)>;
        if constexpr (std::is_same_v<T, KeplerEphemeris>) {
          return keplerSatelliteState(rec, t);
        } else {
          return glonassSatelliteState(rec, t);
        }
      },
      r.record);
  return (s.position - receiver).norm() - constants::kSpeedOfLight * s.clockBias;
}

}  // namespace

double broadcastRecordRangeChange(const BroadcastRecord& from, const BroadcastRecord& to, const GpsTime& t,
                                  const Eigen::Vector3d& receiver) {
  return modelledRange(to, t, receiver) - modelledRange(from, t, receiver);
}

BroadcastRecordContinuity::Step BroadcastRecordContinuity::update(const EphemerisStore& nav, SatId sat,
                                                                  const GpsTime& selectTime, const GpsTime& transmitTime,
                                                                  const Eigen::Vector3d& receiver) {
  Step step;
  std::optional<BroadcastRecord> rec = selectedBroadcastRecord(nav, sat, selectTime);
  if (!rec) return step;
  step.found = true;
  if (!record_) {
    record_ = std::move(rec);
  } else if (!sameBroadcastRecord(*record_, *rec)) {
    step.changed = true;
    step.jump = broadcastRecordRangeChange(*record_, *rec, transmitTime, receiver);
    shift_ += step.jump;
    record_ = std::move(rec);
  }
  return step;
}

}  // namespace gvins
