// Stage 4 of WorldImpl::Step, in Baraff's order: colliding contacts get impulses
// on the velocities the step starts with; then gravity and the applied
// forces act; then resting contacts get the impulses that keep them apart.
#include <algorithm>
#include <cassert>
#include <cmath>

#include "physics/collision/mesh_collision.h"
#include "physics/dynamics/integrator.h"
#include "physics/solver/support_balance.h"
#include "physics/world/world_impl.h"

namespace rigid_body_sim::physics {
namespace {

// Manifolds a thread takes at a time when the solver manifolds are built
// and the contacts reported on the pool.
constexpr std::size_t kManifoldsPerChunk = 256;

}  // namespace

// A support that is new this step (a pair that had no contact point last
// step, and touches at every point now) starts the resting solve from the
// load it would carry at rest, instead of from zero. Statics of a stack,
// from the highest body down: a body's load is its weight m g dt plus the
// loads resting on it; the part its warm supports do not carry already
// (their impulses n / (n.up)) is shared equally by its new supports, whose
// points take the normal part n.up of their share; each support passes its
// load to the body below. Without it, Gauss-Seidel sweeps from zero move a
// load up a stack by about one level per sweep, so a stack spawned at rest
// sags and rocks for its first tenth of a second. The estimate is only
// where the iteration starts: the complementarity conditions, and so the
// solution, are the same. Returns the upright supports it walked (none when
// no support is new), for the soft step's spread.
std::vector<UprightSupport> WorldImpl::SeedNewSupportLoads(const StepContext& step) {
  const double g = settings_.gravity.norm();
  if (g <= 0.0) return {};
  std::vector<SolverManifold>& manifolds = solver_.manifolds();
  std::vector<UprightSupport> supports = UprightSupportsHighestFirst(SupportInput(step), manifolds);
  if (supports.empty()) return supports;
  // N s: a body's load; then, from its first support on, what its new
  // supports share.
  std::vector<double> load(bodies_.size(), 0.0);
  std::vector<int> new_supports(bodies_.size(), 0);
  for (const UprightSupport& support : supports) {
    load[support.upper] = bodies_[support.upper].mass * g * step.dt;
    if (support.is_new) ++new_supports[support.upper];
  }
  auto warm_load = [&](const UprightSupport& support) {
    const SolverManifold& manifold = manifolds[support.manifold];
    double normal = 0.0;
    for (int i = 0; i < manifold.point_count; ++i) normal += manifold.points[i].normal_impulse;
    return normal / support.up_along_normal;
  };
  for (std::size_t k = 0; k < supports.size(); ++k) {
    const std::uint32_t upper = supports[k].upper;
    if (k == 0 || supports[k - 1].upper != upper) {
      for (std::size_t w = k; w < supports.size() && supports[w].upper == upper; ++w) {
        if (!supports[w].is_new) load[upper] -= warm_load(supports[w]);
      }
      load[upper] = std::max(load[upper], 0.0);
    }
    const UprightSupport& support = supports[k];
    double passed = 0.0;
    if (!support.is_new) {
      passed = warm_load(support);
    } else if (CarriesLoad(bodies_[upper])) {
      passed = load[upper] / new_supports[upper];
      SolverManifold& manifold = manifolds[support.manifold];
      const double per_point = passed * support.up_along_normal / manifold.point_count;
      for (int i = 0; i < manifold.point_count; ++i) manifold.points[i].normal_impulse = per_point;
    }
    if (CarriesLoad(bodies_[support.lower])) load[support.lower] += passed;
  }
  return supports;
}

SupportBalanceInput WorldImpl::SupportInput(const StepContext& step) const {
  SupportBalanceInput input;
  input.bodies = &bodies_;
  input.gravity = settings_.gravity;
  input.dt = step.dt;
  input.contact_tolerance = settings_.solver.contact_tolerance;
  return input;
}

// The bodies that move this step; the stages from here on visit only them,
// so sleeping bodies cost nothing.
void WorldImpl::ListMovingBodies() {
  moving_bodies_.clear();
  for (std::uint32_t i = 0; i < bodies_.size(); ++i) {
    if (MovesThisStep(bodies_[i])) moving_bodies_.push_back(i);
  }
}

// One solver manifold per touching pair, with its points' lever arms,
// combined materials and last step's impulses.
void WorldImpl::BuildSolverManifolds(const std::vector<ShapePairContact*>& pairs,
                                     const StepContext& step) {
  std::vector<SolverManifold>& manifolds = solver_.manifolds();
  // Resized, not cleared (ContactSolver::Reset keeps them): a manifold with
  // its four points is 648 bytes, and each is built afresh below, on the pool.
  manifolds.resize(pairs.size());
  std::vector<std::array<std::uint32_t, 2>>& manifold_bodies = solver_.manifold_bodies();
  manifold_bodies.resize(pairs.size());
  step.pool->ParallelFor(pairs.size(), kManifoldsPerChunk, [&](std::size_t m) {
    PrefetchAhead(pairs, m, PrefetchPoints);
    const ShapePairContact* pair = pairs[m];
    manifold_bodies[m] = {pair->body_a, pair->body_b};
    const Body& a = bodies_[pair->body_a];
    const Body& b = bodies_[pair->body_b];
    // Reset field by field: assigning a fresh SolverManifold built all four
    // points (648 bytes) and copied them. Points past point_count keep an
    // earlier step's values; nothing reads them.
    SolverManifold& manifold = manifolds[m];
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
