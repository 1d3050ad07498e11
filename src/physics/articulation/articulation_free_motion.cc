// The free motion's step with its energy balance checked (docs/design.md,
// "Articulated bodies", "Free motion that keeps its energy").
//
// Classical RK4 is stable only while dt omega < 2.78 for every mode of the
// linearized motion (Hairer and Wanner 1996, "Solving Ordinary Differential
// Equations II", section IV.2). A chain of light links under the tension of
// a heavy tip has modes near omega = 2 sqrt(T / (m l)): 1,100 rad/s for
// 0.1 kg, 0.1 m links under 3,000 N, so dt omega = 4.6 at 1/240 s, and the
// unstable mode's energy grows 200-fold per step. Such a mode shows first
// as a miss of the energy balance E1 = E0 + W, where W is the efforts'
// work: the step's own error estimate, a scalar one. So the step is split
// into parts until the balance holds to a tolerance, and the miss left is
// projected away by scaling the velocities (Hairer, Lubich and Wanner 2006,
// "Geometric Numerical Integration", section IV.4, projection onto the
// energy's level set; with q fixed, u -> s u is the projection in the
// kinetic energy's metric). Damping only takes energy out, so with it the
// balance is a bound, E1 <= E0 + W, and only a gain is projected away.
// With external wrenches on links the balance is not checked; the step then
// keeps the split its last checked steps needed. A step's parts are capped
// by a budget of parts times links (MostParts): past it the projection
// still keeps the energy, and a large model's step its bounded cost.
#include <algorithm>
#include <cmath>
#include <utility>

#include "physics/articulation/free_motion.h"

