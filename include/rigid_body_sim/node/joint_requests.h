// The joint topics' messages (joint_command, joint_trajectory) as plain
// requests, checked whole against a model's joints before the world is
// locked: a message of any size is parsed and refused without making the
// step or any other call wait. ROS-free, so the fuzzer drives it.
#ifndef RIGID_BODY_SIM_NODE_JOINT_REQUESTS_H_
#define RIGID_BODY_SIM_NODE_JOINT_REQUESTS_H_

#include <cstddef>
#include <memory>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "rigid_body_sim/node/joint_trajectory.h"
#include "rigid_body_sim/node/model_registry.h"
#include "rigid_body_sim/node/request_validation.h"
#include "rigid_body_sim/physics/articulation.h"
#include "rigid_body_sim/physics/result.h"

namespace rigid_body_sim::node {

// What a joint message may name of one spawned model; made at spawn and
// never changed, so a callback reads it without the world lock.
struct ModelJoints {
  std::string model;
  std::vector<std::string> names;              // movable joints in tree order (joint_states' order)
  std::vector<bool> prismatic;                 // per name: m, m/s, N; else rad, rad/s, N m
  std::vector<std::string> leaders;            // per name: the joint it mimics, or empty
  std::unordered_map<std::string, int> index;  // name -> position in `names`
};
std::shared_ptr<const ModelJoints> ModelJointsOf(const Model& model);

// sensor_msgs/JointState as a command: names, and per name a position,
// velocity or effort (each list empty or one value per name).
struct JointCommandRequest {
  std::vector<std::string> names;
  std::vector<double> position;
  std::vector<double> velocity;
  std::vector<double> effort;
};

// trajectory_msgs/JointTrajectory without its header (the node turns the
// stamp into a start time itself).
struct JointTrajectoryRequest {
  struct Point {
    std::vector<double> positions;
    std::vector<double> velocities;
    double time_from_start = 0.0;  // s
  };
  std::vector<std::string> joint_names;
  std::vector<Point> points;
};

using ParsedCommand = std::vector<std::pair<int, physics::JointCommand>>;

// The commands of one message: every name a movable joint of the model
// that mimics none, given once; each value within the request limits
// (ValidateJointValues). The filled list picks the mode: position (a
// servo, velocity its feed-forward), else velocity (a motor), else effort.
physics::Result<ParsedCommand> ParseJointCommand(const ModelJoints& joints,
                                                 const JointCommandRequest& request,
                                                 const RequestLimits& limits);

struct ParsedTrajectory {
  std::vector<int> joints;  // indices into ModelJoints::names, per joint_names entry
  JointTrajectory plan;     // planned; Begin it with the joints' state
};

// At most limits.max_trajectory_points points; checked before a message is
// copied, and again by ParseJointTrajectory.
physics::Status ValidateTrajectorySize(std::size_t points, const RequestLimits& limits);

// A trajectory for the named joints (each commandable, once), every point's
// values within the request limits, times strictly increasing from >= 0.
physics::Result<ParsedTrajectory> ParseJointTrajectory(const ModelJoints& joints,
                                                       JointTrajectoryRequest request,
                                                       const RequestLimits& limits);

}  // namespace rigid_body_sim::node

#endif  // RIGID_BODY_SIM_NODE_JOINT_REQUESTS_H_
