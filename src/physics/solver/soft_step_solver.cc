// The soft step behind the MotionSolver seam (soft_contact_solver.h): the
// world's bodies loaded into the sub-steps, and their new velocities and
// poses written back. The articulations keep their own solve (the same for
// both solvers), after the rigid bodies': a body that touches a link takes
// the velocity change that solve gives it on top of its sub-stepped motion.
#include <algorithm>
#include <cmath>

#include "physics/dynamics/integrator.h"
#include "physics/solver/motion_solver.h"
#include "physics/solver/soft_contact_solver.h"
#include "physics/solver/support_balance.h"
#include "physics/world/world_impl.h"

namespace rigid_body_sim::physics {

class SoftStepSolver final : public MotionSolver {
 public:
  explicit SoftStepSolver(WorldImpl* world) : world_(*world) {}
  void Solve(const StepContext& step) override;
  void Integrate(const StepContext& step) override;

 private:
  void ColourPairs();
  void SeedNewSupports(const StepContext& step);
  void LoadBodies(const StepContext& step);
  void StoreVelocities(const StepContext& step);

  // A chunk of the pool's per-body loops: a body costs tens of ns.
  static constexpr std::size_t kBodiesPerChunk = 128;
  // A chunk of the pool's per-pair copies of friction anchors.
  static constexpr std::size_t kPairsPerChunk = 256;

