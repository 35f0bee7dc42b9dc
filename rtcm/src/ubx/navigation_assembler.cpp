#include "gvins/ubx/navigation_assembler.hpp"

#include "beidou_d1.hpp"
#include "beidou_d2.hpp"
#include "galileo_inav.hpp"
#include "glonass_strings.hpp"
#include "gps_cnav.hpp"
#include "gps_lnav.hpp"
#include "gvins/ephemeris/ephemeris_store.hpp"
#include "gvins/ubx/ubx_signals.hpp"

namespace gvins::ubx {
namespace {

// u-blox sigIds of the CNAV signals (interface description, "Signal identifiers"): GPS L2 CL/CM
// (3, 4), L5 I/Q (6, 7); QZSS L2 CM/CL (4, 5), L5 I/Q (8, 9).
bool isCnavSignal(System system, std::uint8_t sigId) {
  if (system == System::Gps) return sigId == 3 || sigId == 4 || sigId == 6 || sigId == 7;
  return sigId == 4 || sigId == 5 || sigId == 8 || sigId == 9;
}

}  // namespace

bool NavDataUpdate::empty() const {
  return kepler.empty() && glonass.empty() && cnav.empty() && !ionosphere.gps && !ionosphere.qzss && !ionosphere.beidou &&
         !ionosphere.galileo;
}

void NavDataUpdate::addTo(EphemerisStore& store) const {
  for (const KeplerEphemeris& e : kepler) store.add(e);
  for (const GlonassEphemeris& g : glonass) store.add(g);
  for (const CnavGroupDelays& c : cnav) store.add(c);
  IonosphereParameters& iono = store.ionosphere();
  if (ionosphere.gps) iono.gps = ionosphere.gps;
  if (ionosphere.qzss) iono.qzss = ionosphere.qzss;
  if (ionosphere.beidou) iono.beidou = ionosphere.beidou;
  if (ionosphere.galileo) iono.galileo = ionosphere.galileo;
}

struct NavigationAssembler::State {
  detail::GpsLnavDecoder lnav;
  detail::GpsCnavDecoder cnav;
  detail::GalileoInavDecoder inav;
  detail::BeidouD1Decoder d1;
  detail::BeidouD2Decoder d2;
  detail::GlonassDecoder glonass;
};

NavigationAssembler::NavigationAssembler() : state_(std::make_unique<State>()) {}
NavigationAssembler::~NavigationAssembler() = default;
NavigationAssembler::NavigationAssembler(NavigationAssembler&&) noexcept = default;
NavigationAssembler& NavigationAssembler::operator=(NavigationAssembler&&) noexcept = default;

NavigationCounts& NavigationCounts::operator+=(const NavigationCounts& o) {
  messages += o.messages;
  parityFailures += o.parityFailures;
  crcFailures += o.crcFailures;
  incompleteSets += o.incompleteSets;
  unknownMessages += o.unknownMessages;
  skipped += o.skipped;
  ephemerides += o.ephemerides;
  ionosphere += o.ionosphere;
  groupDelays += o.groupDelays;
  return *this;
}

NavDataUpdate NavigationAssembler::add(const SfrbxMessage& msg, const GpsTime& receiveTime) {
  NavDataUpdate out;
  NavigationCounts delta;
  delta.messages = 1;
  NavigationSource source{msg.gnssId, msg.sigId, false};
  // u-blox gnssId (interface description, "GNSS identifiers"); IMES and reserved values unknown.
  const std::optional<System> system = systemOfGnssId(msg.gnssId);
  if (!system) {
    ++unknownGnss_;
    delta.unknownMessages = 1;
    bySource_[source] += delta;
    return out;
  }
  const SatId sat(*system, msg.svId);
  source.beidouGeo = *system == System::BeiDou && sat.valid() && isBeiDouGeo(sat);
  dispatch(msg, *system, receiveTime, out, delta);
  counts_[static_cast<std::size_t>(systemIndex(*system))] += delta;
  bySource_[source] += delta;
  return out;
}

void NavigationAssembler::dispatch(const SfrbxMessage& msg, System system, const GpsTime& receiveTime,
                                   NavDataUpdate& out, NavigationCounts& c) {
  // u-blox sigId: interface description, "Signal identifiers".
  const SatId sat(system, msg.svId);
  switch (system) {
    case System::Gps:
    case System::Qzss:
      // L1 C/A LNAV (sigId 0) and L2C/L5 CNAV (GPS sigId 3, 4, 6, 7; QZSS 4, 5, 8, 9); QZSS L1S
      // (sigId 1) is not decoded.
      if (msg.sigId == 0) {
        if (!sat.valid()) return void(++c.unknownMessages);
        state_->lnav.add(msg, sat, receiveTime, out, c);
        return;
      }
      if (!isCnavSignal(system, msg.sigId)) break;
      if (!sat.valid()) return void(++c.unknownMessages);
      state_->cnav.add(msg, sat, receiveTime, out, c);
      return;
    case System::Galileo:
      // I/NAV on E1-B (sigId 1) and E5b-I (sigId 5); F/NAV (E5a) and E6 are not decoded.
      if (msg.sigId != 1 && msg.sigId != 5) break;
      if (!sat.valid()) return void(++c.unknownMessages);
      state_->inav.add(msg, sat, receiveTime, out, c);
      return;
    case System::BeiDou:
      // D1/D2 on B1I (sigId 0, 1), B2I (2, 3) and B3I (4, 10): ten 30-bit words. B-CNAV1/2 are not
      // decoded.
      if (msg.words.size() != 10 || !(msg.sigId <= 4 || msg.sigId == 10)) break;
      if (!sat.valid()) return void(++c.unknownMessages);
      // The message follows the satellite: D2 on GEO satellites, D1 on the others (5.1.1).
      if (isBeiDouGeo(sat)) {
        state_->d2.add(msg, sat, out, c);
      } else {
        state_->d1.add(msg, sat, out, c);
      }
      return;
    case System::Glonass:
      if (msg.sigId != 0 && msg.sigId != 2) break;  // L1 OF, L2 OF
      if (!sat.valid()) return void(++c.unknownMessages);  // svId 255: slot not yet known
      state_->glonass.add(msg, sat, receiveTime, out, c);
      return;
    default:
      break;  // SBAS, NavIC: not decoded
  }
  ++c.skipped;
}

NavigationCounts NavigationAssembler::total() const {
  NavigationCounts t;
  for (const NavigationCounts& c : counts_) t += c;
  t.unknownMessages += unknownGnss_;
  t.messages += unknownGnss_;
  return t;
}

}  // namespace gvins::ubx
