#include "gvins/ephemeris/ssr_corrections.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "gvins/base/constants.hpp"

namespace gvins {

std::optional<double> ssrUraMetres(int uraIndex) {
  // RTCM 10403.3 DF389: bits 5-3 class, bits 2-0 value; URA [mm] <= 3^class (1 + value/4) - 1.
  if (uraIndex <= 0 || uraIndex >= 63) return std::nullopt;
  const int cls = (uraIndex >> 3) & 7;
  const int val = uraIndex & 7;
  return (std::pow(3.0, cls) * (1.0 + val / 4.0) - 1.0) * 1e-3;
}

int ssrIssueOfData(const KeplerEphemeris& eph) {
  // BeiDou: DF470 "toe modulo", (toe mod 8192) / 8 with toe in BDT seconds of the week (the BDS
  // ephemerides have no issue-of-data field of their own; the broadcast AODE is not used).
  if (eph.sat.system == System::BeiDou) return (static_cast<int>(std::lround(eph.toeSeconds)) % 8192) / 8;
  return eph.iode;
}

int ssrBeidouIod(const KeplerEphemeris& eph) {
  // DF471 "BDS IOD": (toe / 720) mod 240.
  return (static_cast<int>(std::lround(eph.toeSeconds)) / 720) % 240;
}
int ssrIssueOfData(const GlonassEphemeris& eph) { return eph.iode; }

namespace {

template <class T>
void insertSorted(std::vector<T>& v, T item) {
  auto it = std::upper_bound(v.begin(), v.end(), item.header.epoch,
                             [](const GpsTime& e, const T& x) { return e < x.header.epoch; });
  v.insert(it, std::move(item));
}

// Newest entry with epoch <= t, age <= maxAge and (if iod given) the same IOD SSR.
template <class T>
const T* newestAt(const std::vector<T>& v, const GpsTime& t, double maxAge, std::optional<int> iodSsr = {}) {
  auto it = std::upper_bound(v.begin(), v.end(), t, [](const GpsTime& e, const T& x) { return e < x.header.epoch; });
  while (it != v.begin()) {
    --it;
    if (t - it->header.epoch > maxAge) return nullptr;
    if (!iodSsr || it->header.iodSsr == *iodSsr) return &*it;
  }
  return nullptr;
}

}  // namespace

SsrCorrections::PerSatellite* SsrCorrections::slot(SatId sat) {
  if (!sat.valid()) return nullptr;
  if (sats_.empty()) sats_.resize(static_cast<std::size_t>(numSatIndices()));
  return &sats_[static_cast<std::size_t>(satIndex(sat))];
}

const SsrCorrections::PerSatellite* SsrCorrections::find(SatId sat) const {
  if (!sat.valid() || sats_.empty()) return nullptr;
  return &sats_[static_cast<std::size_t>(satIndex(sat))];
}

void SsrCorrections::add(const SsrMessage& message) {
  const SsrHeader& h = message.header;
  for (const SsrSatellite& s : message.satellites) {
    PerSatellite* p = slot(s.sat);
    if (!p) continue;
    if (s.orbit) {
      insertSorted(p->orbits, Timed<SsrOrbitCorrection>{h, *s.orbit});
      auto& epochs = orbitEpochs_[static_cast<std::size_t>(systemIndex(s.sat.system))];
      epochs.insert(std::upper_bound(epochs.begin(), epochs.end(), h.epoch), h.epoch);
      ++count_;
    }
    if (s.clock) {
      insertSorted(p->clocks, Timed<SsrClockCorrection>{h, *s.clock});
      ++count_;
    }
    if (s.highRateClock) {
      insertSorted(p->highRateClocks, Timed<double>{h, *s.highRateClock});
      ++count_;
    }
    if (h.kind == SsrKind::kCodeBias) {
      insertSorted(p->codeBiases, Timed<std::vector<std::pair<ObsCode, double>>>{h, s.codeBiases});
      ++count_;
    }
    if (s.uraIndex) {
      insertSorted(p->uras, Timed<int>{h, *s.uraIndex});
      ++count_;
    }
  }
}

std::optional<SsrSelection> SsrCorrections::select(SatId sat, const GpsTime& t) const {
  const PerSatellite* p = find(sat);
  if (!p) return std::nullopt;
  const auto* orbit = newestAt(p->orbits, t, options_.maxAge);
  if (!orbit) return std::nullopt;
  const auto* clock = newestAt(p->clocks, t, options_.maxAge, orbit->header.iodSsr);
  if (!clock) return std::nullopt;
  SsrSelection out;
  out.orbitHeader = orbit->header;
  out.orbit = orbit->value;
  out.clockHeader = clock->header;
  out.clock = clock->value;
  if (const auto* hr = newestAt(p->highRateClocks, t, options_.maxHighRateAge, orbit->header.iodSsr))
    out.highRateClock = hr->value;
  if (const auto* ura = newestAt(p->uras, t, options_.maxAge, orbit->header.iodSsr)) out.uraIndex = ura->value;
  return out;
}

bool SsrCorrections::coversSystem(System system, const GpsTime& t) const {
  const auto& epochs = orbitEpochs_[static_cast<std::size_t>(systemIndex(system))];
  auto it = std::upper_bound(epochs.begin(), epochs.end(), t);
  if (it == epochs.begin()) return false;
  return t - *std::prev(it) <= options_.maxAge;
}

std::optional<double> SsrCorrections::codeBias(SatId sat, ObsCode code, const GpsTime& t) const {
  const PerSatellite* p = find(sat);
  if (!p) return std::nullopt;
  const auto* cb = newestAt(p->codeBiases, t, options_.maxCodeBiasAge);
  if (!cb) return std::nullopt;
  for (const auto& [c, b] : cb->value)
    if (c == code) return b;
  return std::nullopt;
}

std::optional<Eigen::Matrix3d> ssrOrbitFrame(const SatelliteState& broadcast) {
  const Eigen::Vector3d& r = broadcast.position;
  const Eigen::Vector3d& v = broadcast.velocity;
  const Eigen::Vector3d rxv = r.cross(v);
  if (v.norm() < 1e-3 || rxv.norm() < 1e-3) return std::nullopt;
  const Eigen::Vector3d ea = v.normalized();
  const Eigen::Vector3d ec = rxv.normalized();
  Eigen::Matrix3d rac;
  rac.col(0) = ea.cross(ec);
  rac.col(1) = ea;
  rac.col(2) = ec;
  return rac;
}

std::optional<SatelliteState> applySsr(const SatelliteState& broadcast, const SsrSelection& ssr,
                                       const GpsTime& t) {
  const auto frame = ssrOrbitFrame(broadcast);
  if (!frame) return std::nullopt;
  const Eigen::Matrix3d& rac = *frame;
  // Reference time t0 = SSR epoch + half the update interval (RTCM 10403.3, 3.5.12.3).
  const double dtOrbit = t - (ssr.orbitHeader.epoch + 0.5 * ssr.orbitHeader.updateInterval);
  const double dtClock = t - (ssr.clockHeader.epoch + 0.5 * ssr.clockHeader.updateInterval);
  SatelliteState out = broadcast;
  out.position = broadcast.position - rac * (ssr.orbit.rac + ssr.orbit.racRate * dtOrbit);
  out.velocity = broadcast.velocity - rac * ssr.orbit.racRate;
  double dc = ssr.clock.c0 + ssr.clock.c1 * dtClock + ssr.clock.c2 * dtClock * dtClock;
  if (ssr.highRateClock) dc += *ssr.highRateClock;
  out.clockBias = broadcast.clockBias + dc / constants::kSpeedOfLight;
  out.clockDrift = broadcast.clockDrift + (ssr.clock.c1 + 2.0 * ssr.clock.c2 * dtClock) / constants::kSpeedOfLight;
  if (ssr.uraIndex)
    if (const auto ura = ssrUraMetres(*ssr.uraIndex)) out.accuracy = *ura;
  out.ssr = true;
  out.precise = false;
  return out;
}

}  // namespace gvins
