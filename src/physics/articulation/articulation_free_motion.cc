// The free motion's step with its energy balance checked (docs/design.md,
// "Articulated bodies", "Free motion that never gains energy").
//
// Classical RK4 is stable only while dt omega < 2.78 for every mode of the
// linearized motion (Hairer and Wanner 1996, "Solving Ordinary Differential
// Equations II", section IV.2). A chain of light links under the tension of
// a heavy tip has modes near omega = 2 sqrt(T / (m l)): 1,100 rad/s for
// 0.1 kg, 0.1 m links under 3,000 N, so dt omega = 4.6 at 1/240 s, and the
// unstable mode's energy grows 200-fold per step. Such a mode shows first
// as a gain of energy that no force supplied. So the step is split into
// parts until the balance E1 - E0 - W holds to a tolerance, where W is the
// efforts' work, and whatever gain is left is projected away by scaling
// the velocities (Hairer, Lubich and Wanner 2006, "Geometric Numerical
// Integration", section IV.4, projection onto the energy's level set).
// Damping only takes energy out, so the balance is a bound: E1 <= E0 + W.
// With external wrenches on links the balance is not checked; the step then
// keeps the split its last checked steps needed.
#include <algorithm>
#include <cmath>

#include "physics/articulation/articulation_dynamics.h"

namespace rigid_body_sim::physics {
namespace {

// A step may gain this share of the kinetic energy before it is split; the
// gain left below it is projected away.
constexpr double kGainTolerance = 1e-8;
// Rounding in E = sum of the links' terms, as a share of their magnitudes.
constexpr double kRounding = 1e-12;
// After this many steps at one split, the next step tries half as many parts.
constexpr int kStepsBeforeFewerParts = 64;

struct Energy {
  double kinetic = 0.0;    // J
  double potential = 0.0;  // J, of gravity, zero at the world's origin
  double magnitude = 0.0;  // J, the sum of the terms' magnitudes
};

// E = sum_i (m_i v_i^2 / 2 + omega_i . I_i omega_i / 2 - m_i g . c_i).
Energy ComputeEnergy(const ArticulationModel& model, const ArticulationState& state,
                     const Vec3& gravity) {
  ArticulationKinematics k;
  ComputeKinematics(model, state, &k, KinematicsParts::kPosesAndVelocities);
  Energy energy;
  for (std::size_t i = 0; i < model.links.size(); ++i) {
    const double mass = model.links[i].mass;
    const double kinetic =
        0.5 * (mass * k.linear_velocity[i].squaredNorm() +
               k.angular_velocity[i].dot(k.inertia_world[i] * k.angular_velocity[i]));
    const double potential = -mass * gravity.dot(k.com_world[i]);
    energy.kinetic += kinetic;
    energy.potential += potential;
    energy.magnitude += kinetic + std::abs(potential);
  }
  return energy;
}

bool WrenchesOnLinks(const ArticulationModel& model) {
  for (const ArticulationLink& link : model.links) {
    if (!link.force.isZero(0.0) || !link.torque.isZero(0.0)) return true;
  }
  return false;
}

ArticulationState StepInParts(const FreeMotionStep& step, int parts) {
  ArticulationState state = step.state;
  const double h = step.dt / parts;
  for (int part = 0; part < parts; ++part) {
    state = StepFreeMotion(step.model, state, step.gravity, step.joint_efforts, h,
                           part == 0 ? step.start_acceleration : nullptr);
  }
  return state;
}

}  // namespace

ArticulationState StepFreeMotionBalanced(const FreeMotionStep& step, FreeMotionSplit* split) {
  split->parts = std::clamp(split->parts, 1, kMaxFreeMotionParts);
  if (split->parts > 1 && split->steps_at_parts >= kStepsBeforeFewerParts) {
    split->parts /= 2;
    split->steps_at_parts = 0;
  }
  if (WrenchesOnLinks(step.model)) {
    ++split->steps_at_parts;
    return StepInParts(step, split->parts);
  }
  const Energy before = ComputeEnergy(step.model, step.state, step.gravity);
  const int parts_at_start = split->parts;
  for (;;) {
    ArticulationState next = StepInParts(step, split->parts);
    const Energy after = ComputeEnergy(step.model, next, step.gravity);
    // The efforts are constant over the step: W = tau . (q1 - q0).
    const double work = step.joint_efforts.dot(next.q - step.state.q);
    const double allowed = before.kinetic + before.potential + work;
    const double gain = after.kinetic + after.potential - allowed;
    const double tolerance = kGainTolerance * std::max(before.kinetic, after.kinetic) +
                             kRounding * (before.magnitude + after.magnitude);
    // Written so that a state that is not finite (NaN gain) is split too.
    if (!(gain <= tolerance) && split->parts < kMaxFreeMotionParts) {
      split->parts *= 2;
      continue;
    }
    split->steps_at_parts = split->parts == parts_at_start ? split->steps_at_parts + 1 : 0;
    if (gain > 0.0 && std::isfinite(gain)) {
      // The kinetic energy is u^T M(q) u / 2: scaling u by s scales it by s^2.
      const double kinetic = allowed - after.potential;
      next.u *= kinetic > 0.0 && after.kinetic > 0.0 ? std::sqrt(kinetic / after.kinetic) : 0.0;
    }
    return next;
  }
}

}  // namespace rigid_body_sim::physics
