// The contact solver's set-up: tangent bases, combined materials, and the
// classification of every point by its relative normal velocity. The two
// solves are in collision_impulses.cc (colliding contact) and
// resting_contact.cc with resting_islands.cc (resting contact).
#include "physics/solver/contact_solver.h"

#include <algorithm>
#include <cmath>

namespace rigid_body_sim::physics {
namespace {

// Manifolds a thread takes at a time when they are built on the pool.
constexpr std::size_t kManifoldsPerChunk = 256;

// Pairs ahead of the one being built whose cache entries, and whose bodies'
// positions, start loading. The soft step builds its pairs in colour order
// (soft_step_solver.cc), where neither is near the last one in memory, and
// four entries ahead left each build waiting for its lines (with the colour
// order and these, pyramid_90 took 0.88 and pile_4000 0.93 of the awake
// step; docs/performance.md, "The soft step's manifolds in colour order").
constexpr std::size_t kEntriesAhead = 12;
constexpr std::size_t kBodiesAhead = 6;

}  // namespace

void ContactSolver::Reset(const SolverSettings& settings, double time_step,
                          std::size_t body_count) {
  assert(time_step > 0.0);
  settings_ = settings;
  time_step_ = time_step;
  // Sized, not cleared: World loads the bodies the contacts reach.
  bodies_.resize(body_count);
  // The manifolds are sized and built afresh by BuildManifolds, which
  // follows.
  schedules_.resize(1);
  schedules_.front().clear();
}

void ContactSolver::Prepare() {
  for (SolverManifold& manifold : manifolds_) {
    manifold.tangent_world = TangentBasis(manifold.normal_world);
    for (int i = 0; i < manifold.point_count; ++i) {
      SolverPoint& point = manifold.points[i];
      point.normal_velocity_before = NormalVelocity(manifold, point);
      point.type = ClassifyContactPoint(point.separation, point.normal_velocity_before, settings_);
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

// One solver manifold per touching pair, with its points' lever arms,
// combined materials and last step's impulses.
void ContactSolver::BuildManifolds(const std::vector<ShapePairContact*>& pairs,
                                   const std::vector<Body>& bodies, TaskPool* pool) {
  // Resized, not cleared (Reset keeps them): a manifold with its four
  // points is 648 bytes, and each is built afresh below, on the pool.
  manifolds_.resize(pairs.size());
  manifold_bodies_.resize(pairs.size());
  pool->ParallelFor(pairs.size(), kManifoldsPerChunk, [&](std::size_t m) {
    if (m + kEntriesAhead < pairs.size()) PrefetchPoints(*pairs[m + kEntriesAhead]);
    if (m + kBodiesAhead < pairs.size()) {
      __builtin_prefetch(&bodies[pairs[m + kBodiesAhead]->body_a].position);
      __builtin_prefetch(&bodies[pairs[m + kBodiesAhead]->body_b].position);
    }
    const ShapePairContact* pair = pairs[m];
    manifold_bodies_[m] = {pair->body_a, pair->body_b};
    const Body& a = bodies[pair->body_a];
    const Body& b = bodies[pair->body_b];
    // Reset field by field: assigning a fresh SolverManifold built all four
    // points (648 bytes) and copied them. Points past point_count keep an
    // earlier step's values; nothing reads them.
    SolverManifold& manifold = manifolds_[m];
    manifold.tangent_world = {Vec3::UnitX(), Vec3::UnitY()};  // as constructed
    manifold.body_a = pair->body_a;
    manifold.body_b = pair->body_b;
    manifold.normal_world = pair->manifold.normal_world;
    const Material& material_a = a.shapes[pair->shape_a].material;
    const Material& material_b = b.shapes[pair->shape_b].material;
    manifold.friction = CombineFriction(material_a.friction, material_b.friction);
    manifold.restitution = CombineRestitution(material_a.restitution, material_b.restitution);
    manifold.point_count = pair->manifold.point_count;
    manifold.new_pair = pair->previous_count == 0;
    for (int i = 0; i < manifold.point_count; ++i) {
      const ContactPoint& contact = pair->manifold.points[i];
      SolverPoint& point = manifold.points[i];
      point = SolverPoint();
      point.r_a = contact.position_world - a.position;
      point.r_b = contact.position_world - b.position;
      point.separation = contact.separation;
      point.feature = contact.feature;
      const CachedImpulse& warm = pair->WarmStart(i);
      point.normal_impulse = warm.normal_impulse;
      point.tangent_impulse = warm.tangent_impulse;
      point.preload = warm.preload;
      point.carried_approach = warm.approach_velocity;
    }
  });
}

}  // namespace rigid_body_sim::physics
