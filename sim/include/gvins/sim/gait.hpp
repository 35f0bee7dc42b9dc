// Walking oscillation of a hand-held (or head-mounted) rig: the vertical bob of each step, the
// lateral sway of each stride (two steps) and the small pitch (per step) and roll and yaw (per
// stride) of the hand, added to the timed samples of a route (route.hpp). The phase advances
// with the distance walked (2 pi per step of `stepLength`), so the oscillation stops when the
// walker stands still; its amplitude fades in below 1 m/s. Typical figures: steps of 0.6-0.8 m
// at ~2 Hz and a vertical bob of the head or hand of 2-5 cm while walking at 1.4 m/s.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "gvins/sim/route.hpp"

namespace gvins::sim {

struct GaitConfig {
  double stepLength = 0.7;  ///< m
  double bob = 0.025;       ///< m, vertical amplitude (once per step)
  double sway = 0.02;       ///< m, lateral amplitude (once per stride)
  double tiltDeg = 1.5;     ///< deg, amplitude of the hand's pitch (per step), roll and yaw (per stride)

  /// Throws std::invalid_argument naming the first out-of-range value.
  void validate() const;
};

/// Gait phase (rad) and amplitude weight in [0, 1] of every sample.
struct GaitPhase {
  std::vector<double> phase, weight;
};
GaitPhase gaitPhase(const GaitConfig& gait, const RouteSamples& samples);

/// Adds the bob (up) and sway (left of the heading) to the sample positions.
void addGaitMotion(const GaitConfig& gait, const GaitPhase& phase, RouteSamples& samples);

/// Roll, pitch, yaw (rad) of the hand at every sample (control points of the attitude
/// perturbation, SplineTrajectory's wobble).
std::vector<Eigen::Vector3d> gaitAngles(const GaitConfig& gait, const GaitPhase& phase);

}  // namespace gvins::sim
