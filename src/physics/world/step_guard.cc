// The step guard around the stages of WorldImpl::Step: no body's state that
// is not finite, or so large that a step's products overflow, ever reaches
// another body. Before the stages, a body whose state or pending force is
// out of bounds is frozen where it is; after them, a body whose state is not
// finite goes back to its pose at the start of the step and is frozen there.
// Frozen is `disabled`: held still, out of the broad phase and the solver,
// its contacts dropped, until SetState gives it a state again.
#include <algorithm>
#include <cmath>

#include "physics/world/world_impl.h"

namespace rigid_body_sim::physics {
namespace {

// Bound on each of position (m), velocity (m/s), angular velocity (rad/s)
// and the velocity changes a step's forces give. The stages multiply at most
// three such quantities together (a lever arm times a mass times a
// velocity, a squared speed times a mass), so below 1e100 each, nothing a
// step computes overflows a double (1.8e308). No physical scene comes near.
constexpr double kMaxMagnitude = 1e100;
// Momenta are a mass or an inertia times a velocity.
constexpr double kMaxMomentum = kMaxMagnitude * kMaxMagnitude;

bool Within(const Vec3& v, double bound) {
  // Written so that NaN fails: !(NaN <= bound).
  return v.allFinite() && v.norm() <= bound;
}

// Whether the body's state, and the step its pending force and torque would
// give it, stay within the bounds.
bool StepIsSafe(const Body& body, double dt) {
  if (!body.HasFiniteState() || !body.force.allFinite() || !body.torque.allFinite()) return false;
  if (!Within(body.position, kMaxMagnitude) || !Within(body.linear_momentum, kMaxMomentum) ||
      !Within(body.angular_momentum, kMaxMomentum)) {
    return false;
  }
  const Vec3 velocity_change = dt * body.inverse_mass * body.force;
  const Vec3 spin_change = dt * (body.inverse_inertia_world * body.torque);
  return Within(body.linear_velocity, kMaxMagnitude) &&
         Within(body.angular_velocity, kMaxMagnitude) && Within(velocity_change, kMaxMagnitude) &&
         Within(spin_change, kMaxMagnitude);
}

bool StateIsSafe(const Body& body) {
  return body.HasFiniteState() && Within(body.position, kMaxMagnitude) &&
         Within(body.linear_momentum, kMaxMomentum) &&
         Within(body.angular_momentum, kMaxMomentum) &&
         Within(body.linear_velocity, kMaxMagnitude) &&
         Within(body.angular_velocity, kMaxMagnitude);
}

}  // namespace

// Both guards test every body on the pool (a test reads its own body and
// writes its own slot) and freeze the ones that failed here, in the
// bodies' order; freezing one body changes no other body's test.
void WorldImpl::GuardBeforeStep(const StepContext& step) {
  guard_start_poses_.resize(bodies_.size());
  guard_failed_.resize(bodies_.size());
  step.pool->ParallelFor(bodies_.size(), kBodiesPerGuardChunk, [&](std::size_t i) {
    const Body& body = bodies_[i];
    guard_failed_[i] = 0;
    // A link's state is its articulation's, which guards it as a whole.
    if (!body.in_use || body.is_static || body.disabled || body.articulation >= 0) return;
    const bool pose_is_finite = body.position.allFinite() && IsFinite(body.orientation);
    if (pose_is_finite) guard_start_poses_[i] = body.WorldFromPrincipal();
    guard_failed_[i] = body.awake && !StepIsSafe(body, step.dt) ? 1 : 0;
  });
  for (std::uint32_t i = 0; i < bodies_.size(); ++i) {
    if (!guard_failed_[i]) continue;
    const Body& body = bodies_[i];
    const bool pose_is_finite = body.position.allFinite() && IsFinite(body.orientation);
    // A pose that is not finite cannot come from the API (it refuses one),
    // so the start of the step is the last finite pose there is.
    FreezeBody(i, pose_is_finite ? body.WorldFromPrincipal() : guard_start_poses_[i]);
  }
}

void WorldImpl::GuardAfterStep() {
  guard_failed_.resize(bodies_.size());
  pool_->ParallelFor(bodies_.size(), kBodiesPerGuardChunk, [&](std::size_t i) {
    const Body& body = bodies_[i];
    guard_failed_[i] = 0;
    if (!body.in_use || body.is_static || body.articulation >= 0) return;
    // A body the stages disabled for a state that is not finite still holds
    // that state; one frozen here before holds a finite one.
    guard_failed_[i] = body.disabled ? !body.HasFiniteState() : !StateIsSafe(body);
  });
  for (std::uint32_t i = 0; i < bodies_.size(); ++i) {
    if (guard_failed_[i]) FreezeBody(i, guard_start_poses_[i]);
  }
}

void WorldImpl::FreezeBody(std::uint32_t index, const Pose& world_from_principal) {
  reports_.ForgetBody(index, pool_.get());
  Body& body = bodies_[index];
  body.position = world_from_principal.translation;
  body.orientation = world_from_principal.rotation;
  for (Vec3* v : {&body.linear_momentum, &body.angular_momentum, &body.force, &body.torque,
                  &body.start_linear_velocity, &body.start_angular_momentum,
                  &body.pseudo_linear_velocity, &body.pseudo_angular_velocity}) {
    v->setZero();
  }
  body.UpdateDerived();
  DisableBody(index);
  contact_cache_.RemoveBody(index);
}

// Only moving bodies change state within a step, so only they are checked,
// on the pool; the few that fail are disabled here, in their order.
void WorldImpl::DisableNonFiniteBodies() {
  non_finite_.resize(moving_bodies_.size());
  constexpr std::size_t kBodiesPerChunk = 256;
  pool_->ParallelFor(moving_bodies_.size(), kBodiesPerChunk, [this](std::size_t k) {
    const Body& body = bodies_[moving_bodies_[k]];
    non_finite_[k] = body.in_use && !body.is_static && !body.disabled && !body.HasFiniteState();
  });
  for (std::size_t k = 0; k < moving_bodies_.size(); ++k) {
    // Its cached pairs are no longer seen from the next step on, and go.
    if (non_finite_[k]) DisableBody(moving_bodies_[k]);
  }
}

// Out of the simulation until it is given a finite state: asleep, out of
// the broad phase, and reported once in non_finite_bodies_.
void WorldImpl::DisableBody(std::uint32_t index) {
  Body& body = bodies_[index];
  body.disabled = true;
  body.awake = false;
  woke_since_prune_ = true;
  collision_.RemoveProxy(index);
  const BodyId id{index, body.generation};
  if (std::find(non_finite_bodies_.begin(), non_finite_bodies_.end(), id) ==
      non_finite_bodies_.end()) {
    non_finite_bodies_.push_back(id);
  }
}

}  // namespace rigid_body_sim::physics
