// The exact solver behind the MotionSolver seam: Baraff's classification of
// every contact by its relative normal velocity, collision impulses with
// restitution, resting contact for all contacts at once (stage 4, here),
// and the time of impact found instead of tunnelling (stage 5,
// exact_integrate.cc and exact_impacts.cc); docs/design.md, stages 4 and 5.
#include "physics/solver/exact_solver.h"

#include <cmath>

#include "physics/dynamics/integrator.h"
#include "physics/solver/support_balance.h"
#include "physics/world/world_impl.h"

namespace rigid_body_sim::physics {
namespace {

// The solver's copy of the moving bodies; the other bodies the contacts
// reach (static or asleep) get zero inverse mass and inertia. Bodies no
// contact reaches are left as they are: the solver never reads them.
void LoadVelocities(const std::vector<Body>& bodies, const std::vector<std::uint32_t>& moving,
                    const std::vector<ShapePairContact*>& pairs,
                    std::vector<SolverBody>* solver_bodies) {
  for (const ShapePairContact* pair : pairs) {
    (*solver_bodies)[pair->body_a] = SolverBody();
    (*solver_bodies)[pair->body_b] = SolverBody();
  }
  for (const std::uint32_t i : moving) {
    const Body& body = bodies[i];
    SolverBody& solver_body = (*solver_bodies)[i];
    solver_body = SolverBody();
    if (body.disabled) continue;
    solver_body.linear_velocity = body.linear_velocity;
    solver_body.angular_velocity = body.angular_velocity;
    solver_body.inverse_mass = body.inverse_mass;
    solver_body.inverse_inertia_world = body.inverse_inertia_world;
  }
}

// P = M v and L = I_world omega, with I_world = R diag(I) R^T.
void StoreVelocities(const std::vector<SolverBody>& solver_bodies,
                     const std::vector<std::uint32_t>& moving, std::vector<Body>* bodies) {
  for (const std::uint32_t i : moving) {
    Body& body = (*bodies)[i];
    if (body.disabled) continue;
    const SolverBody& solver_body = solver_bodies[i];
    body.linear_momentum = body.mass * solver_body.linear_velocity;
    body.angular_momentum = AngularMomentumFor(body, solver_body.angular_velocity);
    body.pseudo_linear_velocity = solver_body.pseudo_linear_velocity;
    body.pseudo_angular_velocity = solver_body.pseudo_angular_velocity;
    body.UpdateDerived();
  }
}

}  // namespace

ExactSolver::ExactSolver(WorldImpl* world) : world_(*world) {}

void ExactSolver::Solve(const StepContext& step) { SolveContacts(step); }

void ExactSolver::Integrate(const StepContext& step) { IntegrateBodies(step); }

std::unique_ptr<MotionSolver> MakeMotionSolver(MotionSolverKind kind, WorldImpl* world) {
  switch (kind) {
    case MotionSolverKind::kExact:
      break;
    case MotionSolverKind::kSoftStep:
      return MakeSoftStepSolver(world);
  }
  return std::make_unique<ExactSolver>(world);
}

// Baraff's order within a step: colliding contacts get impulses on the
// velocities the step starts with, then the forces act, then the resting
// contacts get the impulses that keep them apart, all contacts at once.
void ExactSolver::SolveContacts(const StepContext& step) {
  world_.ListMovingBodies();
  // The contact solver takes the pairs of rigid bodies; the articulations'
  // system, after it, the pairs with a link (articulation_step.cc).
  world_.articulations_.TakeLinkPairs(world_.contact_cache_.touching(), &world_.rigid_pairs_);
  SolveTouching(step, world_.rigid_pairs_);
  world_.articulations_.Solve(step);
  world_.reports_.ReportSolved(world_.rigid_pairs_, step, /*impacts_only=*/false);
  world_.articulations_.ReportContacts(step, &world_.reports_);
}

// The contact solve of the touching pairs over dt, for the bodies of
// moving_bodies_; the others are held where they are.
void ExactSolver::SolveTouching(const StepContext& step,
                                const std::vector<ShapePairContact*>& pairs) {
  world_.solver_.Reset(world_.settings_.solver, step.dt, world_.bodies_.size());
  LoadVelocities(world_.bodies_, world_.moving_bodies_, pairs, &world_.solver_.bodies());
  world_.solver_.BuildManifolds(pairs, world_.bodies_, step.pool);
  SeedNewSupportLoads(SupportInputFor(world_.bodies_, world_.settings_, step.dt),
                      &world_.solver_.manifolds());
  world_.solver_.Prepare();

  world_.solver_.ResolveCollisions();
  world_.solver_.RecordStartVelocities();
  StoreVelocities(world_.solver_.bodies(), world_.moving_bodies_, &world_.bodies_);
  IntegrateForces(world_.settings_.gravity, step.dt, world_.moving_bodies_, &world_.bodies_);
  world_.DisableNonFiniteBodies();
  LoadVelocities(world_.bodies_, world_.moving_bodies_, pairs, &world_.solver_.bodies());
  world_.solver_.SolveRestingContacts();
  StoreVelocities(world_.solver_.bodies(), world_.moving_bodies_, &world_.bodies_);
  HoldPushedBodies();
}

// A body that resting contact pushed this step drifts with its end velocity
// along the contact normal (symplectic Euler), so it does not sink while
// held; across the normal it keeps the trapezoid, dt/2 (v_start + v_end),
// exact for a constant force such as kinetic friction on a sliding box
// (integrator.h). A body pushed along two directions that are not parallel
// (a box in a corner, one in a stack leaning on a neighbour) drifts with its
// end velocity and its end angular momentum throughout.
void ExactSolver::HoldPushedBodies() {
  constexpr double kParallelSine = 1e-9;
  push_normals_.resize(world_.bodies_.size());
  push_state_.assign(world_.bodies_.size(), 0);
  for (const SolverManifold& manifold : world_.solver_.manifolds()) {
    bool pushed = false;
    for (int i = 0; i < manifold.point_count; ++i)
      pushed |= manifold.points[i].normal_impulse > 0.0;
    if (!pushed) continue;
    for (const std::uint32_t index : {manifold.body_a, manifold.body_b}) {
      std::uint8_t& state = push_state_[index];
      if (state == 0) {
        push_normals_[index] = manifold.normal_world;
        state = 1;
      } else if (push_normals_[index].cross(manifold.normal_world).norm() > kParallelSine) {
        state = 2;
      }
    }
  }
  const double impulsive = world_.settings_.solver.collision_velocity_threshold;
  for (const std::uint32_t index : world_.moving_bodies_) {
    Body& body = world_.bodies_[index];
    const Vec3& n = push_normals_[index];
    const double normal_change = n.dot(body.linear_velocity - body.start_linear_velocity);
    // The change along the normal is a force's only while the body rests;
    // one that stops an approach (an inelastic landing) is an impulse at the
    // start of the step, and the end velocity holds throughout.
    if (push_state_[index] == 1 && std::abs(normal_change) <= impulsive) {
      body.start_linear_velocity += n * normal_change;
      body.start_angular_momentum = body.angular_momentum;
    } else if (push_state_[index] != 0) {
      body.start_linear_velocity = body.linear_velocity;
      body.start_angular_momentum = body.angular_momentum;
    }
  }
}

}  // namespace rigid_body_sim::physics
