// The joints of articulated models through ROS: ~<model>/joint_states out,
// ~<model>/joint_command in (sensor_msgs/JointState both ways).
#include <algorithm>
#include <cassert>
#include <cmath>
#include <iterator>
#include <optional>
#include <string>
#include <vector>

#include "rigid_body_sim/node/joint_requests.h"
#include "rigid_body_sim/node/msg_conversion.h"
#include "rigid_body_sim/node/names.h"
#include "rigid_body_sim/node/request_validation.h"
#include "rigid_body_sim/node/sim_node.h"

namespace rigid_body_sim::node {

using physics::FormatNumber;
using physics::JointCommand;
using physics::Result;
using physics::Status;

void SimNode::AdvertiseJointTopicsLocked(const Model& model) {
  JointTopics topics;
  // ~<model>/ by default; a robot namespace as Gazebo's robotNamespace,
  // "/" for the global joint_states that robot_state_publisher reads.
  topics.handle = model.robot_namespace.empty() ? ros::NodeHandle(private_node_, model.name)
                                                : ros::NodeHandle(model.robot_namespace);
  topics.states = topics.handle.advertise<sensor_msgs::JointState>(names::kJointStatesTopic, 10);
  // The callbacks hold what they parse against, so they never read the
  // registry without the world lock.
  const std::shared_ptr<const ModelJoints> joints = ModelJointsOf(model);
  const physics::ArticulationId articulation = model.articulation;
  topics.command = topics.handle.subscribe<sensor_msgs::JointState>(
      names::kJointCommandTopic, 10,
      [this, joints, articulation](const sensor_msgs::JointState::ConstPtr& message) {
        Guarded(names::kJointCommandTopic, [&] { OnJointCommand(joints, articulation, *message); });
      });
  topics.trajectory = topics.handle.subscribe<trajectory_msgs::JointTrajectory>(
      names::kJointTrajectoryTopic, 10,
      [this, joints, articulation](const trajectory_msgs::JointTrajectory::ConstPtr& message) {
        Guarded(names::kJointTrajectoryTopic,
                [&] { OnJointTrajectory(joints, articulation, *message); });
      });
  std::lock_guard<std::mutex> lock(joint_topics_mutex_);
  joint_topics_[model.name] = std::move(topics);
}

void SimNode::RemoveJointTopics(const std::string& model_name) {
  trajectories_.erase(model_name);
  std::lock_guard<std::mutex> lock(joint_topics_mutex_);
  const auto topics = joint_topics_.find(model_name);
  if (topics == joint_topics_.end()) return;
  retired_joint_topics_.push_back(std::move(topics->second));
  joint_topics_.erase(topics);
}

void SimNode::DestroyRetiredJointTopics() {
  std::vector<JointTopics> retired;
  {
    std::lock_guard<std::mutex> lock(joint_topics_mutex_);
    retired.swap(retired_joint_topics_);
  }
  // Destroyed here, with no lock held.
}

void SimNode::OnJointCommand(const std::shared_ptr<const ModelJoints>& joints,
                             physics::ArticulationId articulation,
                             const sensor_msgs::JointState& message) {
  const std::string& model_name = joints->model;
  // Parsed and checked whole before the world is locked.
  const auto commands = ParseJointCommand(*joints, JointCommandFromMsg(message), options_.limits);
  if (!commands.ok()) {
    ROS_ERROR("%s/%s refused, nothing applied: %s", model_name.c_str(), names::kJointCommandTopic,
              commands.message().c_str());
    return;
  }
  std::vector<int> named;
  for (const auto& [joint, command] : *commands) named.push_back(joint);
  std::vector<ActiveTrajectory> released;  // freed after the lock is released
  std::unique_lock<std::mutex> lock = LockWorld();
  if (!IsSameModelLocked(model_name, articulation)) return;
  const Model* model = registry_.Find(model_name);
  // The command takes its joints over from any trajectory in progress; the
  // trajectory keeps driving the others.
  ReleaseJointsLocked(model_name, named, &released);
  for (const auto& [joint, command] : *commands) {
    const Status status = world_.SetJointCommand(model->articulation, joint, command);
    if (!status.ok()) ROS_ERROR("%s: %s", model_name.c_str(), status.message().c_str());
  }
}

bool SimNode::IsSameModelLocked(const std::string& model_name,
                                physics::ArticulationId articulation) const {
  // A message queued for a deleted model, or for an earlier model of the
  // same name, is dropped.
  const Model* model = registry_.Find(model_name);
  return model != nullptr && model->articulation.index == articulation.index &&
         model->articulation.generation == articulation.generation;
}

// A trajectory starts at its header stamp (now when zero), from where the
// joints are, and replaces the one in progress. Its points are checked
// before the world is locked; under the lock only the start is put in.
void SimNode::OnJointTrajectory(const std::shared_ptr<const ModelJoints>& joints,
                                physics::ArticulationId articulation,
                                const trajectory_msgs::JointTrajectory& message) {
  const std::string& model_name = joints->model;
  const auto refuse = [&model_name](const std::string& why) {
    ROS_ERROR("%s/%s refused, nothing applied: %s", model_name.c_str(),
              names::kJointTrajectoryTopic, why.c_str());
  };
  if (Status status = ValidateTrajectorySize(message.points.size(), options_.limits);
      !status.ok()) {
    return refuse(status.message());
  }
  Result<ParsedTrajectory> parsed =
      ParseJointTrajectory(*joints, JointTrajectoryFromMsg(message), options_.limits);
  if (!parsed.ok()) return refuse(parsed.message());
  ActiveTrajectory active{
      std::move(parsed.value().joints), {}, std::move(parsed.value().plan), 0.0};
  std::vector<ActiveTrajectory> released;  // freed after the lock is released
  std::unique_lock<std::mutex> lock = LockWorld();
  if (!IsSameModelLocked(model_name, articulation)) return;
  const Model* model = registry_.Find(model_name);
  active.start_time = world_.time();
  if (!message.header.stamp.isZero()) {
    // In seconds as doubles: ros::Time arithmetic throws beyond its range.
    const double offset = message.header.stamp.toSec() - StampLocked().toSec();
    if (!(std::abs(offset) <= kMaxTrajectoryStampOffset)) {
      return refuse("header.stamp " + FormatNumber(message.header.stamp.toSec()) + " s is " +
                    FormatNumber(offset) + " s from the node's clock (" +
                    FormatNumber(StampLocked().toSec()) + " s); allowed within " +
                    FormatNumber(kMaxTrajectoryStampOffset) + " s of it, or 0 for now");
    }
    active.start_time += offset;
  }
  const std::vector<physics::JointState> states = world_.GetJointStates(model->articulation);
  TrajectoryPoint start;
  for (const int joint : active.joints) {
    start.positions.push_back(states[joint].position);
    start.velocities.push_back(states[joint].velocity);
  }
  if (Status status = active.plan.Begin(start); !status.ok()) return refuse(status.message());
  // It takes its joints over from the trajectories in progress, which keep
  // the others (an arm's trajectory and a gripper's, as two controllers).
  ReleaseJointsLocked(model_name, active.joints, &released);
  active.owned.assign(active.joints.size(), true);
  trajectories_[model_name].push_back(std::move(active));
}

void SimNode::ReleaseJointsLocked(const std::string& model_name, const std::vector<int>& joints,
                                  std::vector<ActiveTrajectory>* released) {
  const auto found = trajectories_.find(model_name);
  if (found == trajectories_.end()) return;
  std::vector<ActiveTrajectory>& running = found->second;
  for (ActiveTrajectory& active : running) {
    for (std::size_t k = 0; k < active.joints.size(); ++k) {
      if (std::find(joints.begin(), joints.end(), active.joints[k]) != joints.end()) {
        active.owned[k] = false;
      }
    }
  }
  const auto owns_none = [](const ActiveTrajectory& active) {
    return std::none_of(active.owned.begin(), active.owned.end(), [](bool owned) { return owned; });
  };
  const auto first_done = std::stable_partition(
      running.begin(), running.end(), [&](const ActiveTrajectory& a) { return !owns_none(a); });
  std::move(first_done, running.end(), std::back_inserter(*released));
  running.erase(first_done, running.end());
  if (running.empty()) trajectories_.erase(found);
}

void SimNode::FollowTrajectoriesLocked() {
  const double end_of_step = world_.time() + world_.settings().time_step;
  for (auto it = trajectories_.begin(); it != trajectories_.end();) {
    const Model* model = registry_.Find(it->first);
    std::vector<ActiveTrajectory>& running = it->second;
    for (auto active = running.begin(); model != nullptr && active != running.end();) {
      const double t = end_of_step - active->start_time;
      if (t < 0.0) {
        ++active;
        continue;
      }
      const TrajectorySample sample = active->plan.Sample(t);
      for (std::size_t k = 0; k < active->joints.size(); ++k) {
        if (!active->owned[k]) continue;
        JointCommand command;
        command.mode = physics::JointCommandMode::kPosition;
        command.position = sample.positions[k];
        command.velocity = sample.velocities[k];
        const Status status =
            world_.SetJointCommand(model->articulation, active->joints[k], command);
        assert(status.ok());
      }
      // Past its end the last servo commands hold the final point.
      active = t > active->plan.duration() ? running.erase(active) : std::next(active);
    }
    it = running.empty() ? trajectories_.erase(it) : std::next(it);
  }
}

void SimNode::FillJointStatesLocked(const ros::Time& stamp, Outbox* outbox) const {
  for (const auto& [name, model] : registry_.models()) {
    if (!model.articulation.IsValid()) continue;
    sensor_msgs::JointState message;
    message.header.stamp = stamp;
    message.name = model.joint_names;
    for (const physics::JointState& state : world_.GetJointStates(model.articulation)) {
      message.position.push_back(state.position);
      message.velocity.push_back(state.velocity);
      message.effort.push_back(state.effort);
    }
    outbox->joint_states.emplace_back(name, std::move(message));
  }
}

void SimNode::PublishJointStates(const Outbox& outbox) {
  std::lock_guard<std::mutex> lock(joint_topics_mutex_);
  for (const auto& [name, message] : outbox.joint_states) {
    const auto topics = joint_topics_.find(name);
    if (topics != joint_topics_.end()) topics->second.states.publish(message);
  }
}

// Gazebo's set_model_configuration: the named joints' positions and
// velocities, the others kept; checked whole before anything changes.
bool SimNode::OnSetJointState(rigid_body_sim::SetJointState::Request& request,
                              rigid_body_sim::SetJointState::Response& response) {
  const auto fail = [&response](const std::string& message) {
    response.success = false;
    response.message = message;
    ROS_WARN("~%s refused: %s", names::kSetJointStateService, message.c_str());
    return true;
  };
  const std::size_t count = request.joint_names.size();
  if (request.positions.size() != count ||
      (!request.velocities.empty() && request.velocities.size() != count)) {
    return fail("positions must have one value per joint name (" + std::to_string(count) +
                "), velocities none or one per name; got " +
                std::to_string(request.positions.size()) + " and " +
                std::to_string(request.velocities.size()));
  }
  if (!request.name.empty() && !request.model.empty() && request.name != request.model) {
    return fail("name '" + request.name + "' and model '" + request.model +
                "' differ; give the model's name in name");
  }
  const std::string& model_name = request.name.empty() ? request.model : request.name;
  std::unique_lock<std::mutex> lock = LockWorld();
  const Model* model = registry_.Find(model_name);
  if (model == nullptr) return fail("no model named '" + model_name + "'");
  if (!model->articulation.IsValid()) {
    return fail("model '" + model_name + "' has no movable joints");
  }
  std::vector<double> positions;
  std::vector<double> velocities;
  for (const physics::JointState& state : world_.GetJointStates(model->articulation)) {
    positions.push_back(state.position);
    velocities.push_back(state.velocity);
  }
  const std::shared_ptr<const ModelJoints> joints = ModelJointsOf(*model);
  for (std::size_t i = 0; i < count; ++i) {
    const std::string& name = request.joint_names[i];
    const auto found = joints->index.find(name);
    if (found == joints->index.end()) {
      return fail("model '" + model_name + "' has no movable joint '" + name + "'");
    }
    const std::size_t joint = static_cast<std::size_t>(found->second);
    if (!joints->leaders[joint].empty()) {
      return fail("joint '" + name + "' mimics '" + joints->leaders[joint] + "'; set that joint");
    }
    if (std::find(request.joint_names.begin(), request.joint_names.begin() + i, name) !=
        request.joint_names.begin() + i) {
      return fail("joint_names[" + std::to_string(i) + "] '" + name + "' is given twice");
    }
    JointValues values;
    values.field = "joint '" + name + "'";
    values.prismatic = joints->prismatic[joint];
    values.position = request.positions[i];
    values.velocity = request.velocities.empty() ? 0.0 : request.velocities[i];
    if (Status status = ValidateJointValues(values, options_.limits); !status.ok()) {
      return fail(status.message());
    }
    positions[joint] = values.position;
    velocities[joint] = values.velocity;
  }
  const Status status = world_.SetJointStates(model->articulation, positions, velocities);
  if (!status.ok()) return fail(status.message());
  response.success = true;
  response.message = "set " + std::to_string(count) + " joints of '" + model_name + "'";
  return true;
}

Status SimNode::ResetJointsLocked(const Model& model) {
  if (!model.articulation.IsValid()) return Status::Ok();
  for (std::size_t j = 0; j < model.joint_names.size(); ++j) {
    const Status status =
        world_.SetJointCommand(model.articulation, static_cast<int>(j), JointCommand());
    if (!status.ok()) return status;
  }
  if (model.hold) HoldJointsLocked(model);
  return world_.SetJointStates(model.articulation, model.spawn_joint_positions,
                               std::vector<double>(model.spawn_joint_positions.size(), 0.0));
}

void SimNode::HoldJointsLocked(const Model& model) {
  const std::shared_ptr<const ModelJoints> joints = ModelJointsOf(model);
  for (std::size_t j = 0; j < model.joint_names.size(); ++j) {
    if (!joints->leaders[j].empty()) continue;  // a mimic follows its leader
    JointCommand hold;
    hold.mode = physics::JointCommandMode::kPosition;
    hold.position = model.spawn_joint_positions[j];
    const Status status = world_.SetJointCommand(model.articulation, static_cast<int>(j), hold);
    assert(status.ok());
  }
}

}  // namespace rigid_body_sim::node
