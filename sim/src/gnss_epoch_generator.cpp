#include "gvins/sim/gnss_epoch_generator.hpp"

namespace gvins::sim {

GnssAntennaMotion trajectoryAntennaMotion(const Trajectory& trajectory, const LocalFrame& frame,
                                          const Eigen::Vector3d& leverArmBody) {
  const Eigen::Matrix3d rEW = frame.rotationEcefFromW();
  const Eigen::Vector3d origin = frame.originEcef();
  const GpsTime start = frame.startTime;
  return [&trajectory, rEW, origin, start, leverArmBody](const GpsTime& t) {
    const TrajectoryState s = trajectory.evaluate(t - start);
    GnssAntennaState a;
    a.position = origin + rEW * s.pointPosition(leverArmBody);
    a.velocity = rEW * s.pointVelocity(leverArmBody);
    a.axes = rEW * s.R_WB;  // antenna along the body axes, z up
    return a;
  };
}

GnssEpochGenerator::GnssEpochGenerator(const GnssSimConfig& config, const NavData& nav, const LocalFrame& frame,
                                       double duration, GnssAntennaMotion roverMotion, std::uint64_t seed)
    : world_(std::make_unique<GnssSimWorld>(config, nav, frame.origin, frame.startTime, duration, seed)) {
  rover_ = std::make_unique<GnssReceiverSim>(*world_, GnssReceiverRole::Rover, std::move(roverMotion));
  if (config.base.enabled) {
    const Eigen::Vector3d p = world_->basePosition();
    base_ = std::make_unique<GnssReceiverSim>(*world_, GnssReceiverRole::Base, [p](const GpsTime&) {
      GnssAntennaState a;
      a.position = p;
      return a;
    });
  }
}

GnssEpochGenerator::GnssEpochGenerator(const GnssSimConfig& config, const NavData& nav, const Trajectory& trajectory,
                                       const LocalFrame& frame, const Eigen::Vector3d& leverArmBody, std::uint64_t seed)
    : GnssEpochGenerator(config, nav, frame, trajectory.duration(),
                         trajectoryAntennaMotion(trajectory, frame, leverArmBody), seed) {}

std::optional<GnssSimEpoch> GnssEpochGenerator::next() {
  for (;;) {
    const auto r = rover_->peekTag();
    const auto b = base_ ? base_->peekTag() : std::nullopt;
    if (!r && !b) return std::nullopt;
    GnssReceiverSim& rx = (r && (!b || !(*b < *r))) ? *rover_ : *base_;
    if (auto e = rx.next()) return e;
    // That receiver skipped to its end; try the other.
  }
}

void GnssEpochGenerator::finish() {
  rover_->finish();
  if (base_) base_->finish();
}

}  // namespace gvins::sim
