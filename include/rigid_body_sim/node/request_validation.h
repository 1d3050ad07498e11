// The one validation layer for the node's requests: every number a service
// request carries is checked here against the ranges the README documents,
// after msg_conversion has turned it into core types. A refusal names the
// field, the value and the allowed range; the caller changes nothing.
// ROS-free, so the fuzzer can drive it without a master.
#ifndef RIGID_BODY_SIM_NODE_REQUEST_VALIDATION_H_
#define RIGID_BODY_SIM_NODE_REQUEST_VALIDATION_H_

#include <cstdint>
#include <string>

#include "rigid_body_sim/node/model_registry.h"
#include "rigid_body_sim/physics/result.h"
#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::node {

// The limits that are parameters (options.h, config/sim.yaml).
struct RequestLimits {
  double max_position = 1e6;            // ~max_position: m, |position| of a pose
  double max_linear_speed = 1e4;        // ~max_linear_speed: m/s
  double max_angular_speed = 1e4;       // ~max_angular_speed: rad/s
  double max_force = 1e9;               // ~max_force: N
  double max_torque = 1e9;              // ~max_torque: N m
  double max_wrench_duration = 3600.0;  // ~max_wrench_duration: s
  int max_step_count = 100000;          // ~max_step_count: steps per ~step call
  // ~max_trajectory_points: points of one joint_trajectory message. Sampling
  // is O(log points) per step; the points are checked outside the world
  // lock, about 0.2 us per joint and point.
  int max_trajectory_points = 100000;
};

// Fixed ranges. A time step above kWarnTimeStep is allowed with a warning:
// contacts and fast bodies degrade, but nothing overflows.
inline constexpr double kMinTimeStep = 1e-5;         // s
inline constexpr double kMaxTimeStep = 0.1;          // s
inline constexpr double kWarnTimeStep = 1.0 / 30.0;  // s
inline constexpr double kMinRealTimeFactor = 1e-3;   // or exactly 0: flat out
inline constexpr double kMaxRealTimeFactor = 1e6;
inline constexpr double kMaxGravity = 1e3;          // m/s^2: |gravity|, and each component
inline constexpr double kMaxFriction = 1e3;         // Coulomb mu of a spawn request
inline constexpr double kMinQuaternionNorm = 1e-9;  // below: no rotation
inline constexpr double kMaxQuaternionNorm = 1e9;
// |position| of a joint in a request, rad or m: a continuous joint wound
// further has lost its angle's precision below 1e-12 rad.
inline constexpr double kMaxJointPosition = 1e4;
// |header.stamp - now| of a joint_trajectory, s: a trajectory starts at its
// stamp, so one stamped further away would start or have ended out of any
// run's reach (a stamp of 2^32 s is 136 years off).
inline constexpr double kMaxTrajectoryStampOffset = 3600.0;
// The largest ~max_trajectory_points allowed.
inline constexpr int kMaxTrajectoryPointsLimit = 10000000;

// One joint's values in a request (spawn, ~set_joint_state, joint_command,
// joint_trajectory): |position| <= kMaxJointPosition, |velocity| within
// ~max_angular_speed (rad/s) or ~max_linear_speed (m/s) and |effort| within
// ~max_torque (N m) or ~max_force (N), by the joint's kind.
struct JointValues {
  std::string field;       // names the values in a refusal: "joint 'elbow'"
  bool prismatic = false;  // m, m/s and N; else rad, rad/s and N m
  double position = 0.0;
  double velocity = 0.0;
  double effort = 0.0;
};

// The limits themselves: each positive and finite.
physics::Status ValidateRequestLimits(const RequestLimits& limits);

// A pose and twist: |position| <= max_position, speeds within their
// limits; `field` prefixes the names ("pose", "twist").
physics::Status ValidateFrameState(const FrameState& state, const RequestLimits& limits);
// The state and the materials of a spawn request.
physics::Status ValidateModelSpec(const ModelSpec& spec, const RequestLimits& limits);
physics::Status ValidateJointValues(const JointValues& values, const RequestLimits& limits);
// An apply_wrench request.
physics::Status ValidateWrench(const physics::Vec3& force, const physics::Vec3& torque,
                               const physics::Vec3& point, double duration,
                               const RequestLimits& limits);
// The steps a wrench of `duration` s lasts at `time_step`, at least one;
// computed in double, so no duration overflows an integer.
std::int64_t WrenchSteps(double duration, double time_step);
physics::Status ValidateStepCount(std::uint64_t steps, const RequestLimits& limits);
// `field` names the parameter or request field in the message.
physics::Status ValidateTimeStep(double time_step, const std::string& field);
physics::Status ValidateRealTimeFactor(double factor, const std::string& field);
physics::Status ValidateGravity(const physics::Vec3& gravity, const std::string& field);

}  // namespace rigid_body_sim::node

#endif  // RIGID_BODY_SIM_NODE_REQUEST_VALIDATION_H_
