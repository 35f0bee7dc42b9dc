// Generates a dataset folder from a scenario (layout: docs/dataset_format.md): the trajectory,
// the IMU log, the camera images (rendered in parallel) or feature tracks, the ground truth in
// the local frame and in ECEF, the calibration files, dataset.yaml, and the GNSS part
// (GnssSimulator) when the scenario has one. The same scenario and seed give byte-identical
// files, whatever the number of threads.
#pragma once

#include <cstdint>
#include <filesystem>
#include <iosfwd>
#include <memory>
#include <string>
#include <vector>

#include "gvins/sim/scenario.hpp"
#include "gvins/sim/trajectory.hpp"

namespace gvins::sim {

struct GenerationOptions {
  std::uint64_t seed = 1;
  bool featuresOnly = false;  ///< force feature tracks instead of images
  bool gnss = true;           ///< false: skip the GNSS part even if the scenario has one
  int threads = 0;            ///< rendering threads, 0 = hardware concurrency
  std::ostream* progress = nullptr;  ///< progress lines (e.g. &std::cerr)
};

struct GenerationSummary {
  std::string scenario;
  std::uint64_t seed = 0;
  std::string startGpst;
  double duration = 0.0;         ///< s
  double pathLength = 0.0;       ///< m, 3-D
  double maxSpeed = 0.0;         ///< m/s
  double maxHeight = 0.0;        ///< m above the ground
  std::size_t imuSamples = 0;
  double imuRate = 0.0;
  int cameras = 0;
  std::size_t framesPerCamera = 0;
  bool images = true;
  std::size_t featureObservations = 0;
  std::size_t landmarks = 0;
  std::size_t buildings = 0;  ///< of the 3-D structure (scene.structure), 0 without
  double meanFeaturesPerImage = 0.0;
  double meanBlurSamples = 0.0;
  std::size_t textureTiles = 0;
  double secondsTrajectoryImu = 0.0, secondsCameras = 0.0, secondsGnss = 0.0, secondsTotal = 0.0;
  std::uintmax_t bytes = 0;
  std::string gnssSummary;  ///< GnssSimSummary table, empty without GNSS

  void print(std::ostream& os) const;
};

/// What one dataset may ask for, checked before anything is written (a scenario of 10,000
/// far-apart waypoints would otherwise fill a disk): trajectory length, IMU samples, and the raw
/// size of the rendered images (8-bit pixels of every camera and frame).
struct GenerationLimits {
  double maxDuration = 6.0 * 3600.0;  ///< s
  double maxImuSamples = 2e7;
  double maxImageBytes = 20e9;        ///< before PNG compression
};

/// The scenario's trajectory (flight from its spec and the seed, or the recorded one).
std::unique_ptr<Trajectory> buildTrajectory(const Scenario& scenario, std::uint64_t seed);

/// Writes the dataset into `dir` (created; existing files of the same names are overwritten).
/// Throws ParseError for bad input files (recorded trajectory, navigation file),
/// std::invalid_argument for inconsistent scenarios or ones beyond GenerationLimits (before
/// writing anything), std::runtime_error for write errors.
GenerationSummary generateDataset(const Scenario& scenario, const std::filesystem::path& dir,
                                  const GenerationOptions& options);

}  // namespace gvins::sim
