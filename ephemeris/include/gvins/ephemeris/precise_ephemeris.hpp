// Satellite states from precise orbit (SP3) and clock (RINEX clock) products, interpolated to an
// arbitrary time, in the same convention as the broadcast SatelliteState.
//
// NOTE: IGS SP3 positions refer to the satellite centre of mass, whereas broadcast ephemerides
// refer to the antenna phase centre. No antenna offset is applied here; a user mixing the two
// (or processing carrier phase) must apply the satellite antenna offsets (IGS ANTEX) themselves.
#pragma once

#include <map>
#include <optional>
#include <utility>
#include <vector>

#include "gvins/base/gnss_time.hpp"
#include "gvins/base/satellite.hpp"
#include "gvins/ephemeris/rinex_clock.hpp"
#include "gvins/ephemeris/satellite_state.hpp"
#include "gvins/ephemeris/sp3.hpp"

namespace gvins {

struct PreciseEphemerisOptions {
  int lagrangeOrder = 10;         ///< polynomial degree for positions (order+1 nodes around t; 1-20)
  /// s: largest gap between two clock samples interpolated linearly. SP3 clocks are also
  /// interpolated between consecutive epochs of their file (up to 1.5 epoch intervals apart) when
  /// that is larger, so that 15-min SP3 clocks remain usable without a clock file.
  double maxClockGap = 330.0;
  double maxExtrapolation = 0.0;  ///< s beyond the first/last position node and clock sample (0: none)
};

class PreciseEphemeris {
 public:
  explicit PreciseEphemeris(PreciseEphemerisOptions options = {});

  /// Adds an orbit file; several files (consecutive days) may be added. Duplicate epochs keep the
  /// data added later. Two consecutive nodes more than 1.5 epoch intervals apart (the ## interval,
  /// or the smallest epoch spacing when it is 0) are a data gap.
  void add(const Sp3Data& orbits);
  /// Adds clock samples; clock files take precedence over SP3 clocks where both exist.
  void add(const ClockData& clocks);

  /// Position (Lagrange interpolation of the nodes around t; missing/NaN nodes make the satellite
  /// unavailable in that window), velocity (analytic derivative of the same interpolant, or the
  /// SP3 V records interpolated when present), clock bias and drift (linear between the two clock
  /// samples bracketing t, from the clock files or else the SP3 clocks), PLUS the periodic
  /// relativistic correction -2 r.v / c^2 (IS-GPS-200 20.3.3.3.3.1; IERS Conventions 2010
  /// eq. 10.10) added to clockBias (and its rate -2 (v.v + r.a) / c^2 to clockDrift, a from the
  /// interpolant), so the result has the convention of the broadcast SatelliteState.
  /// accuracy = the SP3 accuracy (2^exp mm from the ++ lines) in m, or 0.
  /// std::nullopt when t is not covered (no nodes on both sides within the interval, or a clock gap).
  std::optional<SatelliteState> satelliteState(SatId sat, const GpsTime& t) const;

  bool hasOrbit(SatId sat) const;
  std::vector<SatId> satellites() const;
  /// First/last orbit epoch over all satellites (default GpsTime pair when empty).
  std::pair<GpsTime, GpsTime> span() const;

 private:
  struct OrbitNode {
    Eigen::Vector3d position;                 // m (NaN if missing)
    std::optional<Eigen::Vector3d> velocity;  // m/s, from SP3 V records
    double interval = 0.0;                    // the file's epoch interval, s
  };
  struct Track {
    std::map<GpsTime, OrbitNode> orbit;   // all orbit nodes, later files replacing earlier ones
    std::vector<GpsTime> times;           // the same as sorted arrays (rebuilt by add)
    std::vector<OrbitNode> nodes;
    std::map<GpsTime, std::pair<double, double>> sp3Clock;  // s, and the file's interval
    std::map<GpsTime, double> fileClock;  // s, from RINEX clock files
    double accuracy = 0.0;                // m
  };
  PreciseEphemerisOptions options_;
  std::map<SatId, Track> tracks_;
};

}  // namespace gvins
