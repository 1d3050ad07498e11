#include "rigid_body_sim/node/joint_requests.h"

#include <string>
#include <utility>

namespace rigid_body_sim::node {

using physics::JointCommand;
using physics::JointCommandMode;
using physics::Result;
using physics::Status;

std::shared_ptr<const ModelJoints> ModelJointsOf(const Model& model) {
  auto joints = std::make_shared<ModelJoints>();
  joints->model = model.name;
  joints->names = model.joint_names;
  joints->prismatic.assign(model.joint_names.size(), false);
  joints->leaders.assign(model.joint_names.size(), "");
  for (std::size_t k = 0; k < model.joint_names.size(); ++k) {
    joints->index.emplace(model.joint_names[k], static_cast<int>(k));
  }
  for (const io::JointInfo& info : model.joints) {
    const auto found = joints->index.find(info.name);
    if (found == joints->index.end()) continue;
    joints->prismatic[found->second] = info.type == "prismatic";
    joints->leaders[found->second] = info.mimic_joint;
  }
  return joints;
}

namespace {

// The index of a movable joint of the model that mimics none, by name.
Result<int> CommandableJoint(const ModelJoints& joints, const std::string& name) {
  const auto found = joints.index.find(name);
  if (found == joints.index.end()) {
    return Result<int>::Error("model '" + joints.model + "' has no movable joint '" + name + "'");
  }
  const std::string& leader = joints.leaders[found->second];
  if (!leader.empty()) {
    return Result<int>::Error("joint '" + name + "' mimics '" + leader +
                              "'; command that joint instead");
  }
  return found->second;
}

// The validation's view of joint `joint`, values to be filled in.
JointValues ValuesOf(const ModelJoints& joints, int joint) {
  JointValues values;
  values.field = "joint '" + joints.names[joint] + "'";
  values.prismatic = joints.prismatic[joint];
  return values;
}

// The joints of `names`, each commandable and named once.
Result<std::vector<int>> NamedJoints(const ModelJoints& joints,
                                     const std::vector<std::string>& names) {
  std::vector<int> indices;
  std::vector<bool> named(joints.names.size(), false);
  for (const std::string& name : names) {
    const Result<int> joint = CommandableJoint(joints, name);
    if (!joint.ok()) return joint.status();
    if (named[*joint])
      return Result<std::vector<int>>::Error("joint '" + name + "' is named twice");
    named[*joint] = true;
    indices.push_back(*joint);
  }
  return indices;
}

}  // namespace

Result<ParsedCommand> ParseJointCommand(const ModelJoints& joints,
                                        const JointCommandRequest& request,
                                        const RequestLimits& limits) {
  using Parsed = Result<ParsedCommand>;
  const std::size_t count = request.names.size();
  const auto sized = [count](std::size_t size) { return size == 0 || size == count; };
  if (count == 0) return Parsed::Error("name is empty");
  if (!sized(request.position.size()) || !sized(request.velocity.size()) ||
      !sized(request.effort.size())) {
    return Parsed::Error(
        "position, velocity and effort must each be empty or have " + std::to_string(count) +
        " values (one per name); got " + std::to_string(request.position.size()) + ", " +
        std::to_string(request.velocity.size()) + " and " + std::to_string(request.effort.size()));
  }
  if (request.position.empty() && request.velocity.empty() && request.effort.empty()) {
    return Parsed::Error("none of position, velocity and effort is filled");
  }
  const Result<std::vector<int>> named = NamedJoints(joints, request.names);
  if (!named.ok()) return named.status();
  const JointCommandMode mode = !request.position.empty()   ? JointCommandMode::kPosition
                                : !request.velocity.empty() ? JointCommandMode::kVelocity
                                                            : JointCommandMode::kEffort;
  ParsedCommand commands;
  for (std::size_t i = 0; i < count; ++i) {
    const auto value = [i](const std::vector<double>& values) {
      return values.empty() ? 0.0 : values[i];
    };
    JointCommand command;
    command.mode = mode;
    command.position = value(request.position);
    command.velocity = value(request.velocity);
    command.effort = value(request.effort);
    JointValues values = ValuesOf(joints, (*named)[i]);
    values.position = command.position;
    values.velocity = command.velocity;
    values.effort = command.effort;
    if (Status status = ValidateJointValues(values, limits); !status.ok()) return status;
    commands.emplace_back((*named)[i], command);
  }
  return commands;
}

Status ValidateTrajectorySize(std::size_t points, const RequestLimits& limits) {
  if (points > static_cast<std::size_t>(limits.max_trajectory_points)) {
    return Status::Error("points has " + std::to_string(points) +
                         " points, more than ~max_trajectory_points " +
                         std::to_string(limits.max_trajectory_points));
  }
  return Status::Ok();
}

Result<ParsedTrajectory> ParseJointTrajectory(const ModelJoints& joints,
                                              JointTrajectoryRequest request,
                                              const RequestLimits& limits) {
  using Parsed = Result<ParsedTrajectory>;
  if (Status status = ValidateTrajectorySize(request.points.size(), limits); !status.ok()) {
    return status;
  }
  if (request.joint_names.empty()) return Parsed::Error("joint_names is empty");
  Result<std::vector<int>> named = NamedJoints(joints, request.joint_names);
  if (!named.ok()) return named.status();
  std::vector<TrajectoryPoint> points;
  points.reserve(request.points.size());
  for (std::size_t p = 0; p < request.points.size(); ++p) {
    JointTrajectoryRequest::Point& point = request.points[p];
    for (std::size_t k = 0; k < named->size(); ++k) {
      JointValues values;
      values.prismatic = joints.prismatic[(*named)[k]];
      values.position = k < point.positions.size() ? point.positions[k] : 0.0;
      values.velocity = k < point.velocities.size() ? point.velocities[k] : 0.0;
      if (ValidateJointValues(values, limits).ok()) continue;
      // Named only when refused: a long trajectory is checked at about
      // 10 ns a value instead of a string's allocation each.
      values.field = "point " + std::to_string(p) + " " + ValuesOf(joints, (*named)[k]).field;
      return ValidateJointValues(values, limits);
    }
    points.push_back(TrajectoryPoint{point.time_from_start, std::move(point.positions),
                                     std::move(point.velocities)});
  }
  Result<JointTrajectory> plan = JointTrajectory::Plan(named->size(), std::move(points));
  if (!plan.ok()) return plan.status();
  return ParsedTrajectory{std::move(named).value(), std::move(plan).value()};
}

}  // namespace rigid_body_sim::node
