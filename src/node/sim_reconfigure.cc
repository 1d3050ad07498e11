// Live parameters: the dynamic_reconfigure server of cfg/Physics.cfg, and
// how validated settings reach the world and the step loop.
#include <string>
#include <vector>

#include "rigid_body_sim/node/msg_conversion.h"
#include "rigid_body_sim/node/sim_node.h"

namespace rigid_body_sim::node {

using physics::Status;

Status SimNode::ApplyLiveSettingsLocked(const LiveSettings& settings) {
  if (Status status = world_.SetSettings(WithLiveSettings(world_.settings(), settings));
      !status.ok()) {
    return status;
  }
  live_ = settings;
  ReanchorLocked();
  next_publish_ = Clock::now();
  return Status::Ok();
}

void SimNode::StartReconfigure() {
  reconfigure_ = std::make_unique<dynamic_reconfigure::Server<rigid_body_sim::PhysicsConfig>>(
      reconfigure_mutex_, private_node_);
  // The server starts from the .cfg defaults where a parameter is unset
  // (gravity_x, solver_velocity_iterations, ...); it is told what runs
  // before its callback can apply anything.
  PushReconfigureConfig();
  reconfigure_->setCallback([this](rigid_body_sim::PhysicsConfig& config, std::uint32_t level) {
    Guarded("dynamic_reconfigure", [&] { OnReconfigure(config, level); });
  });
}

void SimNode::OnReconfigure(rigid_body_sim::PhysicsConfig& config, std::uint32_t /*level*/) {
  const LiveSettings requested = LiveSettingsFromConfig(config);
  Status status = ValidateLiveSettings(requested, "");
  {
    std::unique_lock<std::mutex> lock = LockWorld();
    if (status.ok()) status = ApplyLiveSettingsLocked(requested);
    // A refused change is put back, so that the server and rqt_reconfigure
    // show what runs.
    if (!status.ok()) LiveSettingsToConfig(live_, &config);
  }
  wake_.notify_all();
  if (!status.ok()) {
    ROS_WARN("dynamic_reconfigure refused, nothing changed: %s", status.message().c_str());
    return;
  }
  for (const std::string& warning : LiveSettingsWarnings(requested, "")) {
    ROS_WARN("dynamic_reconfigure: %s", warning.c_str());
  }
}

void SimNode::PushReconfigureConfig() {
  rigid_body_sim::PhysicsConfig config = rigid_body_sim::PhysicsConfig::__getDefault__();
  {
    std::unique_lock<std::mutex> lock = LockWorld();
    LiveSettingsToConfig(live_, &config);
  }
  reconfigure_->updateConfig(config);
}

}  // namespace rigid_body_sim::node
