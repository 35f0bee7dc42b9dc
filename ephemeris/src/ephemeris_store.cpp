// Ephemeris store and record selection.
//
// Validity windows (half-widths around toe; a record is never used outside its window):
//   GPS     half the fit interval (IS-GPS-200N 20.3.3.4.3.1 and 20.3.4.4): 2 h for the standard
//           4 h fit (fit interval 0 or 4 in RINEX), 3 h when only the "> 4 h" flag (1) is given,
//           otherwise fit/2 as written (6, 8, 14, 26 h fits after long uploads).
//   QZSS    half the fit interval (IS-QZSS 4.1.2.7, as RINEX 3.04 cites it: flag 0 = 2 h, 1 = more):
//           1 h for flag 0, 2 h for flag 1, otherwise fit/2 as written.
//   Galileo 4 h: the OS SIS ICD defines no fit interval; new IODnav batches come every 10 min
//           and 4 h is the common maximum age of a batch (the value RTKLIB 2.4.3 also uses).
//   BeiDou  2 h: the ICD defines no fit interval and D1/D2 ephemerides are refreshed every hour
//           (toe on the hour in practice); one missed update is tolerated.
//   GLONASS 30 min: tb is spaced 30, 45 or 60 min (ICD 5.1 4.4, word P1), so a record serves at
//           most +-30 min around tb.
// Among usable records the nearest toe wins; equal distances go to the newest transmission, then
// the larger issue of data. Records whose transmission time is after t are used only within
// EphemerisSelection::futureTolerance of toe.
//
// Spans of a choice (chooseKepler/chooseGlonass): as t moves, the selection can only change where
// a rule flips for some record: at toe -+ the search bound, toe -+ the validity window, the
// transmission time, toe -+ the future tolerance, or half-way between the toe of the selected
// record and that of another usable one (nearest toe). Between the nearest such edges before and
// after t (less the margin) every rule evaluates as at t, so the selection is the same. Records
// more than twice the search bound from t cannot be in the search range anywhere within one
// bound of t, which also limits the span.
#include <algorithm>
#include <cmath>
#include <utility>

#include "gvins/ephemeris/ephemeris_store.hpp"

#include "gvins/base/constants.hpp"
#include "gvins/ephemeris/satellite_antenna.hpp"

namespace gvins {
namespace {

constexpr double kHour = 3600.0;

// Largest half window of any record of a system (bounds the scan of a satellite's records).
double maxHalfWindow(System s) {
  switch (s) {
    case System::Gps:
    case System::Qzss: return 13.0 * kHour;  // 26 h fit, the longest in IS-GPS-200N 20.3.4.4
    case System::Galileo: return 4.0 * kHour;
    case System::BeiDou: return 2.0 * kHour;
    case System::Glonass: return 0.5 * kHour;
    default: return 0.0;
  }
}

bool sameKeplerRecord(const KeplerEphemeris& a, const KeplerEphemeris& b) {
  return a.message == b.message && a.toe == b.toe && a.iode == b.iode && a.iodc == b.iodc;
}

// Whether a record transmitted at ttr may be used at t.
bool transmittedInTime(const GpsTime& ttr, const GpsTime& toe, const GpsTime& t,
                       const EphemerisSelection& policy) {
  if (!(ttr > t)) return true;
  if (policy.futureTolerance < 0.0) return false;
  return std::fabs(t - toe) <= policy.futureTolerance;
}

const std::vector<KeplerEphemeris> kNoKepler;
const std::vector<GlonassEphemeris> kNoGlonass;

/// The nearest rule edges before and after t, within one search bound.
class Edges {
 public:
  Edges(const GpsTime& t, double bound) : t_(t), before_(t - bound), after_(t + bound) {}
  void add(const GpsTime& edge) {
    if (t_ < edge) {
      if (edge < after_) after_ = edge;
    } else if (before_ < edge) {
      before_ = edge;
    }
  }
  /// The span between the edges less the margin; only t itself when t is within the margin of an
  /// edge (the selection at an edge may differ on either side).
  template <class Record>
  EphemerisChoice<Record> choice(const Record* record) const {
    EphemerisChoice<Record> c{record, before_ + kEphemerisSpanMargin, after_ - kEphemerisSpanMargin};
    if (t_ < c.from || c.until < t_) c.from = c.until = t_;
    return c;
  }

