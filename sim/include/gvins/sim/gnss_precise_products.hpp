// Precise orbit (SP3-d) and clock (RINEX clock 3.04) products of a simulated constellation: the
// true satellite orbits and clocks plus small per-satellite product errors
// (GnssPreciseProductsConfig), written in the conventions of IGS products so that the user side
// (gvins/ephemeris/precise_ephemeris.hpp) reads them like downloaded files: clocks without the
// periodic relativistic term −2 r·v/c² (IS-GPS-200 20.3.3.3.3.1), epochs in GPST.
//
// The simulated positions are those the ranges are computed to, i.e. antenna phase centres. With
// GnssPreciseProductsConfig::centreOfMass (default) the orbits are written as IGS ones are, as
// centres of mass: the phase-centre position minus the yaw-steered offset of invented per-satellite
// antenna offsets, which go into an ANTEX file (gvins/ephemeris/satellite_antenna.hpp gives the
// phase centre back). The clocks have the simulator's broadcast convention (the same group delays
// apply as with the broadcast clock).
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <vector>

#include "gvins/base/gnss_time.hpp"
#include "gvins/ephemeris/antex.hpp"
#include "gvins/ephemeris/rinex_clock.hpp"
#include "gvins/ephemeris/sp3.hpp"
#include "gvins/sim/gnss_constellation.hpp"
#include "gvins/sim/gnss_sim_config.hpp"

namespace gvins::sim {

struct GnssPreciseProducts {
  Sp3Data orbits;
  ClockData clocks;
  std::optional<AntexData> antennas;  ///< centre-of-mass orbits: their satellite antenna offsets
};

/// Products covering [start − margin, end + margin] with margin = 6 orbit intervals (enough nodes
/// on both sides for a degree-10 Lagrange interpolation), epochs on multiples of the intervals.
/// Satellites without a true state at an epoch get a missing record there.
GnssPreciseProducts makePreciseProducts(const GnssConstellation& constellation, const GnssPreciseProductsConfig& config,
                                        const GpsTime& start, const GpsTime& end, std::uint64_t seed);

/// Writes precise.sp3, precise.clk (and satellites.atx with the antennas) into `dir`; returns their
/// paths.
std::vector<std::filesystem::path> writePreciseProducts(const GnssPreciseProducts& products,
                                                        const std::filesystem::path& dir);

}  // namespace gvins::sim
