// Single and double differences between a rover and a base receiver: the measurement model that
// RTK and the GNSS fusion share.
//
// Single differences (SD, rover minus base) are formed per satellite and band, one rover signal
// against one base signal of that band. Matching (RtkConfig::signalMatching):
//   - strict: the same RINEX code at both receivers only;
//   - band (default): the same code when both receivers have one; otherwise another tracking mode
//     of the band (receivers of different brands track different modes: Galileo E1 C against X,
//     GPS L2 L against X or W, ...), provided both receivers' phases are known to refer to the
//     band's reference signal (PhaseAlignment of each receiver, see base/phase_alignment.hpp:
//     RINEX 3.01+ with SYS / PHASE SHIFT records, RTCM MSM; raw tracking phases are aligned here
//     with the RINEX 3.04 Table A23 shift). Without that knowledge a quarter-cycle offset could
//     enter the double differences, so the pair is not formed (as strict; counted).
//   Among several pairs with phase (else with code) at both receivers: the same code first, then
//   two modes of one transmitted signal (sameSignal: L2L and L2X, E1C and E1X), then different
//   signals of the band (GPS L1 C/A and P(Y)); ties by the attribute priority of the rover, then of
//   the base. Code biases between different signals (e.g. GPS P1-C1) do not cancel in such a
//   double difference; they stay within the code noise model of short baselines.
// In metres,
//   SD phase:  λφ_r − λφ_b = ρ_r − ρ_b + c(dt_r − dt_b) + λN_rb + ε
//   SD code:   P_r − P_b   = ρ_r − ρ_b + c(dt_r − dt_b) + ε
// with ρ the geometric range with Sagnac term, minus the satellite clock, plus the modelled
// troposphere, each at its own receiver's epoch (the base part comes as an OMC from
// BaseStation). Satellite clocks, orbits and (for short baselines) atmosphere cancel.
//
// Double differences (DD) are SD differences within a group of one system and one band, against
// the group's reference satellite: the receiver clock difference cancels. The reference is the
// previous reference while it stays usable (observed with phase, above the mask, no slip), else
// the highest satellite with a continuous arc. Ambiguities are carried as SD states
// (RtkSolver), so a change of reference only changes which SD differences are formed: there is no
// state transformation to get wrong, and GLONASS (different wavelengths in one group) needs none
// either: its DD phase is λ_j φ_j − λ_i φ_i with the SD ambiguity of each satellite.
//
// Fusion use: a DdEpoch keeps everything needed to evaluate the residuals and Jacobians at any
// rover position (satellite positions at the rover transmit times, base OMC values, fixed
// ambiguities), see ddPhaseResidual / sdCodeResidual.
#pragma once

#include <cstdint>
#include <optional>
#include <unordered_map>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "gvins/base/observation.hpp"
#include "gvins/base/phase_alignment.hpp"
#include "gvins/ephemeris/ephemeris_store.hpp"
#include "gvins/gnss/base_station.hpp"
#include "gvins/gnss/cycle_slip_detector.hpp"
#include "gvins/gnss/rtk_config.hpp"
#include "gvins/gnss/transmit_states.hpp"

