// The GNSS half of gvins-sim: simulates rover and base along a trajectory and writes
// <dataset>/gnss/ (layout in docs/dataset_format.md, "gnss/"):
//   rover.obs, base.obs   RINEX 3.04 observations (time tags in receiver time, see below)
//   base.rtcm3            RTCM 3 stream of the base (1005/1006, MSM4/MSM7, ephemerides)
//   nav.rnx               RINEX 3.04 navigation file with the broadcast records used
//   truth/                antenna positions, clocks, ambiguities, slips, events, constants
// Time tags: each receiver samples on a grid of its own clock, so the RINEX epoch is receiver
// time; the true GPST of an epoch's measurements is tag - clock bias (truth/*_clock.csv), the
// clock bias is inside every pseudorange and phase, and the epoch record carries the receiver's
// own estimate of its clock offset ("RCV CLOCK OFFS APPL" = 0: nothing applied). This is what
// RTKLIB and gvins-spp expect from a real receiver: they compute transmit times from the
// pseudoranges and solve the clock.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <iosfwd>
#include <map>
#include <vector>

#include <Eigen/Core>

#include "gvins/ephemeris/rinex_nav.hpp"
#include "gvins/sim/gnss_receiver_sim.hpp"
#include "gvins/sim/gnss_sim_config.hpp"
#include "gvins/sim/local_frame.hpp"
#include "gvins/sim/trajectory.hpp"

namespace gvins::sim {

struct GnssSimSummary {
  GpsTime firstTag, lastTag;
  double roverRate = 0.0, baseRate = 0.0;
  std::int64_t roverEpochs = 0;       ///< epochs with observations written
  std::int64_t roverEmptyEpochs = 0;  ///< epochs without any signal (total outage)
  std::int64_t baseEpochs = 0;
  std::int64_t roverSignals = 0;      ///< signal observations written
  std::array<int, kNumSystems> roverSatellites{};  ///< distinct satellites per system
  std::array<double, kNumSystems> roverMeanSatellites{};  ///< mean per epoch
  std::array<int, kNumSystems> baseSatellites{};
  int roverSlips = 0, roverUnflaggedSlips = 0, roverRestarts = 0;
  int baseSlips = 0;
  int nlosEvents = 0, blockages = 0;
  double outageSeconds = 0.0;
  Eigen::Vector3d basePosition = Eigen::Vector3d::Zero();  ///< ECEF
  double baselineStart = 0.0;  ///< rover-base distance at the first epoch, m
  std::int64_t rtcmBytes = 0;
  std::map<int, std::int64_t> rtcmMessages;
  std::vector<std::filesystem::path> files;
  /// Satellites in the precise products (0: none written).
  std::size_t preciseSatellites = 0;
  std::int64_t ssrMessages = 0;  ///< SSR messages in gnss/ssr.rtcm3 (before splitting into frames)

  /// A short table for the tool's output.
  void print(std::ostream& os) const;
};

class GnssSimulator {
 public:
  explicit GnssSimulator(GnssSimConfig config);

  /// Reads the configured navigation file and simulates. Throws gvins::ParseError for a bad
  /// navigation file, std::invalid_argument when none is configured, std::runtime_error when a
  /// file cannot be written.
  GnssSimSummary run(const Trajectory& trajectory, const LocalFrame& frame, const Eigen::Vector3d& leverArmBody,
                     std::uint64_t seed, const std::filesystem::path& datasetDir) const;
  /// Same with navigation data already in memory.
  GnssSimSummary run(const NavData& nav, const Trajectory& trajectory, const LocalFrame& frame,
                     const Eigen::Vector3d& leverArmBody, std::uint64_t seed,
                     const std::filesystem::path& datasetDir) const;

  /// Progress lines (percent of the flight) go here when set (e.g. &std::cerr).
  void setProgressStream(std::ostream* os) { progress_ = os; }
  /// Rover signals through 3-D structure (GnssReceiverSim::setPathModel); none by default.
  void setRoverPathModel(GnssPathModel model) { pathModel_ = std::move(model); }
  const GnssSimConfig& config() const { return config_; }

 private:
  GnssSimConfig config_;
  std::ostream* progress_ = nullptr;
  GnssPathModel pathModel_;
};

}  // namespace gvins::sim
