#include "gvins/sim/gnss_constellation.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "gvins/base/constants.hpp"
#include "gvins/ephemeris/satellite_state.hpp"
#include "gvins/sim/gnss_random.hpp"

namespace gvins::sim {

namespace {

// Split of the SISRE (m) into radial, along-track, cross-track orbit errors and the clock error.
// Broadcast orbit errors are largest along track and smallest radially (Montenbruck,
// Steigenberger & Hauschild 2018); a ground user sees mostly the radial and clock parts, so the
// projected range error is close to the configured SISRE.
constexpr double kRadial = 0.35, kAlong = 1.5, kCross = 1.0, kClock = 0.9;
// Drift of each error per hour, as a fraction of its size.
constexpr double kDriftPerHour = 0.3;

// Quintic smoothstep and its derivative (C^2 blend between records).
double smooth(double u) { return u * u * u * (u * (6.0 * u - 15.0) + 10.0); }
double smoothDot(double u) { return 30.0 * u * u * (u - 1.0) * (u - 1.0); }

}  // namespace

GnssConstellation::GnssConstellation(const EphemerisStore& nav, const GnssSimConfig& config, const GpsTime& start,
                                     const GpsTime& end, std::uint64_t seed)
    : start_(start), index_(static_cast<std::size_t>(numSatIndices()), -1), channels_(nav.glonassChannels()) {
  EphemerisSelection policy;
  policy.allowUnhealthy = config.includeUnhealthy;
  const double margin = 4.0 * 3600.0;
  for (SatId sat : nav.satellites()) {
    if (!config.useSystem(sat.system) || sat.system == System::Sbas || sat.system == System::Navic) continue;
    if (config.signals[systemIndex(sat.system)].empty()) continue;
    Sat s;
    s.id = sat;
    if (sat.system == System::Glonass) {
      if (!channels_.get(sat.prn)) continue;  // no FDMA channel: frequencies unknown
      if (config.satelliteErrors.blendRecords) {
        for (const GlonassEphemeris& g : nav.glonassRecords(sat)) {
          if (!config.includeUnhealthy && !isHealthy(g)) continue;
          if (g.toe < start - margin || end + margin < g.toe) continue;
          if (!s.records.empty() && s.records.back().ref == g.toe) continue;
          s.records.push_back({g.toe, EphemerisStore::validityHalfWindow(g), nullptr, &g});
        }
      } else {
        const GlonassEphemeris* g = nav.selectGlonass(sat, start, policy);
        if (!g) g = nav.selectGlonass(sat, start + 0.5 * (end - start), policy);
        if (!g) g = nav.selectGlonass(sat, end, policy);
        if (g) s.records.push_back({g->toe, EphemerisStore::validityHalfWindow(*g), nullptr, g});
      }
    } else {
      const auto& list = nav.keplerRecords(sat);
      const bool haveInav = std::any_of(list.begin(), list.end(),
                                        [](const KeplerEphemeris& e) { return e.message == NavMessage::GalileoInav; });
      if (config.satelliteErrors.blendRecords) {
        for (const KeplerEphemeris& e : list) {
          if (sat.system == System::Galileo && (e.message == NavMessage::GalileoInav) != haveInav) continue;
          if (!config.includeUnhealthy && !isHealthy(e)) continue;
          if (e.toe < start - margin || end + margin < e.toe) continue;
          if (!s.records.empty() && s.records.back().ref == e.toe) {
            // The same reference time twice (re-upload): keep the later transmission.
            if (s.records.back().kepler->ttr < e.ttr) s.records.back().kepler = &e;
            continue;
          }
          s.records.push_back({e.toe, EphemerisStore::validityHalfWindow(e), &e, nullptr});
        }
      } else {
        const KeplerEphemeris* e = nav.selectKepler(sat, start, policy);
        if (!e) e = nav.selectKepler(sat, start + 0.5 * (end - start), policy);
        if (!e) e = nav.selectKepler(sat, end, policy);
        if (e) s.records.push_back({e->toe, EphemerisStore::validityHalfWindow(*e), e, nullptr});
      }
    }
    if (s.records.empty()) continue;
    GnssRandom rng(streamSeed(seed, {0xC0, static_cast<std::uint64_t>(satIndex(sat))}));
    const double sisre = config.satelliteErrors.sisre[systemIndex(sat.system)];
    const double scale[4] = {kRadial, kAlong, kCross, kClock};
    for (int k = 0; k < 4; ++k) {
      s.e0[k] = rng.normal(sisre * scale[k]);
      s.e1[k] = rng.normal(sisre * scale[k] * kDriftPerHour);
    }
    index_[static_cast<std::size_t>(satIndex(sat))] = static_cast<int>(data_.size());
    data_.push_back(std::move(s));
    sats_.push_back(sat);
  }
}

const GnssConstellation::Sat* GnssConstellation::find(SatId sat) const {
  if (!sat.valid()) return nullptr;
  const int i = index_[static_cast<std::size_t>(satIndex(sat))];
  return i < 0 ? nullptr : &data_[static_cast<std::size_t>(i)];
}

bool GnssConstellation::bracket(const Sat& s, const GpsTime& t, int& i, int& j, double& w, double& wDot,
                                double extension) const {
  const auto& r = s.records;
  const int n = static_cast<int>(r.size());
  // First record with ref > t.
  int k = static_cast<int>(std::upper_bound(r.begin(), r.end(), t, [](const GpsTime& x, const Record& rec) {
                             return x < rec.ref;
                           }) - r.begin());
  w = 0.0;
  wDot = 0.0;
  if (k == 0) {
    i = j = 0;
    return std::fabs(t - r[0].ref) <= r[0].halfWindow + extension;
  }
  if (k == n) {
    i = j = n - 1;
    return std::fabs(t - r[n - 1].ref) <= r[n - 1].halfWindow + extension;
  }
  i = k - 1;
  j = k;
  // Consecutive records close enough to cover the gap between them together are always blended
  // (even where one of them is already past its own validity window: a smooth truth matters more
  // than that record's last metre); across a longer gap each record serves its own window.
  if (r[j].ref - r[i].ref > r[i].halfWindow + r[j].halfWindow) {
    if (t - r[i].ref <= r[i].halfWindow) {
      j = i;
      return true;
    }
    if (r[j].ref - t <= r[j].halfWindow) {
      i = j;
      return true;
    }
    // In the gap: the nearer record's continuation, within the extension.
    const double di = (t - r[i].ref) - r[i].halfWindow, dj = (r[j].ref - t) - r[j].halfWindow;
    if (di <= dj && di <= extension) {
      j = i;
      return true;
    }
    if (dj < di && dj <= extension) {
      i = j;
      return true;
    }
    return false;
  }
  const double span = r[j].ref - r[i].ref;
  const double u = (t - r[i].ref) / span;
  w = smooth(u);
  wDot = smoothDot(u) / span;
  return true;
}

bool GnssConstellation::covers(SatId sat, const GpsTime& t) const {
  const Sat* s = find(sat);
  int i, j;
  double w, wd;
  return s && bracket(*s, t, i, j, w, wd);
}

std::optional<int> GnssConstellation::glonassChannel(SatId sat) const {
  if (sat.system != System::Glonass) return std::nullopt;
  return channels_.get(sat.prn);
}

std::optional<GnssSatelliteState> GnssConstellation::state(SatId sat, const GpsTime& t, double extension) const {
  const Sat* s = find(sat);
  if (!s) return std::nullopt;
  int i, j;
  double w, wDot;
  if (!bracket(*s, t, i, j, w, wDot, extension)) return std::nullopt;
  auto eval = [&](int k) {
    const Record& r = s->records[static_cast<std::size_t>(k)];
    return r.kepler ? keplerSatelliteState(*r.kepler, t) : glonassSatelliteState(*r.glonass, t);
  };
  const SatelliteState a = eval(i);
  GnssSatelliteState out;
  if (i == j) {
    out.broadcastPosition = a.position;
    out.velocity = a.velocity;
    out.broadcastClock = a.clockBias;
    out.clockDrift = a.clockDrift;
  } else {
    const SatelliteState b = eval(j);
    out.broadcastPosition = (1.0 - w) * a.position + w * b.position;
    out.velocity = (1.0 - w) * a.velocity + w * b.velocity + wDot * (b.position - a.position);
    out.broadcastClock = (1.0 - w) * a.clockBias + w * b.clockBias;
    out.clockDrift = (1.0 - w) * a.clockDrift + w * b.clockDrift + wDot * (b.clockBias - a.clockBias);
  }
  // Errors in the radial / along-track / cross-track frame of the broadcast state.
  const double hours = (t - start_) / 3600.0;
  const Eigen::Vector4d e = s->e0 + s->e1 * hours;
  const Eigen::Vector4d eDot = s->e1 / 3600.0;
  const Eigen::Vector3d rHat = out.broadcastPosition.normalized();
  const Eigen::Vector3d cHat = out.broadcastPosition.cross(out.velocity).normalized();
  const Eigen::Vector3d aHat = cHat.cross(rHat);
  out.orbitError = e[0] * rHat + e[1] * aHat + e[2] * cHat;
  out.clockError = e[3] / constants::kSpeedOfLight;
  out.position = out.broadcastPosition + out.orbitError;
  // The error vector turns with the orbit frame (angular velocity r x v / |r|^2).
  const Eigen::Vector3d omega = out.broadcastPosition.cross(out.velocity) / out.broadcastPosition.squaredNorm();
  out.velocity += eDot[0] * rHat + eDot[1] * aHat + eDot[2] * cHat + omega.cross(out.orbitError);
  out.clock = out.broadcastClock + out.clockError;
  out.clockDrift += eDot[3] / constants::kSpeedOfLight;
  return out;
}

double GnssConstellation::groupDelay(SatId sat, ObsCode code, const GpsTime& t) const {
  const Sat* s = find(sat);
  if (!s) return 0.0;
  int i, j;
  double w, wDot;
  if (!bracket(*s, t, i, j, w, wDot)) return 0.0;
  auto gd = [&](int k) {
    const Record& r = s->records[static_cast<std::size_t>(k)];
    return r.kepler ? broadcastGroupDelay(*r.kepler, code) : broadcastGroupDelay(*r.glonass, code);
  };
  return i == j ? gd(i) : (1.0 - w) * gd(i) + w * gd(j);
}

}  // namespace gvins::sim
