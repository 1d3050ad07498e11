#include "rigid_body_sim/node/request_validation.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace rigid_body_sim::node {

using physics::FormatNumber;
using physics::Status;
using physics::Vec3;

namespace {

std::string Describe(const Vec3& v) {
  return "[" + FormatNumber(v.x()) + ", " + FormatNumber(v.y()) + ", " + FormatNumber(v.z()) + "]";
}

std::string Range(double low, double high) {
  return "[" + FormatNumber(low) + ", " + FormatNumber(high) + "]";
}

// |v| <= limit, named `field` with `unit`.
Status CheckMagnitude(const Vec3& v, double limit, const std::string& field,
                      const std::string& unit) {
  // stableNorm: 1e200 on each axis has a finite length that norm() would
  // overflow to infinity.
  const double magnitude = v.allFinite() ? v.stableNorm() : std::nan("");
  if (!(magnitude <= limit)) {
    return Status::Error(field + " " + Describe(v) + " " + unit + " (magnitude " +
                         FormatNumber(magnitude) + ") is outside the allowed range [0, " +
                         FormatNumber(limit) + "] " + unit);
  }
  return Status::Ok();
}

Status CheckIn(double value, double low, double high, const std::string& field,
               const std::string& unit) {
  if (!(value >= low && value <= high)) {
    return Status::Error(field + " " + FormatNumber(value) + (unit.empty() ? "" : " " + unit) +
                         " is outside the allowed range " + Range(low, high) +
                         (unit.empty() ? "" : " " + unit));
  }
  return Status::Ok();
}

}  // namespace

Status ValidateRequestLimits(const RequestLimits& limits) {
  const std::pair<double, const char*> limits_by_name[] = {
      {limits.max_position, "~max_position"},
      {limits.max_linear_speed, "~max_linear_speed"},
      {limits.max_angular_speed, "~max_angular_speed"},
      {limits.max_force, "~max_force"},
      {limits.max_torque, "~max_torque"},
      {limits.max_wrench_duration, "~max_wrench_duration"}};
  for (const auto& [value, name] : limits_by_name) {
    // Up to 1e100, the step guard's bound, so a request within the limits
    // is never frozen by it.
    if (Status status = CheckIn(value, 1e-300, 1e100, name, ""); !status.ok()) return status;
  }
  if (Status status = CheckIn(limits.max_step_count, 1, 1e9, "~max_step_count", ""); !status.ok()) {
    return status;
  }
  return CheckIn(limits.max_trajectory_points, 1, kMaxTrajectoryPointsLimit,
                 "~max_trajectory_points", "");
}

Status ValidateFrameState(const FrameState& state, const RequestLimits& limits) {
  for (const Status& status :
       {CheckMagnitude(state.world_from_frame.translation, limits.max_position, "pose.position",
                       "m"),
        CheckMagnitude(state.linear_velocity, limits.max_linear_speed, "twist.linear", "m/s"),
        CheckMagnitude(state.angular_velocity, limits.max_angular_speed, "twist.angular",
                       "rad/s")}) {
    if (!status.ok()) return status;
  }
  return Status::Ok();
}

Status ValidateModelSpec(const ModelSpec& spec, const RequestLimits& limits) {
  if (Status status = ValidateFrameState(spec.root_state, limits); !status.ok()) return status;
  if (Status status = ResolveRobotNamespace(spec.robot_namespace).status(); !status.ok()) {
    return status;
  }
  if (Status status = ResolveTfPrefix(spec.name, spec.tf_prefix, spec.tf_mode).status();
      !status.ok()) {
    return status;
  }
  // Negative means "not set"; NaN is neither.
  if (std::isnan(spec.friction) || spec.friction > kMaxFriction) {
    return Status::Error("friction " + FormatNumber(spec.friction) +
                         " is outside the allowed range [0, " + FormatNumber(kMaxFriction) +
                         "] (< 0: not set)");
  }
  if (std::isnan(spec.restitution) || spec.restitution > 1.0) {
    return Status::Error("restitution " + FormatNumber(spec.restitution) +
                         " is outside the allowed range [0, 1] (< 0: not set)");
  }
  // The kind of each joint is known once the URDF is read; its limits are
  // checked then. Here only the bound every kind shares.
  for (const auto& [name, position] : spec.joint_positions) {
    if (Status status = CheckIn(position, -kMaxJointPosition, kMaxJointPosition,
                                "joint_positions of '" + name + "'", "(rad or m)");
        !status.ok()) {
      return status;
    }
  }
  return Status::Ok();
}

Status ValidateJointValues(const JointValues& values, const RequestLimits& limits) {
  const double max_speed = values.prismatic ? limits.max_linear_speed : limits.max_angular_speed;
  const double max_effort = values.prismatic ? limits.max_force : limits.max_torque;
  for (const Status& status :
       {CheckIn(values.position, -kMaxJointPosition, kMaxJointPosition, values.field + " position",
                values.prismatic ? "m" : "rad"),
        CheckIn(values.velocity, -max_speed, max_speed, values.field + " velocity",
                values.prismatic ? "m/s" : "rad/s"),
        CheckIn(values.effort, -max_effort, max_effort, values.field + " effort",
                values.prismatic ? "N" : "N m")}) {
    if (!status.ok()) return status;
  }
  return Status::Ok();
}

Status ValidateWrench(const Vec3& force, const Vec3& torque, const Vec3& point, double duration,
                      const RequestLimits& limits) {
  for (const Status& status :
       {CheckMagnitude(force, limits.max_force, "wrench.force", "N"),
        CheckMagnitude(torque, limits.max_torque, "wrench.torque", "N m"),
        CheckMagnitude(point, limits.max_position, "point", "m"),
        CheckIn(duration, 0.0, limits.max_wrench_duration, "duration", "s")}) {
    if (!status.ok()) return status;
  }
  return Status::Ok();
}

std::int64_t WrenchSteps(double duration, double time_step) {
  // Capped far below 2^63, so the cast below is defined even for a duration
  // the limits let through at the smallest time step.
  constexpr double kMaxSteps = 1e15;
  const double steps = std::round(duration / time_step);
  if (!(steps >= 1.0)) return 1;
  return static_cast<std::int64_t>(std::min(steps, kMaxSteps));
}

Status ValidateStepCount(std::uint64_t steps, const RequestLimits& limits) {
  if (steps > static_cast<std::uint64_t>(limits.max_step_count)) {
    return Status::Error("steps " + std::to_string(steps) + " is outside the allowed range [0, " +
                         std::to_string(limits.max_step_count) + "] (~max_step_count)");
  }
  return Status::Ok();
}

Status ValidateTimeStep(double time_step, const std::string& field) {
  return CheckIn(time_step, kMinTimeStep, kMaxTimeStep, field, "s");
}

Status ValidateRealTimeFactor(double factor, const std::string& field) {
  if (factor == 0.0) return Status::Ok();
  if (!(factor >= kMinRealTimeFactor && factor <= kMaxRealTimeFactor)) {
    return Status::Error(field + " " + FormatNumber(factor) + " is outside the allowed range " +
                         Range(kMinRealTimeFactor, kMaxRealTimeFactor) +
                         " (or 0: as fast as possible)");
  }
  return Status::Ok();
}

Status ValidateGravity(const Vec3& gravity, const std::string& field) {
  return CheckMagnitude(gravity, kMaxGravity, field, "m/s^2");
}

}  // namespace rigid_body_sim::node
