// Interpolation of precise orbits (SP3) and clocks (SP3 or RINEX clock files).
//
// Positions: Lagrange polynomial through the nodes around t, in time normalised by the epoch
// interval (x = (t_i - t)/h, so the evaluation point is x = 0 and all |x| stay below the order),
// evaluated from the Lagrange basis weights at x = 0 together with its first and second
// derivatives (velocity and acceleration). This is the usual way of interpolating IGS SP3 orbits
// in the rotating ECEF frame (e.g. Schenewerk 2003, "A brief review of basic GPS orbit interpolation strategies", GPS
// Solutions 6: a 10th-order polynomial over 15-min nodes is at the mm-cm level).
// Clocks: linear between the two samples bracketing t (IGS clock products are white-noise-like
// at 30 s - 5 min; higher-order fits do not help).
// Relativistic periodic correction: dt_rel = -2 r.v / c^2 (IS-GPS-200 20.3.3.3.3.1; IERS
// Conventions 2010, eq. 10.10), rate -2 (v.v + r.a) / c^2.
#include "gvins/ephemeris/precise_ephemeris.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "gvins/base/constants.hpp"

namespace gvins {
namespace {

constexpr int kMaxNodes = 21;        // lagrangeOrder is clamped to [1, kMaxNodes - 1]
constexpr double kGapFactor = 1.5;   // a spacing above this many intervals is a data gap

struct Interpolant {
  Eigen::Vector3d value, first, second;  // value and derivatives with respect to t (per s, per s^2)
};

// Lagrange basis polynomials L_i(x) = prod_{j != i} (x - x_j) / (x_i - x_j) of the nodes' normalised
// abscissae (distinct), with their first and second derivatives, at x = 0: each product is carried
// as its Taylor series to second order (c0 + c1 x + c2 x^2), one factor at a time. The weights
// depend only on the abscissae, so the positions, the SP3 velocities and all three coordinates
// share them: O(n^2) scalar work once, then O(n) per interpolated vector (Neville's recursion with
// derivatives was O(n^2) per vector).
struct LagrangeWeights {
  std::array<double, kMaxNodes> value{}, first{}, second{};
};

LagrangeWeights lagrangeWeights(const std::array<double, kMaxNodes>& x, int n) {
  LagrangeWeights w;
  for (int i = 0; i < n; ++i) {
    double c0 = 1.0, c1 = 0.0, c2 = 0.0, denominator = 1.0;
    for (int j = 0; j < n; ++j) {
      if (j == i) continue;
      // times the factor (x - x_j): one division per basis polynomial, not per factor
      c2 = c1 - x[j] * c2;
      c1 = c0 - x[j] * c1;
      c0 = -x[j] * c0;
      denominator *= x[i] - x[j];
    }
    const double inv = 1.0 / denominator;
    w.value[i] = c0 * inv;
    w.first[i] = c1 * inv;
    w.second[i] = 2.0 * c2 * inv;
  }
  return w;
}

// The interpolating polynomial of the node values y and its derivatives with respect to t at the
// evaluation point (h: the normalisation of the abscissae, s).
Interpolant interpolate(const LagrangeWeights& w, const std::array<Eigen::Vector3d, kMaxNodes>& y, int n, double h) {
  Interpolant r{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  for (int i = 0; i < n; ++i) {
    r.value += w.value[i] * y[i];
    r.first += w.first[i] * y[i];
    r.second += w.second[i] * y[i];
  }
  r.first /= h;
  r.second /= h * h;
  return r;
}

}  // namespace

PreciseEphemeris::PreciseEphemeris(PreciseEphemerisOptions options) : options_(options) {
  options_.lagrangeOrder = std::clamp(options_.lagrangeOrder, 1, kMaxNodes - 1);
}

void PreciseEphemeris::add(const Sp3Data& orbits) {
  // The epoch interval (## line); data built in memory without one: the smallest epoch spacing.
  double interval = orbits.interval;
  if (!(interval > 0.0)) {
    interval = 0.0;
    for (std::size_t k = 1; k < orbits.epochs.size(); ++k) {
      const double dt = orbits.epochs[k].time - orbits.epochs[k - 1].time;
      if (dt > 0.0 && (interval == 0.0 || dt < interval)) interval = dt;
    }
  }
  for (const auto& e : orbits.epochs) {
    for (const auto& r : e.records) {
      Track& tr = tracks_[r.sat];
      OrbitNode node{r.position, std::nullopt, interval};
      if (r.velocity && r.velocity->allFinite()) node.velocity = r.velocity;
      tr.orbit[e.time] = node;
      if (std::isfinite(r.clock)) {
        tr.sp3Clock[e.time] = {r.clock, interval};
      } else {
        tr.sp3Clock.erase(e.time);
      }
    }
  }
  for (std::size_t i = 0; i < orbits.satellites.size() && i < orbits.accuracyExponent.size(); ++i) {
    const int exp = orbits.accuracyExponent[i];
    auto it = tracks_.find(orbits.satellites[i]);
    if (exp > 0 && exp < 60 && it != tracks_.end()) it->second.accuracy = std::ldexp(1.0, exp) * 1e-3;  // 2^exp mm
  }
  for (auto& [sat, tr] : tracks_) {
    tr.times.clear();
    tr.nodes.clear();
    tr.times.reserve(tr.orbit.size());
    tr.nodes.reserve(tr.orbit.size());
    for (const auto& [t, n] : tr.orbit) {
      tr.times.push_back(t);
      tr.nodes.push_back(n);
    }
  }
}

void PreciseEphemeris::add(const ClockData& clocks) {
  for (const auto& [sat, recs] : clocks.satellites) {
    Track& tr = tracks_[sat];
    for (const auto& r : recs) {
      if (std::isfinite(r.bias)) tr.fileClock[r.time] = r.bias;
    }
  }
}

bool PreciseEphemeris::hasOrbit(SatId sat) const {
  const auto it = tracks_.find(sat);
  return it != tracks_.end() && !it->second.times.empty();
}

std::vector<SatId> PreciseEphemeris::satellites() const {
  std::vector<SatId> out;
  for (const auto& [sat, tr] : tracks_) {
    if (!tr.times.empty()) out.push_back(sat);
  }
  return out;
}

std::pair<GpsTime, GpsTime> PreciseEphemeris::span() const {
  std::pair<GpsTime, GpsTime> s;
  bool any = false;
  for (const auto& [sat, tr] : tracks_) {
    if (tr.times.empty()) continue;
    if (!any || tr.times.front() < s.first) s.first = tr.times.front();
    if (!any || s.second < tr.times.back()) s.second = tr.times.back();
    any = true;
  }
  return s;
}

std::optional<SatelliteState> PreciseEphemeris::satelliteState(SatId sat, const GpsTime& t) const {
  const auto found = tracks_.find(sat);
  if (found == tracks_.end()) return std::nullopt;
  const Track& tr = found->second;
  const int n = options_.lagrangeOrder + 1;
  const std::size_t size = tr.times.size();
  if (size < static_cast<std::size_t>(n)) return std::nullopt;
  if (t - tr.times.front() < -options_.maxExtrapolation || t - tr.times.back() > options_.maxExtrapolation) {
    return std::nullopt;
  }

  // ---- orbit: the n nodes around t (t between the middle two), clamped to the data ----
  const std::size_t idx = static_cast<std::size_t>(std::upper_bound(tr.times.begin(), tr.times.end(), t) - tr.times.begin());
  const std::size_t half = static_cast<std::size_t>(n / 2);
  std::size_t start = idx > half ? idx - half : 0;
  start = std::min(start, size - static_cast<std::size_t>(n));
  const double h = tr.nodes[start].interval > 0.0 ? tr.nodes[start].interval : 1.0;
  std::array<double, kMaxNodes> x{};
  std::array<Eigen::Vector3d, kMaxNodes> pos, vel;
  bool haveVelocity = true;
  for (int i = 0; i < n; ++i) {
    const std::size_t k = start + static_cast<std::size_t>(i);
    const OrbitNode& node = tr.nodes[k];
    if (!node.position.allFinite()) return std::nullopt;  // missing node in the window
    if (i > 0) {
      const double gap = tr.times[k] - tr.times[k - 1];
      const double interval = std::max(node.interval, tr.nodes[k - 1].interval);
      if (interval > 0.0 && gap > kGapFactor * interval) return std::nullopt;  // data gap in the window
    }
    x[i] = (tr.times[k] - t) / h;
    pos[i] = node.position;
    if (node.velocity) {
      vel[i] = *node.velocity;
    } else {
      haveVelocity = false;
    }
  }
  const LagrangeWeights w = lagrangeWeights(x, n);
  const Interpolant p = interpolate(w, pos, n, h);
  SatelliteState st;
  st.position = p.value;
  Eigen::Vector3d accel = p.second;
  if (haveVelocity) {
    const Interpolant v = interpolate(w, vel, n, h);  // the SP3 V records
    st.velocity = v.value;
    accel = v.first;
  } else {
    st.velocity = p.first;
  }

  // ---- clock: linear between the two samples bracketing t ----
  double bias = 0.0, drift = 0.0;
  // Linear between the samples bracketing t; beyond the first/last sample (by at most
  // maxExtrapolation) the first/last two samples are extended.
  auto linear = [&](auto const& samples, auto value, auto maxGap) -> bool {
    if (samples.size() < 2) return false;
    auto hi = samples.upper_bound(t);
    if (hi == samples.end()) {
      if (t - samples.rbegin()->first > options_.maxExtrapolation) return false;
      hi = std::prev(samples.end());
    } else if (hi == samples.begin()) {
      if (hi->first - t > options_.maxExtrapolation) return false;
      hi = std::next(hi);
    }
    const auto lo = std::prev(hi);
    const double dt = hi->first - lo->first;
    if (!(dt > 0.0) || dt > maxGap(*lo, *hi)) return false;
    const double a = value(*lo), b = value(*hi);
    drift = (b - a) / dt;
    bias = a + drift * (t - lo->first);
    return true;
  };
  const bool fromFile = linear(
      tr.fileClock, [](const auto& s) { return s.second; },
      [&](const auto&, const auto&) { return options_.maxClockGap; });
  if (!fromFile) {
    // SP3 clocks: consecutive epochs of the file (no missing epoch), or the clock-gap limit if larger.
    const bool fromSp3 = linear(
        tr.sp3Clock, [](const auto& s) { return s.second.first; },
        [&](const auto& a, const auto& b) {
          return std::max(options_.maxClockGap, kGapFactor * std::max(a.second.second, b.second.second));
        });
    if (!fromSp3) return std::nullopt;
  }
  // Periodic relativistic correction (IS-GPS-200 20.3.3.3.3.1 in its r.v form; IERS 2010 eq. 10.10).
  constexpr double c2 = constants::kSpeedOfLight * constants::kSpeedOfLight;
  st.clockBias = bias - 2.0 * st.position.dot(st.velocity) / c2;
  st.clockDrift = drift - 2.0 * (st.velocity.squaredNorm() + st.position.dot(accel)) / c2;
  st.accuracy = tr.accuracy;
  st.precise = true;
  return st;
}

}  // namespace gvins
