// gvins-replay configuration file (--config F.yaml). Every key is optional; unknown keys are
// errors (gvins::ParseError naming file, line and key):
//
//   replay:
//     max_imu_gap_s: 0.05        # IMU gaps longer than this ...
//     imu_gaps: error            # ... stop the replay (error) or are counted (warn)
//     skip_bad_images: false     # undecodable images: error, or skip the frame and count it
//     skip_missing_images: false # listed images without a file: error, or drop and count
//     start_s: 0                 # replay from this many seconds after the first frame
//     duration_s: 0              # for this long (0: to the end)
//     feature_tracks: true       # use camN/features.csv when the dataset has it
//     evaluate: true             # accuracy table and plots when the dataset has ground truth
//     stereo: true               # match into cam1 when present (image front end)
//     max_track_travel_px: 50    # image front end: end tracks (10 images or older) once they
//                                # have moved 50 px since detection (0: never)
//     max_track_length: 0        # ... or after this many images (0: never)
//     klt_window_px: 21          # KLT window side (odd, 5-61); 11 is faster, see docs/replay.md
//     align_templates: true      # refine every tracked position against the track's
//                                # detection patch (affine warp, gain, bias): no chained drift
//     template_max_track_travel_px: 0  # travel limit for template-refined tracks (0: never)
//   estimator: sri_swf.yaml      # SRI-SWF configuration file (sri_swf_estimator.hpp), relative
//                                # to this file; default: noise and cameras from the dataset
//   gnss_fusion: { ... }         # GnssFusion options (gnss_fusion_config.hpp), read by its parser
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "gvins/fusion/replay_pipeline.hpp"

namespace gvins::fusion {

struct ReplayConfig {
  ReplayOptions options;            ///< only the fields of the replay: section are set
  std::string estimatorConfig;      ///< resolved path, empty if not given
  bool hasGnssFusion = false;       ///< the document has a gnss_fusion: section
  std::string text, file;           ///< the document (for the GNSS parser)
};

/// `base_dir` resolves relative paths.
ReplayConfig parseReplayConfig(std::string_view text, const std::string& file, const std::string& base_dir = ".");
ReplayConfig loadReplayConfig(const std::string& path);

}  // namespace gvins::fusion
