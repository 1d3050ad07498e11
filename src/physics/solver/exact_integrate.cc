// The exact solver's stage 5: the bodies drift over the step, and a body
// that would enter another within it is backed up to its time of impact
// (exact_impacts.cc resolves the impact and simulates the rest of the step).
#include <algorithm>
#include <cmath>
#include <limits>
#include <variant>

#include "physics/collision/narrow_phase.h"
#include "physics/dynamics/integrator.h"
#include "physics/dynamics/time_of_impact.h"
#include "physics/geometry/shape_bounds.h"
#include "physics/solver/exact_solver.h"
#include "physics/world/world_impl.h"

namespace rigid_body_sim::physics {
namespace {

// Samples along a fast body's path, at most: 2 km/s against a 1 mm thick
// plate at 240 Hz.
constexpr double kMaxPathSamples = 1e4;

// One pair's shapes carried along their bodies' paths over the step.
struct PairSweep {
  const BodyPath* path_a = nullptr;
  const Body* a = nullptr;
  const BodyPath* path_b = nullptr;
  const Body* b = nullptr;
  int shape_a = 0;
  int shape_b = 0;
  double gap_cap = 0.0;  // m, beyond anything the step can reach
  // m, the radii of spheres about the two shapes' origins that hold them;
  // infinite for a half-space.
  double radius_a = 0.0;
  double radius_b = 0.0;

