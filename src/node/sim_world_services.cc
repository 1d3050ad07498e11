// The node's world services in the manner of gazebo_ros: what is in the
// world, what a model is made of, and the two resets.
#include <cassert>
#include <string>

#include "node/model_sensors.h"
#include "node/service_reply.h"
#include "rigid_body_sim/node/msg_conversion.h"
#include "rigid_body_sim/node/names.h"
#include "rigid_body_sim/node/sim_node.h"

namespace rigid_body_sim::node {

using physics::Status;

std::string SimNode::Reset(bool keep_time) {
  Outbox outbox;
  {
    std::unique_lock<std::mutex> lock = LockWorld();
    for (const auto& [name, model] : registry_.models()) {
      const FrameState& state = model.spawn_state;
      Status status = world_.SetState(model.body, state.world_from_frame, state.linear_velocity,
                                      state.angular_velocity);
      if (status.ok()) status = ResetJointsLocked(model);
      assert(status.ok());
    }
    wrenches_.clear();
    trajectories_.clear();
    pending_sensor_messages_.clear();
    frozen_models_.clear();
    if (keep_time) {
      // SetState already dropped every body's contacts and woke it; sim time,
      // /clock and tf stamps carry on.
      outbox.tf_static = StaticTfLocked();
    } else {
      world_.Restart();
      last_periodic_time_ = -1.0;
      ReanchorLocked();
      status_wall_ = Clock::now();
      status_sim_ = 0.0;
      outbox.tf_static = StaticTfLocked();
      FillPeriodicLocked(&outbox);
      {
        std::lock_guard<std::mutex> clock_lock(clock_mutex_);
        last_clock_ = 0.0;
      }
      ++reset_count_;
    }
    ResetSensorsLocked();
  }
  wake_.notify_all();
  Publish(std::move(outbox));
  const std::string message = keep_time
                                  ? "reset_world: every model at its spawn state, sim time kept"
                                  : "reset: every model at its spawn state, sim time 0";
  ROS_INFO("%s", message.c_str());
  return message;
}

bool SimNode::OnResetSimulation(std_srvs::Trigger::Request& /*request*/,
                                std_srvs::Trigger::Response& response) {
  response.message = Reset(/*keep_time=*/false);
  response.success = true;
  return true;
}

bool SimNode::OnResetWorld(std_srvs::Trigger::Request& /*request*/,
                           std_srvs::Trigger::Response& response) {
  response.message = Reset(/*keep_time=*/true);
  response.success = true;
  return true;
}

bool SimNode::OnGetWorldProperties(rigid_body_sim::GetWorldProperties::Request& /*request*/,
                                   rigid_body_sim::GetWorldProperties::Response& response) {
  std::unique_lock<std::mutex> lock = LockWorld();
  response.sim_time = world_.time();
  response.paused = paused_;
  response.model_names.reserve(registry_.size());
  for (const auto& [name, model] : registry_.models()) response.model_names.push_back(name);
  response.success = true;
  response.message = std::to_string(registry_.size()) + " models";
  return true;
}

bool SimNode::OnGetModelProperties(rigid_body_sim::GetModelProperties::Request& request,
                                   rigid_body_sim::GetModelProperties::Response& response) {
  std::unique_lock<std::mutex> lock = LockWorld();
  const Model* model = registry_.Find(request.name);
  if (model == nullptr) {
    return Fail(response, "no model named '" + request.name + "'",
                names::kGetModelPropertiesService);
  }
  ModelPropertiesToMsg(*model, &response);
  response.success = true;
  response.message = "model '" + request.name + "'";
  return true;
}

}  // namespace rigid_body_sim::node
