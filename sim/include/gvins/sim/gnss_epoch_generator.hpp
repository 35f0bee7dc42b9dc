// In-memory GNSS epoch generator: the rover (moving along a trajectory, antenna at a lever arm
// from the IMU) and the base receiver of one simulated run, epoch by epoch in time-tag order,
// each with its observations and truth. GnssSimulator writes the same epochs to files; tests and
// the fusion can use them directly.
//
//   GnssEpochGenerator gen(config, nav, trajectory, frame, leverArm, seed);
//   while (auto e = gen.next()) { if (e->role == GnssReceiverRole::Rover) use(e->obs, e->truth); }
//   gen.finish();  // closes ambiguity arcs and event intervals
#pragma once

#include <cstdint>
#include <memory>
#include <optional>

#include <Eigen/Core>

#include "gvins/ephemeris/rinex_nav.hpp"
#include "gvins/sim/gnss_receiver_sim.hpp"
#include "gvins/sim/gnss_sim_world.hpp"
#include "gvins/sim/local_frame.hpp"
#include "gvins/sim/trajectory.hpp"

namespace gvins::sim {

/// Antenna of a trajectory: p = p_WB + R_WB l_B and v = v_WB + R_WB (omega_B x l_B) in W, then
/// ECEF through the local frame; t is GPST (flight time = t - frame.startTime). `trajectory`
/// must outlive the returned function.
GnssAntennaMotion trajectoryAntennaMotion(const Trajectory& trajectory, const LocalFrame& frame,
                                          const Eigen::Vector3d& leverArmBody);

class GnssEpochGenerator {
 public:
  /// General form: the rover antenna follows `roverMotion` over [frame.startTime, + duration].
  GnssEpochGenerator(const GnssSimConfig& config, const NavData& nav, const LocalFrame& frame, double duration,
                     GnssAntennaMotion roverMotion, std::uint64_t seed);
  /// From a trajectory and the IMU-to-antenna lever arm (body frame, m).
  GnssEpochGenerator(const GnssSimConfig& config, const NavData& nav, const Trajectory& trajectory,
                     const LocalFrame& frame, const Eigen::Vector3d& leverArmBody, std::uint64_t seed);

  /// Next rover or base epoch, in order of time tags (rover first on equal tags); std::nullopt
  /// when both receivers are done.
  std::optional<GnssSimEpoch> next();
  /// Closes ambiguity arcs and event intervals of both receivers.
  void finish();
  /// Blockage and NLOS of the rover's signals through 3-D structure (GnssReceiverSim::setPathModel).
  void setRoverPathModel(GnssPathModel model) { rover_->setPathModel(std::move(model)); }

  const GnssSimWorld& world() const { return *world_; }
  const GnssReceiverSim& rover() const { return *rover_; }
  /// nullptr when the base is disabled.
  const GnssReceiverSim* base() const { return base_.get(); }
  const Eigen::Vector3d& basePosition() const { return world_->basePosition(); }

 private:
  std::unique_ptr<GnssSimWorld> world_;
  std::unique_ptr<GnssReceiverSim> rover_;
  std::unique_ptr<GnssReceiverSim> base_;
};

}  // namespace gvins::sim