  static Pose WorldFromBodyAt(const BodyPath& path, const Body& body, double t) {
    const Pose world_from_principal = path.dt > 0.0 ? path.At(t) : body.WorldFromPrincipal();
    return world_from_principal * body.principal_from_body;
  }
  CollideInput InputAt(double t, double contact_distance) const {
    const ShapeDef& shape_def_a = a->shapes[shape_a];
    const ShapeDef& shape_def_b = b->shapes[shape_b];
    CollideInput input;
    input.a = &shape_def_a.geometry;
    input.world_from_a = WorldFromBodyAt(*path_a, *a, t) * shape_def_a.body_from_shape;
    input.b = &shape_def_b.geometry;
    input.world_from_b = WorldFromBodyAt(*path_b, *b, t) * shape_def_b.body_from_shape;
    input.contact_distance = contact_distance;
    return input;
  }
  // A lower bound on the gap at time t, from the two shapes' bounding
  // spheres: a test of a few flops that lets the search skip the samples of
  // a fast body's path far from the other body, where a full test (a
  // cylinder against a hull of many edges) would cost thousands of times
  // more.
  double SphereGapAt(double t) const {
    const Vec3 a_world =
        WorldFromBodyAt(*path_a, *a, t) * a->shapes[shape_a].body_from_shape.translation;
    const Vec3 b_world =
        WorldFromBodyAt(*path_b, *b, t) * b->shapes[shape_b].body_from_shape.translation;
    return (a_world - b_world).norm() - radius_a - radius_b;
  }
  // The gap at time t: the nearest manifold point, at most gap_cap.
  double GapAt(double t) const { return Gap(InputAt(t, gap_cap)); }
};

// m; the radius of a sphere about the shape's origin that holds it.
double ShapeRadius(const ShapeGeometry& geometry) {
  if (std::holds_alternative<HalfSpace>(geometry)) return std::numeric_limits<double>::infinity();
  return ShapeBoundingRadius(geometry, Vec3::Zero());
}

}  // namespace

// Time of impact by bracketing (Baraff 1997, "Rigid Body
// Simulation II", section 6, backing up to the collision time t_c): with Y(t0) legal and Y(t0 + dt)
// penetrating, test a time inside the bracket and keep the part whose ends
// differ, until the legal end touches or the bracket is within tolerance.
// The test time is the regula falsi estimate from the two ends' gaps, with
// the midpoint (bisection) as its fallback. A body faster than a fraction
// of its thickness per step is first sampled along its path, so that a thin
// wall it would pass through entirely still shows a penetrating sample to
// bracket. Pairs that cannot close their gap within the step are skipped.
void ExactSolver::IntegrateBodies(const StepContext& step) {
  world_.articulations_.Move();
  DriftBodies(step);
  BoundBodyMotion(step);
  ResolveImpacts(step, FindImpacts(step, world_.contact_cache_.seen()),
                 world_.contact_cache_.touching(), 0);
  world_.sleep_.Update(step, world_.moving_bodies_);
}

// Scales a moving body's angular momenta (at the start and the end of the
// step) so that its angular velocity turns it at most max_turn_per_step in
// dt: |w| <= max_turn / dt with w = I^-1 L. The scale keeps the spin's axis;
// it only takes energy out, and only from spins no step resolves.
void ExactSolver::CapSpin(const StepContext& step) {
  const double max_speed = world_.settings_.max_turn_per_step / step.dt;
  for (const std::uint32_t i : world_.moving_bodies_) {
    Body& body = world_.bodies_[i];
    if (!body.awake || body.disabled) continue;
    const double end_speed = body.angular_velocity.norm();
    const double start_speed = (body.inverse_inertia_world * body.start_angular_momentum).norm();
    // A NaN speed fails both tests and passes on to the step guard as is.
    if (end_speed > max_speed) {
      body.angular_momentum *= max_speed / end_speed;
      body.UpdateDerived();
    }
    if (start_speed > max_speed) body.start_angular_momentum *= max_speed / start_speed;
  }
}

// The awake bodies drift over the step; each one's path (start, end and
// velocities) is kept for the time-of-impact search. paths_ is kept between
// steps, so that a step neither allocates nor clears a path per body.
void ExactSolver::DriftBodies(const StepContext& step) {
  CapSpin(step);
  paths_.resize(world_.bodies_.size());
  for (const std::uint32_t i : world_.moving_bodies_) {
    const Body& body = world_.bodies_[i];
    if (!body.awake) continue;
    BodyPath& path = paths_[i];
    path.start = body.WorldFromPrincipal();
    path.start_velocity = body.start_linear_velocity;
    path.end_velocity = body.linear_velocity;
    path.pseudo_velocity = body.pseudo_linear_velocity;
    path.dt = step.dt;
  }
  IntegratePositions(step.dt, world_.moving_bodies_, &world_.bodies_);
  world_.DisableNonFiniteBodies();
  for (const std::uint32_t i : world_.moving_bodies_) {
    if (world_.bodies_[i].disabled) paths_[i].dt = 0.0;
    BodyPath& path = paths_[i];
    if (path.dt == 0.0) continue;
    path.end = world_.bodies_[i].WorldFromPrincipal();
    path.turn = TurnBetween(path.start.rotation, path.end.rotation,
                            step.dt * world_.bodies_[i].angular_velocity);
  }
}

// Per body, once: whether it moves more than continuous_fraction of its
// thickness (fast: sampled along its path), and how far any of its points
// can move over the step, m. The centre's parabola never leaves the ball of
// radius dt max(|v0|, |v1|) (the velocity is linear in t); add the
// split-impulse drift and the slerp angle times the shapes' reach from the
// centre.
void ExactSolver::BoundBodyMotion(const StepContext& step) {
  for (const std::uint32_t i : world_.moving_bodies_) {
    BodyPath& path = paths_[i];
    if (path.dt == 0.0) continue;
    const double angle = path.turn.norm();
    const double radius = world_.bodies_[i].bounding_radius;
    const double displacement = (path.end.translation - path.start.translation).norm();
    path.fast = displacement + angle * radius >
                world_.settings_.continuous_fraction * world_.bodies_[i].thickness;
    path.reach = step.dt * (std::max(path.start_velocity.norm(), path.end_velocity.norm()) +
                            path.pseudo_velocity.norm()) +
                 angle * radius;
    world_.bodies_[i].travel += path.reach;
  }
}

// Candidate pairs: a pair with no touching point at the start (a new
// contact, which the solver has not seen), and every pair of a fast body;
// pairs already touching are the resting solver's.
// Each pair's search reads the bodies and their paths and writes only its
// own entry, so the pairs are searched on the pool, and the impacts listed
// afterwards in the pairs' order: the same list for any number of threads.
std::vector<Impact> ExactSolver::FindImpacts(const StepContext& step,
                                             const std::vector<ShapePairContact*>& pairs) {
  // A pair's search costs 0.1-10 us; a chunk this long amortizes taking it.
  constexpr std::size_t kPairsPerChunk = 64;
  impact_searches_.resize(pairs.size());
  step.pool->ParallelFor(pairs.size(), kPairsPerChunk, [&](std::size_t e) {
    PrefetchAhead(pairs, e, PrefetchManifold);
    ShapePairContact* pair = pairs[e];
    ImpactSearch& search = impact_searches_[e];
    search.time = std::numeric_limits<double>::infinity();
    if (paths_[pair->body_a].dt == 0.0 && paths_[pair->body_b].dt == 0.0) return;
    // A link's contacts are the articulation solve's, which lets no point
    // close more than its gap within a step.
    if (world_.bodies_[pair->body_a].articulation >= 0 ||
        world_.bodies_[pair->body_b].articulation >= 0) {
      return;
    }
    search.time = PairImpactTime(step, pair, &search.approach_speed);
  });
  std::vector<Impact> impacts;
  for (std::size_t e = 0; e < pairs.size(); ++e) {
    const ImpactSearch& search = impact_searches_[e];
    if (!std::isfinite(search.time)) continue;
    const bool colliding =
        search.approach_speed > world_.settings_.solver.collision_velocity_threshold;
    impacts.push_back(Impact{pairs[e], search.time, colliding});
  }
  return impacts;
}

// The pair's gap at the start of the step: the nearest point of the
// manifold, or, with no point, at least the distance the narrow phase
// looked within, and at least the narrow phase's separating-axis gap less
// what the bodies travelled between that test and the start of this step.
double ExactSolver::PairStartGap(const ShapePairContact& pair) const {
  const double travel_since = world_.bodies_[pair.body_a].travel - paths_[pair.body_a].reach +
                              world_.bodies_[pair.body_b].travel - paths_[pair.body_b].reach -
                              pair.apart_travel;
  double start_gap = std::max(pair.contact_distance, pair.apart_gap - travel_since);
  for (int i = 0; i < pair.manifold.point_count; ++i) {
    start_gap = std::min(start_gap, pair.manifold.points[i].separation);
  }
  return start_gap;
}

// The time within the step at which the pair comes within the touching band,
// or +infinity when it does not or is already in contact.
double ExactSolver::PairImpactTime(const StepContext& step, ShapePairContact* pair,
                                   double* approach_speed) {
  constexpr double kNoImpact = std::numeric_limits<double>::infinity();
  *approach_speed = 0.0;
  double touching = world_.settings_.solver.contact_tolerance;
  // The search stops within 5 % of the touching band above the surface, so
  // the speed at the impact is free fall's to g (0.05 epsilon) / v^2:
  // 2.6e-7 of it after a 1 m drop.
  double target_gap = 0.05 * touching;
  const BodyPath& path_a = paths_[pair->body_a];
  const BodyPath& path_b = paths_[pair->body_b];
  const double start_gap = PairStartGap(*pair);
  const bool fast = path_a.fast || path_b.fast;
  if (start_gap <= touching && !fast) return kNoImpact;
  if (world_.bodies_[pair->body_a].disabled || world_.bodies_[pair->body_b].disabled)
    return kNoImpact;
  if (start_gap <= touching) {
    // Already in contact, and fast (a small body spinning on a corner): the
    // solver holds the points it touches at, and the search only keeps
    // another feature from passing through the other body. Backing up to
    // the first touch of a feature would return t = 0 step after step and
    // freeze the body in place with its velocity. The depth allowed is the
    // motion per sample of a fast body, so nothing thicker than four times
    // it can be passed through.
    const double depth = world_.settings_.continuous_fraction * PairThickness(*pair);
    touching = start_gap - 0.5 * depth;
    target_gap = start_gap - depth;
  }
  // Two bodies that cannot close their gap within the step need no search
  // (a reused manifold's gap is known to within its reuse error).
  const double reach = path_a.reach + path_b.reach;
  if (start_gap - pair->reuse_error - reach > target_gap) return kNoImpact;
  if (start_gap <= target_gap) return kNoImpact;  // already in contact: the solver's business
  const PairSweep sweep{&paths_[pair->body_a],
                        &world_.bodies_[pair->body_a],
                        &paths_[pair->body_b],
                        &world_.bodies_[pair->body_b],
                        pair->shape_a,
                        pair->shape_b,
                        std::max(start_gap, 0.0) + reach + world_.settings_.contact_margin,
                        ShapeRadius(world_.bodies_[pair->body_a].shapes[pair->shape_a].geometry),
                        ShapeRadius(world_.bodies_[pair->body_b].shapes[pair->shape_b].geometry)};
  // Most pairs that get here end the step still apart, such as boxes side
  // by side with a gap below their manifold's reuse error. Asking only
  // whether they are apart by more than target_gap at the end lets the
  // pair's cached separating axis answer, a lower bound on the distance, in
  // a fraction of a full test (Baraff 1997, "Rigid Body Simulation II",
  // section 7.1, the cached separating plane).
  const int samples = fast ? PathSamples(pair->body_a, pair->body_b) : 1;
  if (samples == 1) {
    SeparatingWitness witness = pair->witness;
    ContactManifold manifold;
    if (!Collide(sweep.InputAt(step.dt, target_gap), &witness, &manifold)) return kNoImpact;
  }
  ImpactBracket bracket{0.0, start_gap, -1.0, 0.0};
  for (int k = 1; k <= samples; ++k) {
    const double t = step.dt * k / samples;
    const double bound = sweep.SphereGapAt(t);
    const double gap = bound > target_gap ? bound : sweep.GapAt(t);
    if (gap <= target_gap) {
      bracket.high = t;
      bracket.gap_high = gap;
      break;
    }
    bracket.low = t;
    bracket.gap_low = gap;
  }
  if (bracket.high < 0.0) return kNoImpact;
  // The pair is about to touch: next step clips it afresh, so that the
  // solver and this search see the same gap (a reused manifold's can be off
  // by its reuse error, and a pair backed up to t = 0 again and again would
  // never reach the solver).
  pair->anchors.valid = false;
  bracket = NarrowImpactBracket([&sweep](double t) { return sweep.GapAt(t); },
                                ImpactTarget{target_gap, touching}, step.dt, bracket);
  // The gap's rate over the final bracket: the speed the surfaces meet at.
  *approach_speed = (bracket.gap_low - bracket.gap_high) / (bracket.high - bracket.low);
  return bracket.low;
}

// m; the thinner moving body of the pair (a static one never moves through
// anything).
double ExactSolver::PairThickness(const ShapePairContact& pair) const {
  double thickness = std::numeric_limits<double>::infinity();
  for (const std::uint32_t index : {pair.body_a, pair.body_b}) {
    if (paths_[index].dt > 0.0) thickness = std::min(thickness, world_.bodies_[index].thickness);
  }
  return thickness;
}

// Samples along the faster body's path, so that no sample moves it more than
// continuous_fraction of its thickness.
int ExactSolver::PathSamples(std::uint32_t body_a, std::uint32_t body_b) const {
  double motion = 0.0;
  for (const std::uint32_t index : {body_a, body_b}) {
    const BodyPath& path = paths_[index];
    if (path.dt == 0.0) continue;
    const double displacement = (path.end.translation - path.start.translation).norm() +
                                path.turn.norm() * world_.bodies_[index].bounding_radius;
    motion = std::max(motion, displacement / (world_.settings_.continuous_fraction *
                                              world_.bodies_[index].thickness));
  }
  return static_cast<int>(std::clamp(std::ceil(motion), 1.0, kMaxPathSamples));
}

}  // namespace rigid_body_sim::physics
