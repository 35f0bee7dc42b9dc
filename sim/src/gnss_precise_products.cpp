#include "gvins/sim/gnss_precise_products.hpp"

#include <cmath>
#include <fstream>
#include <stdexcept>

#include <Eigen/Geometry>

#include "gvins/base/constants.hpp"
#include "gvins/ephemeris/satellite_antenna.hpp"
#include "gvins/sim/gnss_random.hpp"

namespace gvins::sim {

namespace {

// Split of the product SISRE into radial, along-track, cross-track orbit and clock errors. Precise
// orbit errors are of the same size in all three directions (IGS final orbits ~2.5 cm 3-D) and the
// clock error is correlated with the radial one; a ground user sees about the configured value.
constexpr double kRadial = 0.5, kAlong = 1.0, kCross = 1.0, kClock = 0.8;
// Drift of each error per hour, as a fraction of its size.
constexpr double kDriftPerHour = 0.3;

// First multiple of `step` seconds (counted from the GPS epoch) at or after t.
GpsTime alignUp(const GpsTime& t, double step) {
  const double k = std::ceil(t.toSecondsApprox() / step - 1e-9);
  const double v = k * step;
  const double whole = std::floor(v);
  return GpsTime::fromSeconds(static_cast<std::int64_t>(whole), v - whole);
}

}  // namespace

GnssPreciseProducts makePreciseProducts(const GnssConstellation& constellation, const GnssPreciseProductsConfig& config,
                                        const GpsTime& start, const GpsTime& end, std::uint64_t seed) {
  if (!(config.orbitInterval > 0.0) || !(config.clockInterval > 0.0))
    throw std::invalid_argument("precise_products: intervals must be positive");
  const double margin = 6.0 * config.orbitInterval;
  const GpsTime first = alignUp(start - margin, config.orbitInterval);
  const GpsTime last = end + margin;
  const double c = constants::kSpeedOfLight;

  struct Errors {
    Eigen::Vector4d e0, e1;
  };
  std::vector<Errors> errors;
  for (SatId sat : constellation.satellites()) {
    GnssRandom rng(streamSeed(seed, {0xC1, static_cast<std::uint64_t>(satIndex(sat))}));
    const double sisre = config.sisre[static_cast<std::size_t>(systemIndex(sat.system))];
    const double scale[4] = {kRadial, kAlong, kCross, kClock};
    Errors e;
    for (int k = 0; k < 4; ++k) {
      e.e0[k] = rng.normal(sisre * scale[k]);
      e.e1[k] = rng.normal(sisre * scale[k] * kDriftPerHour);
    }
    errors.push_back(e);
  }
  GnssPreciseProducts out;
  // Satellite antennas of centre-of-mass products: invented offsets on both reference frequencies
  // (the second band's z up to 10 cm off the first's, as real ones differ).
  if (config.centreOfMass) {
    AntexData& a = out.antennas.emplace();
    a.comments = {"gvins-sim: invented satellite antenna offsets of the simulated products"};
    for (SatId sat : constellation.satellites()) {
      GnssRandom rng(streamSeed(seed, {0xA7, static_cast<std::uint64_t>(satIndex(sat))}));
      AntexAntenna ant;
      ant.type = std::string("GVINS-SIM ") + std::string(systemName(sat.system));
      ant.serial = sat.str();
      ant.satellite = sat;
      ant.svn = sat.str();
      ant.zen1 = 0.0;
      ant.zen2 = 14.0;
      ant.dzen = 1.0;
      ant.validFrom = first - 86400.0;
      const Eigen::Vector3d pco(rng.uniform(-0.4, 0.4), rng.uniform(-0.01, 0.01), rng.uniform(0.5, 2.6));
      const double dz = rng.uniform(-0.1, 0.1);
      const auto [b1, b2] = referenceFrequencyPair(sat.system);
      for (char b : {b1, b2}) {
        AntexFrequency f;
        f.system = sat.system;
        f.band = b;
        f.offset = pco + Eigen::Vector3d(0.0, 0.0, b == b2 ? dz : 0.0);
        f.noAzimuth.assign(15, 0.0);
        ant.frequencies.push_back(f);
      }
      a.antennas.push_back(std::move(ant));
    }
  }
  // Product state at t: truth plus the product error; the clock without the relativistic term;
  // the centre of mass c solves p = c + R(c) pco (a fixed point: R turns by ~1e-7 rad per metre).
  auto product = [&](std::size_t i, const GpsTime& t, Eigen::Vector3d& pos, double& clock) {
    const auto st = constellation.state(constellation.satellites()[i], t, margin + config.orbitInterval);
    if (!st) return false;
    const Eigen::Vector4d e = errors[i].e0 + errors[i].e1 * ((t - start) / 3600.0);
    const Eigen::Vector3d rHat = st->position.normalized();
    const Eigen::Vector3d cHat = st->position.cross(st->velocity).normalized();
    const Eigen::Vector3d aHat = cHat.cross(rHat);
    pos = st->position + e[0] * rHat + e[1] * aHat + e[2] * cHat;
    if (out.antennas) {
      const Eigen::Vector3d apc = pos;
      for (int k = 0; k < 3; ++k) {
        const auto off = satelliteAntennaOffset(*out.antennas, constellation.satellites()[i], t, pos);
        if (!off) break;
        pos = apc - *off;
      }
    }
    const double relativistic = -2.0 * st->position.dot(st->velocity) / (c * c);
    clock = st->clock - relativistic + e[3] / c;
    return true;
  };

  Sp3Data& o = out.orbits;
  o.version = 'd';
  o.timeSystem = "GPS";
  o.coordinateSystem = "IGb20";
  o.orbitType = "FIT";
  o.agency = "SIM";
  o.dataUsed = "ORBIT";
  o.interval = config.orbitInterval;
  o.satellites = constellation.satellites();
  for (SatId sat : o.satellites) {
    const double sisre = config.sisre[static_cast<std::size_t>(systemIndex(sat.system))];
    // Accuracy exponent: 2^exp mm closest to the 3-D orbit error.
    const double mm = std::max(1.0, 1e3 * sisre * std::sqrt(kRadial * kRadial + kAlong * kAlong + kCross * kCross));
    o.accuracyExponent.push_back(static_cast<int>(std::lround(std::log2(mm))));
  }
  o.comments = {"gvins-sim: true orbits and clocks plus simulated product errors",
                "(precise_products in the scenario's gnss section)"};
  for (GpsTime t = first; t <= last; t = t + config.orbitInterval) {
    Sp3Epoch ep;
    ep.time = t;
    for (std::size_t i = 0; i < o.satellites.size(); ++i) {
      Sp3Record r;
      r.sat = o.satellites[i];
      double clock = 0.0;
      if (product(i, t, r.position, clock)) r.clock = clock;
      ep.records.push_back(r);
    }
    o.epochs.push_back(std::move(ep));
  }

  ClockData& k = out.clocks;
  k.version = 3.04;
  k.timeSystem = "GPS";
  const GpsTime kFirst = alignUp(start - margin, config.clockInterval);
  for (std::size_t i = 0; i < constellation.satellites().size(); ++i) {
    std::vector<ClockRecord> recs;
    for (GpsTime t = kFirst; t <= last; t = t + config.clockInterval) {
      Eigen::Vector3d pos;
      double clock = 0.0;
      if (product(i, t, pos, clock)) recs.push_back({t, clock, 0.0});
    }
    if (!recs.empty()) k.satellites.emplace_back(constellation.satellites()[i], std::move(recs));
  }
  return out;
}

std::vector<std::filesystem::path> writePreciseProducts(const GnssPreciseProducts& products,
                                                        const std::filesystem::path& dir) {
  auto write = [&](const char* name, auto&& writer) {
    const auto path = dir / name;
    std::ofstream f(path, std::ios::binary);
    if (!f) throw std::runtime_error("cannot create " + path.string());
    writer(f);
    if (!f) throw std::runtime_error("writing " + path.string() + " failed");
    return path;
  };
  std::vector<std::filesystem::path> files{
      write("precise.sp3", [&](std::ostream& os) { writeSp3(os, products.orbits); }),
      write("precise.clk", [&](std::ostream& os) { writeRinexClock(os, products.clocks); })};
  if (products.antennas)
    files.push_back(write("satellites.atx", [&](std::ostream& os) { writeAntex(os, *products.antennas); }));
  return files;
}

}  // namespace gvins::sim
