// Why the SRI-SWF estimator has not initialised yet (or that it has): the outcome of its last
// initialisation attempt (visual_inertial_initializer.hpp, docs/vio_estimator.md "Initialisation").
#pragma once

#include <string_view>

namespace gvins::vio {

enum class InitStatus {
  kInitialized,         ///< the estimator runs
  kCollecting,          ///< too few frames or IMU samples buffered for any test yet
  kStaticNoTracks,      ///< the IMU is at rest but too few tracks to confirm it (static init off)
  kMovingNoAcceleration,///< the IMU sees no excitation but the features move: constant velocity or
                        ///< acceleration, the degenerate motion of mono VIO (scale unobservable)
  kTooFewTracks,        ///< too few features tracked through the alignment window
  kTooLittleParallax,   ///< tracked, but the camera has not moved enough relative to the depth
  kTooLittleAcceleration,///< structure is there, but the scale is not observable from the accelerometer
  kInconsistent,        ///< the alignment's gravity or scale came out implausible (rejected)
  kNoAttempt,           ///< no attempt this frame (waiting for more parallax or acceleration)
};

/// Short text for progress lines and summaries ("too little parallax", ...).
constexpr std::string_view initStatusText(InitStatus s) {
  switch (s) {
    case InitStatus::kInitialized: return "initialised";
    case InitStatus::kCollecting: return "collecting";
    case InitStatus::kStaticNoTracks: return "static, no tracks";
    case InitStatus::kMovingNoAcceleration: return "constant velocity/acceleration (scale unobservable)";
    case InitStatus::kTooFewTracks: return "too few tracks";
    case InitStatus::kTooLittleParallax: return "too little parallax";
    case InitStatus::kTooLittleAcceleration: return "too little acceleration";
    case InitStatus::kInconsistent: return "alignment rejected";
    case InitStatus::kNoAttempt: return "waiting";
  }
  return "?";
}

}  // namespace gvins::vio
