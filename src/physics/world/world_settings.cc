#include "rigid_body_sim/physics/world_settings.h"

#include <cmath>
#include <string>

namespace rigid_body_sim::physics {
namespace {

// Each check returns an error naming the setting, its value and the range
// it must lie in.
Status FiniteAbove(const char* name, double value, double low, bool low_open, const char* range) {
  const bool above = low_open ? value > low : value >= low;
  if (std::isfinite(value) && above) return Status::Ok();
  return Status::Error(std::string(name) + " " + FormatNumber(value) + " must be " + range);
}

Status AtLeast(const char* name, int value, int low) {
  if (value >= low) return Status::Ok();
  return Status::Error(std::string(name) + " " + std::to_string(value) +
                       " must be >= " + std::to_string(low));
}

Status FirstError(std::initializer_list<Status> statuses) {
  for (const Status& status : statuses) {
    if (!status.ok()) return status;
  }
  return Status::Ok();
}

}  // namespace

Status ValidateSolverSettings(const SolverSettings& settings) {
  const double correction = settings.position_correction;
  return FirstError({
      AtLeast("velocity_iterations", settings.velocity_iterations, 1),
      AtLeast("position_iterations", settings.position_iterations, 0),
      FiniteAbove("velocity_tolerance", settings.velocity_tolerance, 0.0, false, "finite and >= 0"),
      FiniteAbove("collision_velocity_threshold", settings.collision_velocity_threshold, 0.0, false,
                  "finite and >= 0"),
      FiniteAbove("contact_tolerance", settings.contact_tolerance, 0.0, true, "finite and > 0"),
      FiniteAbove("penetration_slop", settings.penetration_slop, 0.0, false, "finite and >= 0"),
      correction > 0.0 && correction <= 1.0
          ? Status::Ok()
          : Status::Error("position_correction " + FormatNumber(correction) + " must be in (0, 1]"),
      AtLeast("max_collision_rounds", settings.max_collision_rounds, 1),
      AtLeast("collision_iterations", settings.collision_iterations, 1),
      AtLeast("max_pivoting_points", settings.max_pivoting_points, 0),
  });
}

Status ValidateSoftStepSettings(const SoftStepSettings& settings) {
  return FirstError({
      settings.substeps >= 1 && settings.substeps <= kMaxSoftSubsteps
          ? Status::Ok()
          : Status::Error("substeps " + std::to_string(settings.substeps) + " must be in [1, " +
                          std::to_string(kMaxSoftSubsteps) + "]"),
      FiniteAbove("contact_hertz", settings.contact_hertz, 0.0, true, "finite and > 0 (Hz)"),
      FiniteAbove("contact_damping_ratio", settings.contact_damping_ratio, 0.0, false,
                  "finite and >= 0"),
      FiniteAbove("max_push_velocity", settings.max_push_velocity, 0.0, true,
                  "finite and > 0 (m/s)"),
      settings.load_tracking >= 0.0 && settings.load_tracking <= 1.0
          ? Status::Ok()
          : Status::Error("load_tracking " + FormatNumber(settings.load_tracking) +
                          " must be in [0, 1]"),
      AtLeast("compact_blocks_from", settings.compact_blocks_from, 0),
  });
}

Status ValidateWorldSettings(const WorldSettings& settings) {
  if (!IsFinite(settings.gravity)) {
    return Status::Error("gravity [" + FormatNumber(settings.gravity.x()) + ", " +
                         FormatNumber(settings.gravity.y()) + ", " +
                         FormatNumber(settings.gravity.z()) + "] m/s^2 must be finite");
  }
  const double fraction = settings.continuous_fraction;
  const SleepSettings& sleep = settings.sleep;
  if (Status status = FirstError({
          FiniteAbove("time_step", settings.time_step, 0.0, true, "positive and finite (s)"),
          FiniteAbove("contact_margin", settings.contact_margin, 0.0, false, "finite and >= 0 (m)"),
          FiniteAbove("contact_reuse_distance", settings.contact_reuse_distance, 0.0, false,
                      "finite and >= 0 (m)"),
          fraction > 0.0 && fraction <= 1.0
              ? Status::Ok()
              : Status::Error("continuous_fraction " + FormatNumber(fraction) +
                              " must be in (0, 1]"),
          settings.max_turn_per_step > 0.0 && settings.max_turn_per_step <= M_PI
              ? Status::Ok()
              : Status::Error("max_turn_per_step " + FormatNumber(settings.max_turn_per_step) +
                              " rad must be in (0, pi]"),
          // Speeds may be infinite: every body may then sleep.
          sleep.linear_velocity >= 0.0
              ? Status::Ok()
              : Status::Error("sleep.linear_velocity " + FormatNumber(sleep.linear_velocity) +
                              " m/s must be >= 0"),
          sleep.angular_velocity >= 0.0
              ? Status::Ok()
              : Status::Error("sleep.angular_velocity " + FormatNumber(sleep.angular_velocity) +
                              " rad/s must be >= 0"),
          FiniteAbove("sleep.time_to_sleep", sleep.time_to_sleep, 0.0, false,
                      "finite and >= 0 (s)"),
          settings.threads >= 0 && settings.threads <= kMaxThreads
              ? Status::Ok()
              : Status::Error("threads " + std::to_string(settings.threads) + " must be in [0, " +
                              std::to_string(kMaxThreads) + "] (0: one per core)"),
          FiniteAbove("sleep.speeding_up_time", sleep.speeding_up_time, 0.0, false,
                      "finite and >= 0 (s)"),
          settings.motion_solver == MotionSolverKind::kExact ||
                  settings.motion_solver == MotionSolverKind::kSoftStep
              ? Status::Ok()
              : Status::Error("motion_solver " +
                              std::to_string(static_cast<int>(settings.motion_solver)) +
                              " is not a solver: kExact (0) or kSoftStep (1)"),
      });
      !status.ok()) {
    return status;
  }
  if (Status status = ValidateSolverSettings(settings.solver); !status.ok()) {
    return Status::Error("solver." + status.message());
  }
  if (Status status = ValidateSoftStepSettings(settings.soft_step); !status.ok()) {
    return Status::Error("soft_step." + status.message());
  }
  return Status::Ok();
}

}  // namespace rigid_body_sim::physics
