// GnssFusion before the estimator is initialised: the GNSS/INS start (gnss_ins_alignment.hpp,
// docs/gnss_fusion.md "Starting from GNSS/INS").
#include <cmath>

#include "gvins/base/constants.hpp"
#include "gvins/fusion/gnss_fusion.hpp"

namespace gvins::fusion {

template <typename Scalar>
void GnssFusion<Scalar>::startFromGnss(vio::EstimatorBackend<Scalar>& est, const ObsEpoch& rover, GnssEpochReport& rep) {
  const std::span<const vio::ImuSample> imu = est.bufferedImu();
  if (imu.empty()) return;  // the backend keeps its IMU to itself: no GNSS/INS start
  if (!insAlign_) {
    GnssInsAlignmentConfig c;
    c.window = config_.insStartWindow;
    c.maxYawSigmaDeg = config_.insStartYawSigmaDeg;
    insAlign_ = std::make_unique<GnssInsAlignment>(c, est.imuNoise(), est.gravity().norm());
  }
  const SppSolution spp = spp_->solve(rover);
  // Measurement time: the tag minus the receiver clock of the first system solved.
  double dtr = 0.0;
  for (const auto& b : spp.clockBias) {
    if (b) {
      dtr = *b / constants::kSpeedOfLight;
      break;
    }
  }
  if (!(std::abs(dtr) < 0.01)) dtr = 0.0;
  const GpsTime t = rover.time - dtr;
  const std::int64_t t_ns = t.wholeSeconds() * 1000000000LL + std::llround(t.fraction() * 1e9);
  if (t_ns < imu.front().t_ns) return;
  const std::optional<vio::ExternalInitialState> s = insAlign_->add(t_ns, spp, imu, lever_.start());
  rep.insStart = insAlign_->status();
  rep.t_ns = t_ns;
  if (!s || !est.initializeFrom(*s)) return;
  // The estimator now runs in ENU at the alignment's anchor: no frame block to estimate, the
  // tight rows (clocks first) start with the next epoch.
  generation_ = est.generation();
  anchor_ = insAlign_->anchor();
  worldChange_ = vio::WorldFrameChange{};
  stage_ = GnssFusionStage::kTight;
  lastUpdate_.reset();
  insAlign_->clear();
}

template void GnssFusion<float>::startFromGnss(vio::EstimatorBackend<float>&, const ObsEpoch&, GnssEpochReport&);
template void GnssFusion<double>::startFromGnss(vio::EstimatorBackend<double>&, const ObsEpoch&, GnssEpochReport&);

}  // namespace gvins::fusion