  WorldImpl& world_;
  SoftContactSolver solver_;
  std::vector<SoftBody> bodies_;            // per body slot
  std::vector<FrictionAnchor> anchors_;     // per manifold
  std::vector<std::uint8_t> touches_link_;  // per body slot, Integrate's
  // The touching pairs' colours (ColourPairs), and its scratch: each pair's
  // bodies, the moving ones' mask and their colours' masks, per body slot,
  // and the pairs before they are put in colour order.
  ConstraintColouring colouring_;
  std::vector<std::uint32_t> pair_body_a_;
  std::vector<std::uint32_t> pair_body_b_;
  std::vector<std::uint8_t> moving_mask_;
  std::vector<std::uint32_t> colour_masks_;
  std::vector<std::uint8_t> colour_of_;
  std::vector<ShapePairContact*> unordered_pairs_;
};

std::unique_ptr<MotionSolver> MakeSoftStepSolver(WorldImpl* world) {
  return std::make_unique<SoftStepSolver>(world);
}

void SoftStepSolver::Solve(const StepContext& step) {
  WorldImpl& w = world_;
  w.ListMovingBodies();
  w.articulations_.TakeLinkPairs(w.contact_cache_.touching(), &w.rigid_pairs_);
  ColourPairs();
  w.solver_.Reset(w.settings_.solver, step.dt, w.bodies_.size());
  w.solver_.BuildManifolds(w.rigid_pairs_, w.bodies_, step.pool);
  SeedNewSupports(step);
  LoadBodies(step);
  SoftStepInput input;
  input.dt = step.dt;
  input.settings = w.settings_.soft_step;
  input.collision_velocity_threshold = w.settings_.solver.collision_velocity_threshold;
  // A point a tenth of the contact margin apart touches: a face landing
  // flat stops on its first corners' speculative rows, the others a fraction
  // of a millimetre up.
  input.moving = &w.moving_bodies_;
  input.manifold_bodies = &w.solver_.manifold_bodies();
  input.colouring = &colouring_;
  input.touch_tolerance =
      std::max(w.settings_.solver.contact_tolerance, 0.1 * w.settings_.contact_margin);
  // The anchors to and from the pairs' cache entries on the pool: each
  // entry is a load from memory the caches no longer hold.
  anchors_.resize(w.rigid_pairs_.size());
  step.pool->ParallelFor(w.rigid_pairs_.size(), kPairsPerChunk, [&](std::size_t m) {
    PrefetchAhead(w.rigid_pairs_, m, PrefetchFrictionAnchor);
    anchors_[m] = w.rigid_pairs_[m]->friction_anchor;
  });
  solver_.Step(input, step.pool, &bodies_, &w.solver_.manifolds(), &anchors_);
  step.pool->ParallelFor(w.rigid_pairs_.size(), kPairsPerChunk, [&](std::size_t m) {
    PrefetchAhead(w.rigid_pairs_, m, PrefetchFrictionAnchor);
    w.rigid_pairs_[m]->friction_anchor = anchors_[m];
  });
  StoreVelocities(step);
  w.DisableNonFiniteBodies();
  w.articulations_.Solve(step);
  w.reports_.ReportSolved(w.rigid_pairs_, step, /*impacts_only=*/false);
  w.articulations_.ReportContacts(step, &w.reports_);
}

// The touching pairs coloured (constraint_colouring.h) and put in colour
// order, before their manifolds are built: the manifolds, the rows and
// their blocks are then all in one order, and every pass of the sub-steps,
// the preparing and the store reads and writes the manifolds front to back.
// In the cache's order, each colour was a stride through the manifolds,
// which outgrow the cache in the big scenes (docs/performance.md, "The
// soft step's manifolds in colour order").
void SoftStepSolver::ColourPairs() {
  WorldImpl& w = world_;
  std::vector<ShapePairContact*>& pairs = w.rigid_pairs_;
  moving_mask_.assign(w.bodies_.size(), 0);
  for (const std::uint32_t i : w.moving_bodies_) moving_mask_[i] = 1;
  pair_body_a_.resize(pairs.size());
  pair_body_b_.resize(pairs.size());
  for (std::size_t m = 0; m < pairs.size(); ++m) {
    pair_body_a_[m] = pairs[m]->body_a;
    pair_body_b_[m] = pairs[m]->body_b;
  }
  ColourConstraints(pair_body_a_, pair_body_b_, moving_mask_, &colour_masks_, &colour_of_,
                    &colouring_);
  unordered_pairs_.swap(pairs);
  pairs.resize(unordered_pairs_.size());
  for (std::size_t k = 0; k < pairs.size(); ++k) pairs[k] = unordered_pairs_[colouring_.order[k]];
}

// A new support starts from the load it would carry at rest (the exact
// solver's estimate, SeedNewSupportLoads, spread over the points so that
// each body carries its load with no moment, BalanceNewSupports), both as
// its warm start and as its spring's preload: a stack spawned at rest then
// starts at its equilibrium, instead of sagging on unloaded springs while
// the load tracking catches up.
void SoftStepSolver::SeedNewSupports(const StepContext& step) {
  WorldImpl& w = world_;
  std::vector<SolverManifold>& manifolds = w.solver_.manifolds();
  const SupportBalanceInput input = SupportInputFor(w.bodies_, w.settings_, step.dt);
  const std::vector<UprightSupport> supports = SeedNewSupportLoads(input, &manifolds);
  BalanceNewSupports(input, supports, &manifolds);
  for (std::size_t m = 0; m < manifolds.size(); ++m) {
    if (!manifolds[m].new_pair) continue;
    for (int i = 0; i < manifolds[m].point_count; ++i) {
      manifolds[m].points[i].preload = manifolds[m].points[i].normal_impulse;
    }
  }
}

// The moving bodies with their velocities (the spin capped at
// max_turn_per_step, as the exact solver's) and their accelerations, which
// the sub-steps hold constant; the other bodies the contacts reach, as
// bodies the solve never moves.
void SoftStepSolver::LoadBodies(const StepContext& step) {
  WorldImpl& w = world_;
  bodies_.resize(w.bodies_.size());
  // The moving bodies are loaded on the pool below.
  for (const std::array<std::uint32_t, 2>& pair : w.solver_.manifold_bodies()) {
    for (const std::uint32_t i : pair) {
      if (WorldImpl::MovesThisStep(w.bodies_[i])) continue;
      bodies_[i] = SoftBody();
      bodies_[i].position = w.bodies_[i].position;
      bodies_[i].orientation = w.bodies_[i].orientation;
    }
  }
  const double max_spin = w.settings_.max_turn_per_step / step.dt;
  step.pool->ParallelFor(w.moving_bodies_.size(), kBodiesPerChunk, [&](std::size_t k) {
    const std::uint32_t i = w.moving_bodies_[k];
    Body& body = w.bodies_[i];
    SoftBody& soft = bodies_[i];
    soft = SoftBody();
    soft.position = body.position;
    soft.orientation = body.orientation;
    if (body.disabled) return;
    soft.linear_velocity = body.linear_velocity;
    soft.angular_velocity = body.angular_velocity;
    const double spin = soft.angular_velocity.norm();
    if (spin > max_spin) soft.angular_velocity *= max_spin / spin;
    soft.linear_acceleration = w.settings_.gravity + body.inverse_mass * body.force;
    soft.angular_acceleration = body.inverse_inertia_world * body.torque;
    body.force.setZero();
    body.torque.setZero();
    soft.inverse_mass = body.inverse_mass;
    soft.inverse_inertia_world = body.inverse_inertia_world;
    soft.reach = body.bounding_radius;
    soft.moving = true;
  });
}

// The end velocities as momenta, P = M v and L = I_world w, still about the
// start orientation: the pose is written by Integrate, after the
// articulations' solve has had its say on the bodies that touch a link.
void SoftStepSolver::StoreVelocities(const StepContext& step) {
  WorldImpl& w = world_;
  step.pool->ParallelFor(w.moving_bodies_.size(), kBodiesPerChunk, [&](std::size_t k) {
    Body& body = w.bodies_[w.moving_bodies_[k]];
    const SoftBody& soft = bodies_[w.moving_bodies_[k]];
    if (!soft.moving) return;
    body.linear_momentum = body.mass * soft.linear_velocity;
    body.angular_momentum = AngularMomentumFor(body, soft.angular_velocity);
    body.start_linear_velocity = soft.linear_velocity;
    body.start_angular_momentum = body.angular_momentum;
    body.pseudo_linear_velocity.setZero();
    body.pseudo_angular_velocity.setZero();
    body.UpdateDerived();
  });
}

// Each moving body takes the motion of its sub-steps. A body that touches a
// link drifts instead with the velocity the articulations' solve ended it
// with (and its split-impulse velocity), x += dt v, as the exact solver's
// pushed bodies do: that solve holds a gripped box at its fingers' velocity
// at the end of the step, and the sub-steps' drift, which lags that by
// (n - 1) / 2n g dt^2 each step, let the box slip out of a still grip. One
// that a link struck within the step drifts with its mean velocity over
// the step, before the impact and after it (StruckBodyMeanVelocity).
void SoftStepSolver::Integrate(const StepContext& step) {
  WorldImpl& w = world_;
  w.articulations_.Move();
  touches_link_.assign(w.bodies_.size(), 0);
  for (const ShapePairContact* pair : w.articulations_.link_pairs()) {
    touches_link_[pair->body_a] = 1;
    touches_link_[pair->body_b] = 1;
  }
  step.pool->ParallelFor(w.moving_bodies_.size(), kBodiesPerChunk, [&](std::size_t k) {
    const std::uint32_t i = w.moving_bodies_[k];
    Body& body = w.bodies_[i];
    const SoftBody& soft = bodies_[i];
    if (!soft.moving || body.disabled) return;
    const Vec3 angular_velocity = body.angular_velocity;
    Vec3 moved = soft.delta_position;
    Vec3 turn = Vec3::Zero();
    if (touches_link_[i]) {
      Vec3 linear = body.linear_velocity;
      Vec3 angular = angular_velocity;
      w.articulations_.StruckBodyMeanVelocity(i, step.dt, &linear, &angular);
      moved = step.dt * (linear + body.pseudo_linear_velocity);
      turn = step.dt * (angular + body.pseudo_angular_velocity);
    } else {
      body.orientation = (soft.delta_rotation * body.orientation).normalized();
    }
    body.position += moved;
    const double angle = turn.norm();
    if (angle > 0.0) {
      body.orientation =
          (Quat(Eigen::AngleAxisd(angle, turn / angle)) * body.orientation).normalized();
    }
    body.angular_momentum = AngularMomentumFor(body, angular_velocity);
    body.UpdateDerived();
    body.travel += touches_link_[i] ? moved.norm() + angle * body.bounding_radius : soft.travel;
  });
  w.DisableNonFiniteBodies();
  w.sleep_.Update(step, w.moving_bodies_);
}

}  // namespace rigid_body_sim::physics
