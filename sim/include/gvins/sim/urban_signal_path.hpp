// The path of a GNSS signal through an UrbanStructure (urban_structure.hpp): for a satellite in
// direction u seen from an antenna at p (both in W), the direct ray either clears every
// building (line of sight) or enters one below its roof (blocked). A blocked satellite is still
// received, delayed, when a facade facing it within 60 m reflects the signal to the antenna
// (non-line-of-sight: the reflection point on the face, below its roof, with a clear ray from
// there to the satellite); the extra path of a reflection off a vertical plane at distance d from the
// antenna, whose outward normal n faces the satellite (u.n > 0), is 2 d (u.n) (image-antenna
// geometry; e.g. Groves, "Principles of GNSS, Inertial, and Multisensor Integrated Navigation
// Systems", 2nd ed., 10.4). Otherwise the signal is lost. Multipath grows near facades:
// the scale 1 + 2 exp(-d_min / 8 m) of the nearest facade's distance d_min.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "gvins/sim/urban_structure.hpp"

namespace gvins::sim {

struct UrbanSignalPath {
  enum class Kind { LineOfSight, Reflected, Blocked };
  Kind kind = Kind::LineOfSight;
  double extraPath = 0.0;       ///< m, reflected only
  double multipathScale = 1.0;  ///< factor on the receiver's multipath sigma
};

/// Buildings that can matter to an antenna at p (within `radius` metres horizontally).
std::vector<int> buildingsNear(const UrbanStructure& world, const Eigen::Vector3d& p, double radius = 300.0);

/// The path of the signal from direction u (unit, W) to the antenna at p, over `candidates`
/// (indices from buildingsNear).
UrbanSignalPath urbanSignalPath(const UrbanStructure& world, const Eigen::Vector3d& p, const Eigen::Vector3d& u,
                                const std::vector<int>& candidates);

}  // namespace gvins::sim