namespace gvins {

/// Rover-minus-base single difference of one satellite signal.
struct SingleDifference {
  SatId sat;
  ObsCode code;          ///< rover signal
  ObsCode baseCode;      ///< base signal (another tracking mode of the band when matched across modes)
  int group = -1;        ///< index into DdEpoch::groups
  double wavelength = 0.0;  ///< m (0: unknown, phase unusable)
  double elevation = 0.0;   ///< rad, at the rover
  double azimuth = 0.0;     ///< rad, at the rover
  double snr = 0.0;         ///< rover C/N0, dB-Hz (0 unknown)
  double baseSnr = 0.0;     ///< base C/N0, dB-Hz (0 unknown)
  Eigen::Vector3d satPosition = Eigen::Vector3d::Zero();  ///< at the rover transmit time (ECEF of that time)
  double satClock = 0.0;     ///< c·dt_s at that time, m
  double troposphere = 0.0;  ///< modelled rover slant delay, m
  bool hasPhase = false;
  bool hasCode = false;
  double roverPhase = 0.0;    ///< λφ_r, m
  double roverCode = 0.0;     ///< P_r, m
  double basePhaseOmc = 0.0;  ///< base phase minus its model, m
  double baseCodeOmc = 0.0;   ///< base code minus its model, m
  double phaseVariance = 0.0;  ///< of the SD phase, m²
  double codeVariance = 0.0;   ///< of the SD code, m² (rover plus base, RtkConfig::codeWeighting)
  GpsTime roverArc;  ///< start of the rover phase arc
  GpsTime baseArc;   ///< start of the base phase arc
  std::uint8_t roverSlip = 0;  ///< rover slip flags of this epoch (CycleSlipDetector)
  std::uint8_t baseSlip = 0;   ///< base slip flags of the base epoch used
  bool halfCycle = false;      ///< a half-cycle flag at either receiver: no integer fixing
  bool continuous = false;     ///< also formed in the previous epoch with the same arcs
};

/// One system and band.
struct DdGroup {
  System system = System::Gps;
  char band = '1';
  int phaseReference = -1;  ///< SD index of the reference satellite of the phase DDs (-1: none)
  int codeReference = -1;   ///< SD index of the reference of the code DDs
};

/// One double difference, satellite minus reference.
struct DoubleDifference {
  int reference = -1;  ///< SD index
  int satellite = -1;  ///< SD index
  /// Phase only: the integer DD ambiguity N_sat − N_ref (cycles) when resolved.
  std::optional<double> fixedCycles;
  /// Phase only: λ_sat N_sat − λ_ref N_ref (m) of the fixed solution, the term ddPhaseResidual
  /// subtracts (for GLONASS it includes the float SD ambiguity of the reference times Δλ; with
  /// the ionosphere-weighted model of RtkConfig it includes minus the DD ionospheric phase advance
  /// of the fixed solution, −(μ_sat I_sat − μ_ref I_ref)).
  std::optional<double> ambiguityMeters;
};

/// All differences of one rover epoch.
struct DdEpoch {
  GpsTime time;      ///< rover epoch
  GpsTime baseTime;  ///< base time the base values refer to
  double age = 0.0;  ///< s
  bool baseInterpolated = false;
  Eigen::Vector3d basePosition = Eigen::Vector3d::Zero();
  std::vector<SingleDifference> sd;
  std::vector<DdGroup> groups;
  std::vector<DoubleDifference> phase;
  std::vector<DoubleDifference> code;

  void clear();
  /// Number of distinct satellites with a phase DD (including references).
  int phaseSatellites() const;
};

/// Modelled SD range at rover position x: |r_s − x| + Sagnac − c·dt_s + T_r (m); `gradient`
/// receives its derivative w.r.t. x (see geometricRange).
double sdModelRange(const SingleDifference& sd, const Eigen::Vector3d& x, Eigen::Vector3d* gradient = nullptr);
/// SD phase residual (observed minus modelled, m) at x: c(dt_r − dt_b) + λN_rb + noise;
/// `gradient` receives the derivative of the model (not of the residual).
double sdPhaseResidual(const SingleDifference& sd, const Eigen::Vector3d& x, Eigen::Vector3d* gradient = nullptr);
/// SD code residual at x: c(dt_r − dt_b) + noise (the SD pseudorange of the paper, eq. z_dp).
double sdCodeResidual(const SingleDifference& sd, const Eigen::Vector3d& x, Eigen::Vector3d* gradient = nullptr);

struct DdResidual {
  double residual = 0.0;  ///< observed minus modelled, m (phase: minus the fixed ambiguity term)
  /// ∂(model)/∂x of the rover position: residual(x + δ) ≈ residual(x) − jacobian·δ.
  Eigen::RowVector3d jacobian = Eigen::RowVector3d::Zero();
  double variance = 0.0;  ///< m², of this DD alone (DDs sharing a reference are correlated)
};
/// DD phase residual at x; the ambiguity term is `dd.ambiguityMeters` (0 when not fixed, then the
/// residual still contains it).
DdResidual ddPhaseResidual(const DdEpoch& e, const DoubleDifference& dd, const Eigen::Vector3d& x);
DdResidual ddCodeResidual(const DdEpoch& e, const DoubleDifference& dd, const Eigen::Vector3d& x);
/// Covariance of a list of DDs (phase or code): var(sat) on the diagonal plus var(ref) wherever
/// two DDs share their reference.
Eigen::MatrixXd ddCovariance(const DdEpoch& e, const std::vector<DoubleDifference>& dds, bool phase);

/// Why rover satellites (or signals) were not differenced.
struct DdFormationStats {
  std::int64_t satellites = 0;       ///< rover satellite-epochs seen
  std::int64_t systemDisabled = 0;
  std::int64_t noEphemeris = 0;
  std::int64_t belowMask = 0;
  std::int64_t lowSnr = 0;
  std::int64_t notAtBase = 0;        ///< satellite absent from the base data
  std::int64_t signalMismatch = 0;   ///< a band seen by both receivers without a signal pair formed
  /// Of signalMismatch: a pair across tracking modes existed, but a receiver's phase alignment is
  /// unknown (or matching is strict).
  std::int64_t crossModeRefused = 0;
  std::int64_t crossMode = 0;        ///< signal-epochs differenced across tracking modes
  std::int64_t used = 0;             ///< satellite-epochs with at least one SD
};

class DoubleDifferenceBuilder {
 public:
  /// `nav` must outlive the builder.
  DoubleDifferenceBuilder(const EphemerisStore& nav, const RtkConfig& config);
  /// Rover GLONASS channels (header); the navigation data fill gaps.
  void setGlonassChannels(const GlonassChannels& channels);
  /// What rover and base data state about their phase alignment (default: Unknown, i.e. only
  /// the same codes are differenced).
  void setPhaseAlignment(const PhaseAlignments& rover, const PhaseAlignments& base);