namespace rigid_body_sim::physics {
namespace {

// A step may miss the balance by this share of the kinetic energy before
// it is split: a loose estimate of RK4's local error, tight enough to catch
// an unstable mode while its energy is still this small a share.
constexpr double kBalanceTolerance = 1e-4;
// Rounding in E = sum of the links' terms, as a share of their magnitudes.
constexpr double kRounding = 1e-12;
// RK4's local error is O(h^5): a step in half as many parts misses the
// balance by about 2^5 / 2 = 16 times as much.
constexpr double kHalvingGrowth = 16.0;
// Half as many parts are tried when the last step's miss, so grown, would
// stay below this share of the tolerance.
constexpr double kSafety = 0.5;
// An unstable mode's miss does not follow the error's order: after fewer
// parts failed, this many steps pass before they are tried again.
constexpr int kStepsBeforeRetry = 64;

bool WrenchesOnLinks(const ArticulationModel& model) {
  for (const ArticulationLink& link : model.links) {
    if (!link.force.isZero(0.0) || !link.torque.isZero(0.0)) return true;
  }
  return false;
}

// The velocities of a state whose u is scaled by s: every one is linear in u.
void ScaleVelocities(double s, ArticulationKinematics* k) {
  for (Vec3& v : k->linear_velocity) v *= s;
  for (Vec3& w : k->angular_velocity) w *= s;
  for (double& v : k->joint_velocity) v *= s;
}

}  // namespace

// E = sum_i (m_i v_i^2 / 2 + omega_i . I_i omega_i / 2 - m_i g . c_i) over
// the links that move: a fixed base's constant term would only change the
// rounding (a base of mass 0 and one of 1 kg must swing the same arm alike).
Energy EnergyOf(const ArticulationModel& model, const ArticulationKinematics& k,
                const Vec3& gravity) {
  Energy energy;
  for (std::size_t i = model.fixed_base ? 1 : 0; i < model.links.size(); ++i) {
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

int FreeMotionIntegrator::MostParts(const ArticulationModel& model) {
  const std::size_t moving = model.links.size() - (model.fixed_base ? 1 : 0);
  int parts = kMaxParts;
  while (parts > 1 && static_cast<std::size_t>(parts) * moving > kLinkPartBudget) parts /= 2;
  return parts;
}

void FreeMotionIntegrator::Step(const FreeMotionStep& step, const FreeMotionEnd& end) {
  const int most_parts = MostParts(step.model);
  parts_ = std::clamp(parts_, 1, most_parts);
  if (WrenchesOnLinks(step.model)) {
    StepInParts(step, parts_, end.state);
    ComputeKinematics(step.model, *end.state, end.kinematics, KinematicsParts::kPosesAndVelocities);
    return;
  }
  bool fewer = parts_ > 1 && steps_before_retry_ == 0 && kHalvingGrowth * last_ratio_ < kSafety;
  steps_before_retry_ = std::max(0, steps_before_retry_ - 1);
  if (fewer) parts_ /= 2;
  const bool exact_balance = !AnyJointDamped(step.model);
  const Energy before = EnergyOf(step.model, step.kinematics, step.gravity);
  for (;;) {
    StepInParts(step, parts_, end.state);
    ComputeKinematics(step.model, *end.state, end.kinematics, KinematicsParts::kPosesAndVelocities);
    const Energy after = EnergyOf(step.model, *end.kinematics, step.gravity);
    // The efforts are constant over the step: W = tau . (q1 - q0).
    const double work = step.joint_efforts.dot(end.state->q - step.state.q);
    const double allowed = before.kinetic + before.potential + work;
    const double miss = after.kinetic + after.potential - allowed;
    const double rounding = kRounding * (before.magnitude + after.magnitude);
    const double tolerance = kBalanceTolerance * std::max(before.kinetic, after.kinetic) + rounding;
    const double error = exact_balance ? std::abs(miss) : miss;
    // Written so that a state that is not finite (NaN miss) is split too.
    if (!(error <= tolerance) && parts_ < most_parts) {
      parts_ *= 2;
      if (fewer) steps_before_retry_ = kStepsBeforeRetry;
      fewer = false;
      continue;
    }
    last_ratio_ = error <= tolerance ? error / tolerance : 1.0;
    // A gain is always taken away. Where the balance is exact, a loss beyond
    // the rounding is given back, even one beyond the tolerance at the most
    // parts; where it is a bound, a loss is the damping's. A loss within the
    // rounding is left: projecting it would only move the state by rounding
    // (a free fall, which RK4 integrates exactly, would drift).
    const bool project = miss > 0.0 || (exact_balance && miss < -rounding);
    if (!std::isfinite(miss) || !project) return;
    // K = u^T M(q) u / 2: scaling u by s scales it by s^2.
    const double kinetic = allowed - after.potential;
    double s = kinetic > 0.0 && after.kinetic > 0.0 ? std::sqrt(kinetic / after.kinetic) : 0.0;
    if (s == 0.0 && miss <= 0.0) s = 1.0;
    end.state->u *= s;
    ScaleVelocities(s, end.kinematics);
    return;
  }
}

void FreeMotionIntegrator::Restart() {
  parts_ = 1;
  last_ratio_ = 1.0;
  steps_before_retry_ = 0;
}

void FreeMotionIntegrator::StepInParts(const FreeMotionStep& step, int parts,
                                       ArticulationState* next) {
  const double h = step.dt / parts;
  if (parts == 1) {
    RungeKuttaStep(step, step.state, h, /*from_step_start=*/true, next);
    return;
  }
  part_start_ = step.state;
  for (int part = 0; part < parts; ++part) {
    RungeKuttaStep(step, part_start_, h, part == 0, next);
    if (part + 1 < parts) std::swap(part_start_, *next);
  }
}

void FreeMotionIntegrator::Accelerate(const FreeMotionStep& step, const ArticulationState& state,
                                      Eigen::VectorXd* acceleration) {
  ComputeKinematics(step.model, state, &kinematics_, KinematicsParts::kPosesAndVelocities);
  ForwardDynamics({step.model, state, kinematics_, step.gravity, step.joint_efforts}, &dynamics_,
                  acceleration);
}

// Classical RK4 (Kutta 1901; Hairer, Norsett and Wanner 1993, "Solving
// Ordinary Differential Equations I", section II.1): k1..k4 at t, t + h/2,
// t + h/2, t + h, combined as (k1 + 2 k2 + 2 k3 + k4) / 6. The base
// orientation takes the weighted mean angular velocity as one turn, which
// keeps it a unit quaternion.
void FreeMotionIntegrator::RungeKuttaStep(const FreeMotionStep& step,
                                          const ArticulationState& start, double h,
                                          bool from_step_start, ArticulationState* next) {
  const ArticulationModel& model = step.model;
  std::array<Eigen::VectorXd, 4>& a = stage_acceleration_;
  const Eigen::VectorXd& u1 = start.u;
  const bool given = from_step_start && step.start_acceleration != nullptr;
  if (!given) Accelerate(step, start, &a[0]);
  const Eigen::VectorXd& a1 = given ? *step.start_acceleration : a[0];
  AdvanceInto(model, start, u1, 0.5 * h, &stage_);
  stage_.u = u1 + 0.5 * h * a1;
  Accelerate(step, stage_, &a[1]);
  velocity_sum_ = u1 + 2.0 * stage_.u;
  AdvanceInto(model, start, stage_.u, 0.5 * h, &stage_);
  stage_.u = u1 + 0.5 * h * a[1];
  Accelerate(step, stage_, &a[2]);
  velocity_sum_ += 2.0 * stage_.u;
  AdvanceInto(model, start, stage_.u, h, &stage_);
  stage_.u = u1 + h * a[2];
  Accelerate(step, stage_, &a[3]);
  velocity_sum_ += stage_.u;
  velocity_sum_ /= 6.0;
  AdvanceInto(model, start, velocity_sum_, h, next);
  next->u = u1 + h / 6.0 * (a1 + 2.0 * a[1] + 2.0 * a[2] + a[3]);
}

}  // namespace rigid_body_sim::physics
