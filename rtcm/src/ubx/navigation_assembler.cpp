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
  dispatch(msg, source, *system, receiveTime, out, delta);
  counts_[static_cast<std::size_t>(systemIndex(*system))] += delta;
  bySource_[source] += delta;
  return out;
}

void NavigationAssembler::dispatch(const SfrbxMessage& msg, const NavigationSource& source, System system,
                                   const GpsTime& receiveTime, NavDataUpdate& out, NavigationCounts& c) {
  const NavigationDecoder decoder = navigationDecoder(source);  // the one sigId table
  const bool beidou = decoder == NavigationDecoder::BeidouD1 || decoder == NavigationDecoder::BeidouD2;
  if (decoder == NavigationDecoder::None || (beidou && msg.words.size() != 10)) return void(++c.skipped);
  const SatId sat(system, msg.svId);
  if (!sat.valid()) return void(++c.unknownMessages);  // e.g. GLONASS svId 255: slot not yet known
  switch (decoder) {
    case NavigationDecoder::Lnav: return state_->lnav.add(msg, sat, receiveTime, out, c);
    case NavigationDecoder::Cnav: return state_->cnav.add(msg, sat, receiveTime, out, c);
    case NavigationDecoder::GalileoInav: return state_->inav.add(msg, sat, receiveTime, out, c);
    // The BeiDou message follows the satellite: D2 on GEO satellites, D1 on the others (5.1.1).
    case NavigationDecoder::BeidouD1: return state_->d1.add(msg, sat, out, c);
    case NavigationDecoder::BeidouD2: return state_->d2.add(msg, sat, out, c);
    case NavigationDecoder::GlonassStrings: return state_->glonass.add(msg, sat, receiveTime, out, c);
    case NavigationDecoder::None: break;
  }
}

NavigationCounts NavigationAssembler::total() const {
  NavigationCounts t;
  for (const NavigationCounts& c : counts_) t += c;
  t.unknownMessages += unknownGnss_;
  t.messages += unknownGnss_;
  return t;
}

}  // namespace gvins::ubx