  /// Forms the SDs and DDs of a rover epoch at the rover position `x` (linearisation point for
  /// elevations and the troposphere; residuals can be evaluated anywhere later). `roverSlips` must
  /// have processed this rover epoch.
  /// `states` (optional, for rover.time): satellite states already computed for this epoch.
  void form(const ObsEpoch& rover, const CycleSlipDetector& roverSlips, const BaseSnapshot& base,
            const Eigen::Vector3d& basePosition, const Eigen::Vector3d& x, DdEpoch& out,
            TransmitStates* states = nullptr);
  /// Chooses the references and forms the DD lists of `e` again (e.g. after SDs were removed as
  /// outliers: remove them by clearing hasPhase/hasCode).
  void formDoubleDifferences(DdEpoch& e);
  /// Forgets references and arc continuity.
  void reset();

  const DdFormationStats& stats() const { return stats_; }

 private:
  static int groupKey(System s, char band) { return systemIndex(s) * 16 + (band - '0'); }
  static std::uint32_t signalKey(SatId s, ObsCode c) {
    return static_cast<std::uint32_t>(satIndex(s)) << 16 | static_cast<std::uint32_t>(c.band) << 8 |
           static_cast<std::uint32_t>(static_cast<unsigned char>(c.attr));
  }

  struct Pick {
    const SignalObs* rover = nullptr;
    const BaseSignal* base = nullptr;
  };
  /// The rover and base signals of a band to difference (see the file comment), or nullopt
  /// (counted in the statistics).
  std::optional<Pick> pickPair(const SatObs& so, char band, const BaseSignal* baseBegin, const BaseSignal* baseEnd);
  /// The base signals of a satellite (`base.signals` is sorted by satellite).
  static std::pair<const BaseSignal*, const BaseSignal*> baseSignalsOf(const BaseSnapshot& base, SatId sat);
  /// Cycles to add to a phase of a receiver with alignment `a` to refer it to the band's reference.
  static double alignedShift(const PhaseAlignments& a, System sys, ObsCode code);

  const EphemerisStore& nav_;
  RtkConfig config_;
  GlonassChannels channels_;
  PhaseAlignments roverAlignment_, baseAlignment_;
  DdFormationStats stats_;
  std::unordered_map<int, SatId> phaseRef_;  // by groupKey
  struct Arcs {
    GpsTime rover, base, epoch;
    ObsCode baseCode;
  };
  std::unordered_map<std::uint32_t, Arcs> arcs_;  // by signalKey
  GpsTime lastEpoch_;
  bool haveLast_ = false;
};

}  // namespace gvins
