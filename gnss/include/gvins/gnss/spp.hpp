// Single point positioning: iterative weighted least squares for the receiver position and one
// clock bias per constellation from broadcast ephemerides, with fault detection and exclusion,
// DOPs, a covariance for every solution, and Doppler velocity.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "gvins/base/local_frame.hpp"
#include "gvins/base/observation.hpp"
#include "gvins/ephemeris/ephemeris_cache.hpp"
#include "gvins/ephemeris/ephemeris_store.hpp"
#include "gvins/gnss/dop.hpp"
#include "gvins/gnss/doppler_velocity.hpp"
#include "gvins/gnss/position_solution.hpp"
#include "gvins/gnss/signal_choice.hpp"
#include "gvins/gnss/spp_config.hpp"

namespace gvins {

enum class SppStatus {
  Ok,
  NoObservations,       ///< no usable pseudorange in the epoch
  NotEnoughSatellites,  ///< fewer measurements than unknowns
  NoConvergence,
  GdopTooLarge,
  TestFailed,  ///< residual test failed even after exclusions (solution still reported)
};
const char* toString(SppStatus s);

/// Why a satellite of the epoch did not contribute.
enum class SatelliteUse {
  Used,
  SystemDisabled,
  NoSignal,      ///< no pseudorange on the configured bands
  LowSnr,
  NoEphemeris,   ///< no usable (healthy, valid) broadcast record
  BelowMask,
  Excluded,      ///< removed by fault exclusion
};

struct SatelliteResidual {
  SatId sat;
  SatelliteUse use = SatelliteUse::Used;
  AzEl azel;
  double residual = 0.0;  ///< m, post-fit (pre-fit for excluded satellites)
  double sigma = 0.0;     ///< m, a priori
  double weightFactor = 1.0;  ///< < 1 when robust estimation down-weighted the measurement
  bool ionosphereFree = false;
};

struct SppSolution {
  GpsTime time;          ///< receiver time tag of the epoch
  GpsTime solutionTime;  ///< time tag corrected by the receiver clock of the reference system
  SppStatus status = SppStatus::NoObservations;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();            ///< ECEF, m
  Eigen::Matrix3d positionCovariance = Eigen::Matrix3d::Zero();  ///< ECEF, m^2
  /// Factor the least-squares covariance was scaled by (SppConfig::covarianceScaling; 1: none);
  /// with SppConfig::reportedError that of its independent part only.
  double varianceFactor = 1.0;
  /// Receiver clock bias per system (m), present for the systems estimated.
  std::array<std::optional<double>, kNumSystems> clockBias;
  std::array<double, kNumSystems> clockBiasVariance{};
  /// Estimated correction to the broadcast model's zenith ionospheric delay on L1 (m), when the
  /// ionosphere is estimated.
  std::optional<double> ionosphereCorrection;
  Dop dop;
  int numSatellites = 0;  ///< used in the position
  std::vector<SatId> excluded;
  double chi2 = 0.0;
  int dof = 0;
  bool testPassed = false;
  int iterations = 0;
  VelocitySolution velocity;  ///< valid when Doppler was available
  std::vector<SatelliteResidual> satellites;  ///< every satellite of the epoch

  bool valid() const { return status == SppStatus::Ok || status == SppStatus::TestFailed; }
  /// As a PositionSolution (quality Single) for the .pos writer.
  PositionSolution toPositionSolution() const;
};

class SppSolver {
 public:
  /// `nav` must outlive the solver.
  SppSolver(const EphemerisStore& nav, SppConfig config = {});

  /// GLONASS FDMA channels from the observation header (the navigation data's are used for slots
  /// missing here).
  void setGlonassChannels(const GlonassChannels& channels);
  /// A-priori receiver position (e.g. RINEX "APPROX POSITION XYZ"); otherwise the solver starts
  /// from the last solution or the Earth's centre.
  void setInitialPosition(const Eigen::Vector3d& ecef);
  /// Forgets the last solution and the inter-system bias priors.
  void reset();

  SppSolution solve(const ObsEpoch& epoch);
  const SppConfig& config() const { return config_; }
  /// One message per system and signal used instead of the first band of `bands` (the band was
  /// not tracked; signal_choice.hpp), in the order they first occurred.
  const std::vector<std::string>& signalNotices() const { return signalNotices_.messages(); }

 private:
  struct Measurement;
  class Fit;  // one epoch's least-squares solution (spp.cpp)
  struct Isb {
    bool known = false;
    double value = 0.0;  ///< clock(system) - clock(GPS), m
    double variance = 0.0;
    GpsTime time;
  };
  bool gatherMeasurements(const ObsEpoch& epoch, SppSolution& sol, std::vector<Measurement>& meas);
  void updateIsb(const SppSolution& sol, const Eigen::MatrixXd& cov, const std::vector<int>& clockSystems);

  const EphemerisStore& nav_;
  SppConfig config_;
  EphemerisCache ephemerides_;  // record selection per satellite, reused across epochs
  GlonassChannels channels_;
  std::optional<Eigen::Vector3d> initial_;
  std::optional<Eigen::Vector3d> last_;
  GpsTime lastTime_;
  std::array<Isb, kNumSystems> isb_{};
  SignalFallbackNotices signalNotices_;
};

}  // namespace gvins
