// The contact solver's set-up: tangent bases, combined materials, and the
// classification of every point by its relative normal velocity. The two
// solves are in collision_impulses.cc (colliding contact) and
// resting_contact.cc with resting_islands.cc (resting contact).
#include "physics/solver/contact_solver.h"

#include <algorithm>
#include <cmath>

namespace rigid_body_sim::physics {

void ContactSolver::Reset(const SolverSettings& settings, double time_step,
                          std::size_t body_count) {
  assert(time_step > 0.0);
  settings_ = settings;
  time_step_ = time_step;
  // Sized, not cleared: World loads the bodies the contacts reach.
  bodies_.resize(body_count);
  // The manifolds are sized and built afresh by
  // WorldImpl::BuildSolverManifolds, which follows.
  schedules_.resize(1);
  schedules_.front().clear();
}

void ContactSolver::Prepare() {
  for (SolverManifold& manifold : manifolds_) {
    manifold.tangent_world = TangentBasis(manifold.normal_world);
    for (int i = 0; i < manifold.point_count; ++i) {
      SolverPoint& point = manifold.points[i];
      point.normal_velocity_before = NormalVelocity(manifold, point);
      const double epsilon = settings_.collision_velocity_threshold;
      if (point.separation > settings_.contact_tolerance) {
        // Apart: the time-of-impact search finds when it touches.
        point.type = ContactType::kSeparating;
      } else if (point.normal_velocity_before < -epsilon) {
        point.type = ContactType::kColliding;
      } else if (point.normal_velocity_before <= epsilon) {
        point.type = ContactType::kResting;
      } else {
        point.type = ContactType::kSeparating;
      }
    }
  }
}

Vec3 ContactSolver::RelativeVelocity(const SolverManifold& manifold,
                                     const SolverPoint& point) const {
  const SolverBody& a = bodies_[manifold.body_a];
  const SolverBody& b = bodies_[manifold.body_b];
  return a.linear_velocity + a.angular_velocity.cross(point.r_a) - b.linear_velocity -
         b.angular_velocity.cross(point.r_b);
}

// v_r = n . (pa' - pb'), pa' = va + wa x ra (Baraff 1997, "Rigid Body
// Simulation II", section 8, eqs. (8-1)-(8-3)).
double ContactSolver::NormalVelocity(const SolverManifold& manifold,
                                     const SolverPoint& point) const {
  return manifold.normal_world.dot(RelativeVelocity(manifold, point));
}

// P_a += J, L_a += r_a x J; the opposite on B (Baraff 1997,
// "Rigid Body Simulation II", section 8, eqs. (8-5)-(8-7) and (8-12)).
void ContactSolver::ApplyImpulse(const SolverManifold& manifold, const SolverPoint& point,
                                 const Vec3& impulse_world) {
  SolverBody& a = bodies_[manifold.body_a];
  SolverBody& b = bodies_[manifold.body_b];
  // A body that does not move (static, asleep) is skipped, not multiplied
  // by its zero inverse mass: an impulse that overflowed would make its
  // velocity 0 * inf = NaN, and every body touching it (the ground: all of
  // them) would read that NaN. The step guard freezes the pair's moving body.
  if (a.inverse_mass != 0.0) {
    a.linear_velocity += a.inverse_mass * impulse_world;
    a.angular_velocity += Multiply(a.inverse_inertia_world, point.r_a.cross(impulse_world));
  }
  if (b.inverse_mass != 0.0) {
    b.linear_velocity -= b.inverse_mass * impulse_world;
    b.angular_velocity -= Multiply(b.inverse_inertia_world, point.r_b.cross(impulse_world));
  }
}

void ContactSolver::RecordStartVelocities() {
  for (SolverManifold& manifold : manifolds_) {
    for (int i = 0; i < manifold.point_count; ++i) {
      SolverPoint& point = manifold.points[i];
      point.normal_velocity_start =
          velocities_changed_ ? NormalVelocity(manifold, point) : point.normal_velocity_before;
    }
  }
}

}  // namespace rigid_body_sim::physics
