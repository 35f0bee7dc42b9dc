// Dilution of precision from the receiver-satellite geometry.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "gvins/base/satellite.hpp"

namespace gvins {

struct Dop {
  double gdop = 0.0;
  double pdop = 0.0;
  double hdop = 0.0;
  double vdop = 0.0;
  double tdop = 0.0;  ///< of the first clock
  bool valid = false;
};

/// DOPs for unit line-of-sight vectors in the local ENU frame (receiver to satellite) and the
/// clock each measurement depends on (0..numClocks-1, one per constellation): the diagonal of
/// (G^T G)^-1 with rows G = [-e^T, 1 in the clock's column] (unweighted). Invalid (zeros) when
/// the geometry is singular, there are fewer measurements than unknowns or more clocks than
/// constellations (kNumSystems).
Dop computeDop(const std::vector<Eigen::Vector3d>& losEnu, const std::vector<int>& clockIndex, int numClocks);

}  // namespace gvins