 private:
  GpsTime t_, before_, after_;
};

/// Collects into `edges` the rule edges of every considered record within two search bounds of
/// t (sorted by toe): the search bound and validity window around its toe, its transmission time
/// (`transmitted`: ttr or tof), the future tolerance, and the midpoint towards the chosen `best`
/// where another usable record would take over.
template <class Record, class Considered, class Usable>
void addRuleEdges(const std::vector<Record>& list, const GpsTime& t, double bound, const EphemerisSelection& policy,
                  const Record* best, const Considered& considered, const Usable& usable,
                  GpsTime Record::*transmitted, Edges& edges) {
  auto wide = std::lower_bound(list.begin(), list.end(), t - 2.0 * bound,
                               [](const Record& e, const GpsTime& x) { return e.toe < x; });
  for (; wide != list.end() && !(t + 2.0 * bound < wide->toe); ++wide) {
    const Record& e = *wide;
    if (!considered(e)) continue;
    const double window = EphemerisStore::validityHalfWindow(e);
    edges.add(e.toe - bound);
    edges.add(e.toe + bound);
    edges.add(e.toe - window);
    edges.add(e.toe + window);
    edges.add(e.*transmitted);
    if (policy.futureTolerance >= 0.0) {
      edges.add(e.toe - policy.futureTolerance);
      edges.add(e.toe + policy.futureTolerance);
    }
    if (best && e.toe != best->toe && usable(e)) edges.add(best->toe + 0.5 * (e.toe - best->toe));
  }
}

/// Kepler record selection among one satellite's records (sorted by toe) for one message filter;
/// with `edges`, also collects the rule edges of every record that may matter near t.
const KeplerEphemeris* pickKepler(const std::vector<KeplerEphemeris>& list, const GpsTime& t, double bound,
                                  const EphemerisSelection& policy, bool anyMessage, NavMessage wanted,
                                  Edges* edges) {
  const GpsTime lo = t - bound, hi = t + bound;
  auto considered = [&](const KeplerEphemeris& e) {
    return (anyMessage || e.message == wanted) && (policy.allowUnhealthy || isHealthy(e));
  };
  auto usable = [&](const KeplerEphemeris& e) {
    if (e.toe < lo || hi < e.toe || !considered(e)) return false;
    if (std::fabs(t - e.toe) > EphemerisStore::validityHalfWindow(e)) return false;
    return transmittedInTime(e.ttr, e.toe, t, policy);
  };
  const KeplerEphemeris* best = nullptr;
  double bestDt = 0.0;
  auto it = std::lower_bound(list.begin(), list.end(), lo,
                             [](const KeplerEphemeris& e, const GpsTime& x) { return e.toe < x; });
  for (; it != list.end() && !(hi < it->toe); ++it) {
    const KeplerEphemeris& e = *it;
    if (!usable(e)) continue;
    const double dt = std::fabs(t - e.toe);
    if (best) {
      if (dt > bestDt) continue;
      if (dt == bestDt && (e.ttr < best->ttr || (e.ttr == best->ttr && e.iode <= best->iode))) continue;
    }
    best = &e;
    bestDt = dt;
  }
  if (edges) addRuleEdges(list, t, bound, policy, best, considered, usable, &KeplerEphemeris::ttr, *edges);
  return best;
}

/// The same for GLONASS records (transmission time tof; ties to the latest tof).
const GlonassEphemeris* pickGlonass(const std::vector<GlonassEphemeris>& list, const GpsTime& t, double bound,
                                    const EphemerisSelection& policy, Edges* edges) {
  const GpsTime lo = t - bound, hi = t + bound;
  auto usable = [&](const GlonassEphemeris& e) {
    if (e.toe < lo || hi < e.toe) return false;
    if (!policy.allowUnhealthy && !isHealthy(e)) return false;
    if (std::fabs(t - e.toe) > EphemerisStore::validityHalfWindow(e)) return false;
    return transmittedInTime(e.tof, e.toe, t, policy);
  };
  const GlonassEphemeris* best = nullptr;
  double bestDt = 0.0;
  auto it = std::lower_bound(list.begin(), list.end(), lo,
                             [](const GlonassEphemeris& e, const GpsTime& x) { return e.toe < x; });
  for (; it != list.end() && !(hi < it->toe); ++it) {
    const GlonassEphemeris& e = *it;
    if (!usable(e)) continue;
    const double dt = std::fabs(t - e.toe);
    if (best && (dt > bestDt || (dt == bestDt && !(best->tof < e.tof)))) continue;
    best = &e;
    bestDt = dt;
  }
  if (edges) {
    auto considered = [&](const GlonassEphemeris& e) { return policy.allowUnhealthy || isHealthy(e); };
    addRuleEdges(list, t, bound, policy, best, considered, usable, &GlonassEphemeris::tof, *edges);
  }
  return best;
}

}  // namespace

double EphemerisStore::validityHalfWindow(const KeplerEphemeris& eph) {
  const double fit = eph.fitInterval;
  switch (eph.sat.system) {
    case System::Gps:
      if (fit > 1.5) return 0.5 * fit * kHour;
      return fit > 0.5 ? 3.0 * kHour : 2.0 * kHour;
    case System::Qzss:
      if (fit > 1.5) return 0.5 * fit * kHour;
      return fit > 0.5 ? 2.0 * kHour : 1.0 * kHour;
    default:
      return maxHalfWindow(eph.sat.system);
  }
}

double EphemerisStore::validityHalfWindow(const GlonassEphemeris&) { return 0.5 * kHour; }

void EphemerisStore::add(const KeplerEphemeris& eph) {
  if (!eph.sat.valid() || eph.sat.system == System::Glonass) return;
  const int idx = satIndex(eph.sat);
  if (kepler_.size() < static_cast<std::size_t>(numSatIndices())) kepler_.resize(numSatIndices());
  auto& list = kepler_[idx];
  auto it = std::lower_bound(list.begin(), list.end(), eph.toe,
                             [](const KeplerEphemeris& e, const GpsTime& t) { return e.toe < t; });
  for (auto j = it; j != list.end() && j->toe == eph.toe; ++j) {
    if (sameKeplerRecord(*j, eph)) {
      // The same data set seen again: keep the copy that was available first.
      if (eph.ttr < j->ttr) {
        *j = eph;
        ++revision_;
      }
      return;
    }
  }
  list.insert(it, eph);
  ++revision_;
}

void EphemerisStore::add(const GlonassEphemeris& eph) {
  if (!eph.sat.valid() || eph.sat.system != System::Glonass) return;
  const int idx = satIndex(eph.sat);
  if (glonass_.size() < static_cast<std::size_t>(numSatIndices())) glonass_.resize(numSatIndices());
  auto& list = glonass_[idx];
  auto it = std::lower_bound(list.begin(), list.end(), eph.toe,
                             [](const GlonassEphemeris& e, const GpsTime& t) { return e.toe < t; });
  for (auto j = it; j != list.end() && j->toe == eph.toe; ++j) {
    if (j->position == eph.position && j->velocity == eph.velocity) {
      if (eph.tof < j->tof) {
        *j = eph;
        ++revision_;
      }
      return;
    }
  }
  list.insert(it, eph);
  ++revision_;
  if (eph.frequencyChannel >= -7 && eph.frequencyChannel <= 6) channels_.set(eph.sat.prn, eph.frequencyChannel);
}

void EphemerisStore::add(const NavData& nav) {
  for (const auto& e : nav.kepler) add(e);
  for (const auto& g : nav.glonass) add(g);
  if (!iono_.gps) iono_.gps = nav.iono.gps;
  if (!iono_.qzss) iono_.qzss = nav.iono.qzss;
  if (!iono_.beidou) iono_.beidou = nav.iono.beidou;
  if (!iono_.galileo) iono_.galileo = nav.iono.galileo;
  if (!leapSeconds_) leapSeconds_ = nav.leapSeconds;
}

namespace {

template <class Pick>
auto chooseGalileoFirst(SatId sat, const EphemerisSelection& policy, Pick pick) {
  if (sat.system == System::Galileo) {
    const NavMessage first = policy.preferGalileoInav ? NavMessage::GalileoInav : NavMessage::GalileoFnav;
    const NavMessage second = policy.preferGalileoInav ? NavMessage::GalileoFnav : NavMessage::GalileoInav;
    if (const auto* e = pick(false, first)) return e;
    return pick(false, second);
  }
  return pick(true, NavMessage::GpsLnav);
}

}  // namespace

const KeplerEphemeris* EphemerisStore::selectKepler(SatId sat, const GpsTime& t,
                                                    const EphemerisSelection& policy) const {
  if (!sat.valid() || sat.system == System::Glonass || kepler_.empty()) return nullptr;
  const auto& list = kepler_[satIndex(sat)];
  if (list.empty()) return nullptr;
  const double bound = maxHalfWindow(sat.system);
  return chooseGalileoFirst(sat, policy, [&](bool anyMessage, NavMessage wanted) {
    return pickKepler(list, t, bound, policy, anyMessage, wanted, nullptr);
  });
}

EphemerisChoice<KeplerEphemeris> EphemerisStore::chooseKepler(SatId sat, const GpsTime& t,
                                                             const EphemerisSelection& policy) const {
  const double bound = sat.valid() ? maxHalfWindow(sat.system) : 0.0;
  Edges edges(t, bound);
  if (!sat.valid() || sat.system == System::Glonass || kepler_.empty()) return edges.choice<KeplerEphemeris>(nullptr);
  const auto& list = kepler_[satIndex(sat)];
  // A Galileo I/NAV pick holds in its own span; a fall-back to F/NAV also needs the I/NAV
  // search to stay empty, so the edges of both add up.
  return edges.choice(chooseGalileoFirst(sat, policy, [&](bool anyMessage, NavMessage wanted) {
    return pickKepler(list, t, bound, policy, anyMessage, wanted, &edges);
  }));
}

const GlonassEphemeris* EphemerisStore::selectGlonass(SatId sat, const GpsTime& t,
                                                      const EphemerisSelection& policy) const {
  if (!sat.valid() || sat.system != System::Glonass || glonass_.empty()) return nullptr;
  return pickGlonass(glonass_[satIndex(sat)], t, maxHalfWindow(System::Glonass), policy, nullptr);
}

EphemerisChoice<GlonassEphemeris> EphemerisStore::chooseGlonass(SatId sat, const GpsTime& t,
                                                               const EphemerisSelection& policy) const {
  const double bound = maxHalfWindow(System::Glonass);
  Edges edges(t, bound);
  if (!sat.valid() || sat.system != System::Glonass || glonass_.empty()) return edges.choice<GlonassEphemeris>(nullptr);
  return edges.choice(pickGlonass(glonass_[satIndex(sat)], t, bound, policy, &edges));
}

void EphemerisStore::setPrecise(std::shared_ptr<const PreciseEphemeris> precise) {
  precise_ = std::move(precise);
  ++revision_;
}

void EphemerisStore::setSatelliteAntennas(std::shared_ptr<const AntexData> antex) {
  antex_ = std::move(antex);
  ++revision_;
}

void EphemerisStore::setCodeBiases(std::shared_ptr<const BiasSinexData> biases) {
  biases_ = std::move(biases);
  ++revision_;
}

std::optional<double> EphemerisStore::preciseCodeBias(const SatelliteState& state, SatId sat, ObsCode code,
                                                      const GpsTime& t) const {
  if (state.ssr) {
    if (const auto b = ssr_.codeBias(sat, code, t)) return -*b / constants::kSpeedOfLight;
    return std::nullopt;
  }
  if (!state.precise || !biases_) return std::nullopt;
  return biases_->codeOsb(sat, code, t);
}

double EphemerisStore::codeDelay(const SatelliteState& state, SatId sat, ObsCode code, const GpsTime& t,
                                 const EphemerisSelection& policy) const {
  if (const auto osb = preciseCodeBias(state, sat, code, t)) return *osb;
  return groupDelay(sat, code, t, policy);
}

void EphemerisStore::addSsr(const SsrMessage& message) {
  ssr_.add(message);
  ++revision_;
}

void EphemerisStore::setSsrOptions(const SsrOptions& options) {
  ssr_.setOptions(options);  // only the selection changes; what was received is kept
  ++revision_;
}

std::optional<SatelliteState> EphemerisStore::ssrState(SatId sat, const GpsTime& t,
                                                       const EphemerisSelection& policy) const {
  if (ssr_.empty() || !sat.valid()) return std::nullopt;
  const auto sel = ssr_.select(sat, t);
  if (!sel) return std::nullopt;
  const int iod = sel->orbit.issueOfData;
  std::optional<SatelliteState> broadcast;
  if (sat.system == System::Glonass) {
    const GlonassEphemeris* best = nullptr;
    for (const auto& g : glonassRecords(sat)) {
      if (ssrIssueOfData(g) != iod || std::abs(t - g.toe) > validityHalfWindow(g)) continue;
      if (!best || std::abs(t - g.toe) < std::abs(t - best->toe)) best = &g;
    }
    if (best) broadcast = glonassSatelliteState(*best, t);
  } else {
    const KeplerEphemeris* best = nullptr;
    auto rank = [&](const KeplerEphemeris& e) {
      if (sat.system != System::Galileo) return 0;
      const bool inav = e.message == NavMessage::GalileoInav;
      return inav == policy.preferGalileoInav ? 0 : 1;
    };
    for (const auto& e : keplerRecords(sat)) {
      if (ssrIssueOfData(e) != iod || std::abs(t - e.toe) > validityHalfWindow(e)) continue;
      if (!best || rank(e) < rank(*best) ||
          (rank(e) == rank(*best) && std::abs(t - e.toe) < std::abs(t - best->toe)))
        best = &e;
    }
    if (best) broadcast = keplerSatelliteState(*best, t);
  }
  if (!broadcast || (!broadcast->healthy && !policy.allowUnhealthy)) return std::nullopt;
  return applySsr(*broadcast, *sel, t);
}

std::optional<SatelliteState> EphemerisStore::preciseState(SatId sat, const GpsTime& t) const {
  if (!precise_ || !sat.valid()) return std::nullopt;
  auto st = precise_->satelliteState(sat, t);
  if (!st) return st;
  if (antex_) {
    const auto offset = satelliteAntennaOffset(*antex_, sat, t, st->position);
    if (!offset) return std::nullopt;  // centre of mass only: the broadcast record is better
    st->position += *offset;
  }
  st->precise = true;
  return st;
}

std::optional<SatelliteState> EphemerisStore::satelliteState(SatId sat, const GpsTime& t,
                                                             const EphemerisSelection& policy) const {
  if (auto st = preciseState(sat, t)) return st;
  if (!ssr_.empty()) {
    if (auto st = ssrState(sat, t, policy)) return st;
    if (ssr_.coversSystem(sat.system, t)) return std::nullopt;
  }
  if (sat.system == System::Glonass) {
    if (const auto* g = selectGlonass(sat, t, policy)) return glonassSatelliteState(*g, t);
    return std::nullopt;
  }
  if (const auto* e = selectKepler(sat, t, policy)) return keplerSatelliteState(*e, t);
  return std::nullopt;
}

double EphemerisStore::groupDelay(SatId sat, ObsCode code, const GpsTime& t,
                                  const EphemerisSelection& policy) const {
  if (sat.system == System::Glonass) {
    const auto* g = selectGlonass(sat, t, policy);
    return g ? broadcastGroupDelay(*g, code) : 0.0;
  }
  const auto* e = selectKepler(sat, t, policy);
  return e ? broadcastGroupDelay(*e, code, cnavGroupDelays(sat, t)) : 0.0;
}

void EphemerisStore::add(const CnavGroupDelays& cnav) {
  if (!cnav.sat.valid() || (cnav.sat.system != System::Gps && cnav.sat.system != System::Qzss)) return;
  if (cnav_.size() < static_cast<std::size_t>(numSatIndices())) cnav_.resize(numSatIndices());
  auto& list = cnav_[satIndex(cnav.sat)];
  auto it = std::upper_bound(list.begin(), list.end(), cnav.time,
                             [](const GpsTime& t, const CnavRun& r) { return t < r.first.time; });
  if (it != list.begin()) {
    CnavRun& before = *std::prev(it);
    if (before.first.sameCorrections(cnav)) {
      if (before.lastSeen < cnav.time) before.lastSeen = cnav.time;
      return;
    }
  }
  if (it != list.end() && it->first.sameCorrections(cnav)) {  // the same, seen earlier than known
    it->first = cnav;
    return;
  }
  list.insert(it, CnavRun{cnav, cnav.time});
}

const CnavGroupDelays* EphemerisStore::cnavGroupDelays(SatId sat, const GpsTime& t) const {
  if (!sat.valid() || cnav_.empty()) return nullptr;
  const auto& list = cnav_[satIndex(sat)];
  auto it = std::upper_bound(list.begin(), list.end(), t,
                             [](const GpsTime& x, const CnavRun& r) { return x < r.first.time; });
  if (it == list.begin()) return nullptr;
  const CnavRun& r = *std::prev(it);
  const double age = r.lastSeen < t ? t - r.lastSeen : 0.0;
  return age <= kCnavGroupDelayMaxAge ? &r.first : nullptr;
}

std::vector<SatId> EphemerisStore::satellites() const {
  std::vector<SatId> out;
  const int n = numSatIndices();
  for (int i = 0; i < n; ++i) {
    const bool k = i < static_cast<int>(kepler_.size()) && !kepler_[i].empty();
    const bool g = i < static_cast<int>(glonass_.size()) && !glonass_[i].empty();
    if (k || g) out.push_back(satFromIndex(i));
  }
  return out;
}

std::size_t EphemerisStore::size() const {
  std::size_t n = 0;
  for (const auto& l : kepler_) n += l.size();
  for (const auto& l : glonass_) n += l.size();
  return n;
}

const std::vector<KeplerEphemeris>& EphemerisStore::keplerRecords(SatId sat) const {
  if (!sat.valid() || kepler_.empty()) return kNoKepler;
  return kepler_[satIndex(sat)];
}

const std::vector<GlonassEphemeris>& EphemerisStore::glonassRecords(SatId sat) const {
  if (!sat.valid() || glonass_.empty()) return kNoGlonass;
  return glonass_[satIndex(sat)];
}

}  // namespace gvins
