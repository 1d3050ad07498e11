// The joints of articulated models through ROS: ~<model>/joint_states out,
// ~<model>/joint_command in (sensor_msgs/JointState both ways).
#include <algorithm>
#include <cassert>
#include <cmath>
#include <iterator>
#include <string>
#include <vector>

#include "rigid_body_sim/node/names.h"
#include "rigid_body_sim/node/request_validation.h"
#include "rigid_body_sim/node/sim_node.h"

namespace rigid_body_sim::node {

using physics::JointCommand;
using physics::JointCommandMode;
using physics::Status;

void SimNode::AdvertiseJointTopicsLocked(const Model& model) {
  JointTopics topics;
  topics.handle = ros::NodeHandle(private_node_, model.name);
  topics.states = topics.handle.advertise<sensor_msgs::JointState>(names::kJointStatesTopic, 10);
  const std::string name = model.name;
  topics.command = topics.handle.subscribe<sensor_msgs::JointState>(
      names::kJointCommandTopic, 10,
      [this, name](const sensor_msgs::JointState::ConstPtr& message) {
        OnJointCommand(name, *message);
      });
  topics.trajectory = topics.handle.subscribe<trajectory_msgs::JointTrajectory>(
      names::kJointTrajectoryTopic, 10,
      [this, name](const trajectory_msgs::JointTrajectory::ConstPtr& message) {
        OnJointTrajectory(name, *message);
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

namespace {

// The index of a movable joint of the model that mimics none, by name.
physics::Result<int> CommandableJoint(const Model& model, const std::string& name) {
  int joint = -1;
  for (std::size_t k = 0; k < model.joint_names.size(); ++k) {
    if (model.joint_names[k] == name) joint = static_cast<int>(k);
  }
  if (joint < 0) {
    return physics::Result<int>::Error("model '" + model.name + "' has no movable joint '" + name +
                                       "'");
  }
  for (const io::JointInfo& info : model.joints) {
    if (info.name == name && !info.mimic_joint.empty()) {
      return physics::Result<int>::Error("joint '" + name + "' mimics '" + info.mimic_joint +
                                         "'; command that joint instead");
    }
  }
  return joint;
}

// The validation's view of joint `name` of `model`, values to be filled in.
JointValues ValuesOf(const Model& model, const std::string& name) {
  JointValues values;
  values.field = "joint '" + name + "'";
  for (const io::JointInfo& info : model.joints) {
    if (info.name == name) values.prismatic = info.type == "prismatic";
  }
  return values;
}

// The commands of one message, checked whole before any is applied: every
// name a movable joint of the model that mimics none, given once, each of
// position, velocity and effort empty or one value per name within the
// request limits (request_validation.h). The filled field
// picks the mode: position (a servo, velocity its feed-forward), else
// velocity (a motor), else effort.
physics::Result<std::vector<std::pair<int, JointCommand>>> ParseCommand(
    const Model& model, const sensor_msgs::JointState& message, const RequestLimits& limits) {
  using Parsed = physics::Result<std::vector<std::pair<int, JointCommand>>>;
  const std::size_t count = message.name.size();
  const auto sized = [count](std::size_t size) { return size == 0 || size == count; };
  if (count == 0) return Parsed::Error("name is empty");
  if (!sized(message.position.size()) || !sized(message.velocity.size()) ||
      !sized(message.effort.size())) {
    return Parsed::Error(
        "position, velocity and effort must each be empty or have " + std::to_string(count) +
        " values (one per name); got " + std::to_string(message.position.size()) + ", " +
        std::to_string(message.velocity.size()) + " and " + std::to_string(message.effort.size()));
  }
  if (message.position.empty() && message.velocity.empty() && message.effort.empty()) {
    return Parsed::Error("none of position, velocity and effort is filled");
  }
  std::vector<std::pair<int, JointCommand>> commands;
  for (std::size_t i = 0; i < count; ++i) {
    const std::string& name = message.name[i];
    const physics::Result<int> joint = CommandableJoint(model, name);
    if (!joint.ok()) return joint.status();
    for (const auto& [earlier, unused] : commands) {
      if (earlier == *joint) return Parsed::Error("joint '" + name + "' is named twice");
    }
    JointCommand command;
    const auto value = [i](const std::vector<double>& values) {
      return values.empty() ? 0.0 : values[i];
    };
    command.position = value(message.position);
    command.velocity = value(message.velocity);
    command.effort = value(message.effort);
    JointValues values = ValuesOf(model, name);
    values.position = command.position;
    values.velocity = command.velocity;
    values.effort = command.effort;
    if (Status status = ValidateJointValues(values, limits); !status.ok()) return status;
    command.mode = !message.position.empty()   ? JointCommandMode::kPosition
                   : !message.velocity.empty() ? JointCommandMode::kVelocity
                                               : JointCommandMode::kEffort;
    commands.emplace_back(*joint, command);
  }
  return commands;
}

}  // namespace

void SimNode::OnJointCommand(const std::string& model_name,
                             const sensor_msgs::JointState& message) {
  std::unique_lock<std::mutex> lock = LockWorld();
  const Model* model = registry_.Find(model_name);
  if (model == nullptr || !model->articulation.IsValid()) return;
  auto commands = ParseCommand(*model, message, options_.limits);
  if (!commands.ok()) {
    ROS_ERROR("%s/%s refused, nothing applied: %s", model_name.c_str(), names::kJointCommandTopic,
              commands.message().c_str());
    return;
  }
  // A command takes over from a trajectory in progress.
  trajectories_.erase(model_name);
  for (const auto& [joint, command] : *commands) {
    const Status status = world_.SetJointCommand(model->articulation, joint, command);
    if (!status.ok()) ROS_ERROR("%s: %s", model_name.c_str(), status.message().c_str());
  }
}

// A trajectory starts at its header stamp (now when zero), from where the
// joints are, and replaces the one in progress.
void SimNode::OnJointTrajectory(const std::string& model_name,
                                const trajectory_msgs::JointTrajectory& message) {
  std::unique_lock<std::mutex> lock = LockWorld();
  const Model* model = registry_.Find(model_name);
  if (model == nullptr || !model->articulation.IsValid()) return;
  const auto refuse = [&model_name](const std::string& why) {
    ROS_ERROR("%s/%s refused, nothing applied: %s", model_name.c_str(),
              names::kJointTrajectoryTopic, why.c_str());
  };
  ActiveTrajectory active;
  const std::vector<physics::JointState> states = world_.GetJointStates(model->articulation);
  TrajectoryPoint start;
  for (const std::string& name : message.joint_names) {
    const physics::Result<int> joint = CommandableJoint(*model, name);
    if (!joint.ok()) return refuse(joint.message());
    if (std::find(active.joints.begin(), active.joints.end(), *joint) != active.joints.end()) {
      return refuse("joint '" + name + "' is named twice");
    }
    active.joints.push_back(*joint);
    start.positions.push_back(states[*joint].position);
    start.velocities.push_back(states[*joint].velocity);
  }
  if (active.joints.empty()) return refuse("joint_names is empty");
  std::vector<TrajectoryPoint> points;
  for (std::size_t p = 0; p < message.points.size(); ++p) {
    const trajectory_msgs::JointTrajectoryPoint& point = message.points[p];
    for (std::size_t k = 0; k < message.joint_names.size(); ++k) {
      JointValues values = ValuesOf(*model, message.joint_names[k]);
      values.field = "point " + std::to_string(p) + " " + values.field;
      values.position = k < point.positions.size() ? point.positions[k] : 0.0;
      values.velocity = k < point.velocities.size() ? point.velocities[k] : 0.0;
      if (Status status = ValidateJointValues(values, options_.limits); !status.ok()) {
        return refuse(status.message());
      }
    }
    points.push_back(
        TrajectoryPoint{point.time_from_start.toSec(), point.positions, point.velocities});
  }
  physics::Result<JointTrajectory> plan = JointTrajectory::Make(start, std::move(points));
  if (!plan.ok()) return refuse(plan.message());
  active.plan = std::move(plan).value();
  active.start_time = world_.time();
  if (!message.header.stamp.isZero()) {
    active.start_time += (message.header.stamp - StampLocked()).toSec();
  }
  trajectories_[model_name] = std::move(active);
}

void SimNode::FollowTrajectoriesLocked() {
  const double end_of_step = world_.time() + world_.settings().time_step;
  for (auto it = trajectories_.begin(); it != trajectories_.end();) {
    const Model* model = registry_.Find(it->first);
    const ActiveTrajectory& active = it->second;
    const double t = end_of_step - active.start_time;
    if (model == nullptr || t < 0.0) {
      ++it;
      continue;
    }
    const TrajectorySample sample = active.plan.Sample(t);
    for (std::size_t k = 0; k < active.joints.size(); ++k) {
      JointCommand command;
      command.mode = JointCommandMode::kPosition;
      command.position = sample.positions[k];
      command.velocity = sample.velocities[k];
      const Status status = world_.SetJointCommand(model->articulation, active.joints[k], command);
      assert(status.ok());
    }
    // Past its end the last servo commands hold the final point.
    it = t > active.plan.duration() ? trajectories_.erase(it) : std::next(it);
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
  std::unique_lock<std::mutex> lock = LockWorld();
  const Model* model = registry_.Find(request.model);
  if (model == nullptr) return fail("no model named '" + request.model + "'");
  if (!model->articulation.IsValid()) {
    return fail("model '" + request.model + "' has no movable joints");
  }
  std::vector<double> positions;
  std::vector<double> velocities;
  for (const physics::JointState& state : world_.GetJointStates(model->articulation)) {
    positions.push_back(state.position);
    velocities.push_back(state.velocity);
  }
  for (std::size_t i = 0; i < count; ++i) {
    const std::string& name = request.joint_names[i];
    const auto found = std::find(model->joint_names.begin(), model->joint_names.end(), name);
    if (found == model->joint_names.end()) {
      return fail("model '" + request.model + "' has no movable joint '" + name + "'");
    }
    for (const io::JointInfo& info : model->joints) {
      if (info.name == name && !info.mimic_joint.empty()) {
        return fail("joint '" + name + "' mimics '" + info.mimic_joint + "'; set that joint");
      }
    }
    if (std::find(request.joint_names.begin(), request.joint_names.begin() + i, name) !=
        request.joint_names.begin() + i) {
      return fail("joint_names[" + std::to_string(i) + "] '" + name + "' is given twice");
    }
    JointValues values = ValuesOf(*model, name);
    values.position = request.positions[i];
    values.velocity = request.velocities.empty() ? 0.0 : request.velocities[i];
    if (Status status = ValidateJointValues(values, options_.limits); !status.ok()) {
      return fail(status.message());
    }
    const std::size_t joint = static_cast<std::size_t>(found - model->joint_names.begin());
    positions[joint] = values.position;
    velocities[joint] = values.velocity;
  }
  const Status status = world_.SetJointStates(model->articulation, positions, velocities);
  if (!status.ok()) return fail(status.message());
  response.success = true;
  response.message = "set " + std::to_string(count) + " joints of '" + request.model + "'";
  return true;
}

Status SimNode::ResetJointsLocked(const Model& model) {
  if (!model.articulation.IsValid()) return Status::Ok();
  for (std::size_t j = 0; j < model.joint_names.size(); ++j) {
    const Status status =
        world_.SetJointCommand(model.articulation, static_cast<int>(j), JointCommand());
    if (!status.ok()) return status;
  }
  return world_.SetJointStates(model.articulation, model.spawn_joint_positions,
                               std::vector<double>(model.spawn_joint_positions.size(), 0.0));
}

}  // namespace rigid_body_sim::node
