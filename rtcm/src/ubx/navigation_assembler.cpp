#include "gvins/ubx/navigation_assembler.hpp"

#include "beidou_d1.hpp"
#include "galileo_inav.hpp"
#include "glonass_strings.hpp"
#include "gps_lnav.hpp"
#include "gvins/ephemeris/ephemeris_store.hpp"

namespace gvins::ubx {

bool NavDataUpdate::empty() const {
  return kepler.empty() && glonass.empty() && !ionosphere.gps && !ionosphere.qzss && !ionosphere.beidou &&
         !ionosphere.galileo;
}

void NavDataUpdate::addTo(EphemerisStore& store) const {
  for (const KeplerEphemeris& e : kepler) store.add(e);
  for (const GlonassEphemeris& g : glonass) store.add(g);
  IonosphereParameters& iono = store.ionosphere();
  if (ionosphere.gps) iono.gps = ionosphere.gps;
  if (ionosphere.qzss) iono.qzss = ionosphere.qzss;
  if (ionosphere.beidou) iono.beidou = ionosphere.beidou;
  if (ionosphere.galileo) iono.galileo = ionosphere.galileo;
}

struct NavigationAssembler::State {
  detail::GpsLnavDecoder lnav;
  detail::GalileoInavDecoder inav;
  detail::BeidouD1Decoder d1;
  detail::GlonassDecoder glonass;
};

NavigationAssembler::NavigationAssembler() : state_(std::make_unique<State>()) {}
NavigationAssembler::~NavigationAssembler() = default;
NavigationAssembler::NavigationAssembler(NavigationAssembler&&) noexcept = default;
NavigationAssembler& NavigationAssembler::operator=(NavigationAssembler&&) noexcept = default;

NavDataUpdate NavigationAssembler::add(const SfrbxMessage& msg, const GpsTime& receiveTime) {
  NavDataUpdate out;
  // u-blox gnssId and sigId (interface description, "GNSS identifiers" and "Signal identifiers").
  System system;
  switch (static_cast<UbxGnss>(msg.gnssId)) {
    case UbxGnss::Gps: system = System::Gps; break;
    case UbxGnss::Sbas: system = System::Sbas; break;
    case UbxGnss::Galileo: system = System::Galileo; break;
    case UbxGnss::BeiDou: system = System::BeiDou; break;
    case UbxGnss::Qzss: system = System::Qzss; break;
    case UbxGnss::Glonass: system = System::Glonass; break;
    case UbxGnss::Navic: system = System::Navic; break;
    default: {
      ++unknownGnss_;
      return out;
    }
  }
  NavigationCounts& c = counts_[static_cast<std::size_t>(systemIndex(system))];
  ++c.messages;
  const SatId sat(system, msg.svId);
  switch (system) {
    case System::Gps:
    case System::Qzss:
      // L1 C/A LNAV only (sigId 0); L2C/L5 CNAV and QZSS L1C/A-on-other-signals are not decoded.
      if (msg.sigId != 0) break;
      if (!sat.valid()) return ++c.unknownMessages, out;
      state_->lnav.add(msg, sat, receiveTime, out, c);
      return out;
    case System::Galileo:
      // I/NAV on E1-B (sigId 1) and E5b-I (sigId 5); F/NAV (E5a) and E6 are not decoded.
      if (msg.sigId != 1 && msg.sigId != 5) break;
      if (!sat.valid()) return ++c.unknownMessages, out;
      state_->inav.add(msg, sat, receiveTime, out, c);
      return out;
    case System::BeiDou:
      // D1/D2 on B1I (sigId 0, 1), B2I (2, 3) and B3I (4, 10): ten 30-bit words. B-CNAV1/2 are not
      // decoded.
      if (msg.words.size() != 10 || !(msg.sigId <= 4 || msg.sigId == 10)) break;
      if (!sat.valid()) return ++c.unknownMessages, out;
      state_->d1.add(msg, sat, receiveTime, out, c);
      return out;
    case System::Glonass:
      if (msg.sigId != 0 && msg.sigId != 2) break;  // L1 OF, L2 OF
      if (!sat.valid()) return ++c.unknownMessages, out;  // svId 255: slot not yet known
      state_->glonass.add(msg, sat, receiveTime, out, c);
      return out;
    default:
      break;  // SBAS, NavIC: not decoded
  }
  ++c.skipped;
  return out;
}

NavigationCounts NavigationAssembler::total() const {
  NavigationCounts t;
  for (const NavigationCounts& c : counts_) {
    t.messages += c.messages;
    t.parityFailures += c.parityFailures;
    t.crcFailures += c.crcFailures;
    t.incompleteSets += c.incompleteSets;
    t.unknownMessages += c.unknownMessages;
    t.skipped += c.skipped;
    t.ephemerides += c.ephemerides;
    t.ionosphere += c.ionosphere;
  }
  t.unknownMessages += unknownGnss_;
  t.messages += unknownGnss_;
  return t;
}

}  // namespace gvins::ubx
