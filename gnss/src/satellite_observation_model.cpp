#include "gvins/gnss/satellite_observation_model.hpp"

#include <algorithm>

#include "gvins/base/signal.hpp"
#include "gvins/ephemeris/satellite_antenna.hpp"
#include "gvins/ephemeris/sun_position.hpp"
#include "gvins/gnss/klobuchar.hpp"
#include "gvins/gnss/phase_windup.hpp"
#include "gvins/gnss/sagnac.hpp"

namespace gvins {

IonosphereDelay broadcastIonosphereDelay(const IonosphereParameters& parameters, System system,
                                         const Geodetic& receiver, const AzEl& azel, const GpsTime& t,
                                         double frequency) {
  static const double fL1 = *carrierFrequency(System::Gps, '1');
  static const double fB1I = *carrierFrequency(System::BeiDou, '2');
  IonosphereDelay d;
  // Obliquity of the GPS model (IS-GPS-200N 20.3.3.5.2.5), shared by the delay and its partial.
  const double obliquity = klobucharObliquity(azel.elevation);
  if (system == System::BeiDou && parameters.beidou) {
    d.slant = beidouKlobucharDelayB1I(*parameters.beidou, receiver, azel, t) * ionosphereFrequencyScale(fB1I, frequency);
  } else if (const auto& p = parameters.gps ? parameters.gps : parameters.qzss) {
    d.slant = klobucharDelayL1(*p, receiver, azel, t, obliquity) * ionosphereFrequencyScale(fL1, frequency);
  }
  d.mapL1 = obliquity * ionosphereFrequencyScale(fL1, frequency);
  return d;
}

SatelliteObservationModel::SatelliteObservationModel(const Eigen::Vector3d& receiver, const GpsTime& t,
                                                     const ObservationModelOptions& options,
                                                     const IonosphereParameters* ionosphere)
    : options_(options), ionosphere_(ionosphere), receiver_(receiver), time_(t) {
  geodetic_ = ecefToGeodetic(receiver);
  enu_ = ecefToEnuRotation(geodetic_.lat, geodetic_.lon);
  doy_ = fractionalDayOfYear(t);
  troposphere_ = StationTroposphere::at(geodetic_, doy_, options.troposphere, options.relativeHumidity);
}

AzEl SatelliteObservationModel::azimuthElevation(const Eigen::Vector3d& satellite) const {
  return gvins::azimuthElevation(enu_, receiver_, satellite);
}

SatelliteModelTerms SatelliteObservationModel::terms(const Eigen::Vector3d& satellite, System system,
                                                     double frequency) const {
  return terms(satellite, azimuthElevation(satellite), system, frequency);
}

SatelliteModelTerms SatelliteObservationModel::terms(const Eigen::Vector3d& satellite, const AzEl& azel, System system,
                                                     double frequency) const {
  SatelliteModelTerms m;
  m.azel = azel;
  if (troposphere_.valid() && azel.elevation > 0.0) m.troposphere = troposphere_.slant(azel.elevation);
  m.ionosphere = ionosphere(system, azel, frequency);
  if (options_.shapiro) m.shapiro = shapiroDelay(satellite, receiver_);
  return m;
}

double SatelliteObservationModel::phaseWindup(const Eigen::Vector3d& satellite) const {
  if (!sun_) sun_ = sunPositionEcef(time_);
  return phaseWindupCycles(satellite, receiver_, yawSteeringAxes(satellite, *sun_),
                           levelAntennaAxes(geodetic_.lat, geodetic_.lon));
}

IonosphereDelay SatelliteObservationModel::ionosphere(System system, const AzEl& azel, double frequency) const {
  if (!options_.broadcastIonosphere || !ionosphere_ || !(frequency > 0.0)) return {};
  return broadcastIonosphereDelay(*ionosphere_, system, geodetic_, azel, time_, frequency);
}

std::optional<CodeSignal> usableCode(const SatObs& so, char band, std::optional<int> glonassChannel) {
  const SignalObs* s = so.bestOnBand(band, SignalObs::kCode);
  if (!s || !(s->pseudorange > 1e6 && s->pseudorange < 1e8)) return std::nullopt;
  const auto f = carrierFrequency(so.sat.system, band, glonassChannel);
  if (!f) return std::nullopt;
  return CodeSignal{s, *f};
}

bool semiCodelessL2(System sys, ObsCode code) {
  if ((sys != System::Gps && sys != System::Qzss) || code.band != '2') return false;
  // RINEX 3 L2 attributes of the encrypted P(Y) code: D semi-codeless, P, W Z-tracking, Y, M, N codeless.
  return code.attr == 'D' || code.attr == 'P' || code.attr == 'W' || code.attr == 'Y' || code.attr == 'M' ||
         code.attr == 'N';
}

std::optional<CodeSignal> secondCode(const SatObs& so, const std::string& bands, std::size_t count, char firstBand,
                                     std::optional<int> glonassChannel) {
  const std::size_t n = std::min(count, bands.size());
  std::optional<CodeSignal> deferred;  // a semi-codeless L2 P(Y): taken only when no other band is
  for (std::size_t i = 0; i < n; ++i) {
    if (bands[i] == firstBand) continue;
    auto c = usableCode(so, bands[i], glonassChannel);
    if (!c) continue;
    if (semiCodelessL2(so.sat.system, c->signal->code)) {
      if (!deferred) deferred = c;
      continue;
    }
    return c;
  }
  return deferred;
}

}  // namespace gvins
