// Stage 5 of WorldImpl::Step: drift the bodies, back up the ones that would
// enter another body to their time of impact, and put quiet islands to sleep.
#include <algorithm>
#include <cmath>
#include <limits>
#include <variant>

#include "physics/integrator.h"
#include "physics/narrow_phase.h"
#include "physics/union_find.h"
#include "physics/world_impl.h"

namespace rigid_body_sim::physics {
namespace {

// Bisection stops when the bracket is shorter than this fraction of the step.
constexpr double kTimeOfImpactTolerance = 1e-6;

// Samples along a fast body's path, at most: 2 km/s against a 1 mm thick
// plate at 240 Hz.
constexpr double kMaxPathSamples = 1e4;

}  // namespace

// Time of impact by bracketing (Baraff, seed 000 slide 4 and seed 002
// "Backing up to the collision time"): with Y(t0) legal and Y(t0 + dt)
// penetrating, test a time inside the bracket and keep the part whose ends
// differ, until the legal end touches or the bracket is within tolerance.
// The test time is the regula falsi estimate from the two ends' gaps, with
// the midpoint (bisection) as its fallback. A body faster than a fraction
// of its thickness per step is first sampled along its path, so that a thin
// wall it would pass through entirely still shows a penetrating sample to
// bracket. Pairs that cannot close their gap within the step are skipped.
void WorldImpl::IntegrateBodies(double dt) {
  // Kept between steps, so that a step neither allocates nor clears a path
  // per body: outside this function every entry reads as a body that does
  // not move (dt 0, not fast, reach 0), whatever its other fields hold.
  std::vector<BodyPath>& paths = paths_;
  paths.resize(bodies_.size());
  for (const std::uint32_t i : moving_bodies_) {
    const Body& body = bodies_[i];
    if (!body.awake) continue;
    paths[i].start = body.WorldFromPrincipal();
    paths[i].start_velocity = body.start_linear_velocity;
    paths[i].end_velocity = body.linear_velocity;
    paths[i].pseudo_velocity = body.pseudo_linear_velocity;
    paths[i].dt = dt;
  }
  IntegratePositions(dt, moving_bodies_, &bodies_);
  DisableNonFiniteBodies();
  for (const std::uint32_t i : moving_bodies_) {
    if (bodies_[i].disabled) paths[i].dt = 0.0;
    if (paths[i].dt > 0.0) paths[i].end = bodies_[i].WorldFromPrincipal();
  }

  // Candidate pairs: a pair with no touching point at the start (a new
  // contact, which the solver has not seen), and every pair of a fast body.
  // Pairs already touching are the resting solver's.
  const double touching = settings_.solver.contact_tolerance;
  const double target_gap = 0.5 * touching;
  // Per body, once: whether it moves more than continuous_fraction of its
  // thickness (fast: sampled along its path), and how far any of its points
  // can move over the step, m. The centre's parabola never leaves the ball
  // of radius dt max(|v0|, |v1|) (the velocity is linear in t); add the
  // split-impulse drift and the slerp angle times the shapes' reach from
  // the centre.
  for (const std::uint32_t i : moving_bodies_) {
    BodyPath& path = paths[i];
    if (path.dt == 0.0) continue;
    const double angle = path.start.rotation.angularDistance(path.end.rotation);
    const double radius = bodies_[i].bounding_radius;
    const double displacement = (path.end.translation - path.start.translation).norm();
    path.fast =
        displacement + angle * radius > settings_.continuous_fraction * bodies_[i].thickness;
    path.reach = dt * (std::max(path.start_velocity.norm(), path.end_velocity.norm()) +
                       path.pseudo_velocity.norm()) +
                 angle * radius;
    bodies_[i].travel += path.reach;
  }
  // Each body is backed up to its own earliest impact. Backing up whole
  // groups of linked impacts instead would let one grazing pair hold every
  // body of a pile at the start of its step, step after step.
  std::vector<double> impact_time(bodies_.size(), std::numeric_limits<double>::infinity());
  const std::vector<ShapePairContact*>& seen = contact_cache_.seen();
  for (std::size_t e = 0; e < seen.size(); ++e) {
    PrefetchAhead(seen, e, PrefetchManifold);
    ShapePairContact* pair = seen[e];
    // The gap at the start: the nearest point of the manifold, or, with no
    // point, at least the distance the narrow phase looked within, and at
    // least the narrow phase's separating-axis gap less what the bodies
    // travelled between that test and the start of this step.
    const double travel_since = bodies_[pair->body_a].travel - paths[pair->body_a].reach +
                                bodies_[pair->body_b].travel - paths[pair->body_b].reach -
                                pair->apart_travel;
    double start_gap = std::max(pair->contact_distance, pair->apart_gap - travel_since);
    for (int i = 0; i < pair->manifold.point_count; ++i) {
      start_gap = std::min(start_gap, pair->manifold.points[i].separation);
    }
    const bool fast = paths[pair->body_a].fast || paths[pair->body_b].fast;
    if (start_gap <= touching && !fast) continue;
    if (bodies_[pair->body_a].disabled || bodies_[pair->body_b].disabled) continue;
    // Two bodies that cannot close their gap within the step need no search
    // (a reused manifold's gap is known to within its reuse error).
    const double reach = paths[pair->body_a].reach + paths[pair->body_b].reach;
    if (start_gap - pair->reuse_error - reach > target_gap) continue;
    const Body& a = bodies_[pair->body_a];
    const Body& b = bodies_[pair->body_b];
    const ShapeDef& shape_a = a.shapes[pair->shape_a];
    const ShapeDef& shape_b = b.shapes[pair->shape_b];
    auto pose_at = [&](std::uint32_t index, const Body& body, double t) {
      const Pose world_from_principal =
          paths[index].dt > 0.0 ? paths[index].At(t) : body.WorldFromPrincipal();
      return world_from_principal * body.principal_from_body;
    };
    // The gap at time t: the nearest manifold point, capped at a distance
    // beyond anything the step can reach.
    auto input_at = [&](double t, double contact_distance) {
      CollideInput input;
      input.a = &shape_a.geometry;
      input.world_from_a = pose_at(pair->body_a, a, t) * shape_a.body_from_shape;
      input.b = &shape_b.geometry;
      input.world_from_b = pose_at(pair->body_b, b, t) * shape_b.body_from_shape;
      input.contact_distance = contact_distance;
      return input;
    };
    const double gap_cap = std::max(start_gap, 0.0) + reach + settings_.contact_margin;
    auto gap_at = [&](double t) {
      ContactManifold manifold;
      double gap = gap_cap;
      if (Collide(input_at(t, gap_cap), nullptr, &manifold)) {
        for (int i = 0; i < manifold.point_count; ++i) {
          gap = std::min(gap, manifold.points[i].separation);
        }
      }
      return gap;
    };
    int samples = 1;
    if (fast) {
      double motion = 0.0;
      for (const std::uint32_t index : {pair->body_a, pair->body_b}) {
        if (paths[index].dt == 0.0) continue;
        motion = std::max(motion,
                          (paths[index].end.translation - paths[index].start.translation).norm() /
                              (settings_.continuous_fraction * bodies_[index].thickness));
      }
      samples = static_cast<int>(std::clamp(std::ceil(motion), 1.0, kMaxPathSamples));
    }
    double low = 0.0;
    double gap_low = start_gap;
    if (gap_low <= target_gap) continue;  // already in contact: the solver's business
    // Most pairs that get here end the step still apart, such as boxes side
    // by side with a gap below their manifold's reuse error. Asking only
    // whether they are apart by more than target_gap at the end lets the
    // pair's cached separating axis answer, a lower bound on the distance,
    // in a fraction of a full test (seed 000 slide 13).
    if (samples == 1) {
      SeparatingWitness witness = pair->witness;
      ContactManifold manifold;
      if (!Collide(input_at(dt, target_gap), &witness, &manifold)) continue;
    }
    double high = -1.0;
    double gap_high = 0.0;
    for (int k = 1; k <= samples; ++k) {
      const double t = dt * k / samples;
      const double gap = gap_at(t);
      if (gap <= target_gap) {
        high = t;
        gap_high = gap;
        break;
      }
      low = t;
      gap_low = gap;
    }
    if (high < 0.0) continue;
    // The pair is about to touch: next step clips it afresh, so that the
    // solver and this search see the same gap (a reused manifold's can be
    // off by its reuse error, and a pair backed up to t = 0 again and
    // again would never reach the solver).
    pair->anchors.valid = false;
    // Regula falsi on gap(t) = aim, keeping the bracket gap(low) >
    // target_gap >= gap(high) (Illinois: the end kept twice in a row has its
    // value halved, so it converges superlinearly instead of creeping). It
    // ends when `low` is within a tenth of the touching band above
    // target_gap, so the free flight is cut short by at most that much, or
    // when the bracket is within tolerance, as plain bisection would.
    const double close_enough = target_gap + 0.1 * (touching - target_gap);
    const double aim = target_gap + 0.05 * (touching - target_gap);
    int kept_side = 0;  // -1: low was kept last time, +1: high
    double weight_low = 1.0;
    double weight_high = 1.0;
    while (gap_low > close_enough && high - low > kTimeOfImpactTolerance * dt) {
      const double f_low = weight_low * (gap_low - aim);
      const double f_high = weight_high * (gap_high - aim);
      double t = low + (high - low) * f_low / (f_low - f_high);
      if (!(t > low && t < high)) t = 0.5 * (low + high);
      const double gap = gap_at(t);
      if (gap > target_gap) {
        low = t;
        gap_low = gap;
        weight_low = 1.0;
        weight_high = kept_side == 1 ? 0.5 * weight_high : 1.0;
        kept_side = 1;
      } else {
        high = t;
        gap_high = gap;
        weight_high = 1.0;
        weight_low = kept_side == -1 ? 0.5 * weight_low : 1.0;
        kept_side = -1;
      }
    }
    impact_time[pair->body_a] = std::min(impact_time[pair->body_a], low);
    impact_time[pair->body_b] = std::min(impact_time[pair->body_b], low);
  }
  for (const std::uint32_t i : moving_bodies_) {
    const double time = impact_time[i];
    if (!std::isfinite(time) || paths[i].dt == 0.0) continue;
    Body& body = bodies_[i];
    const Pose pose = paths[i].At(time);
    body.position = pose.translation;
    body.orientation = pose.rotation.normalized();
    body.linear_momentum = body.mass * paths[i].VelocityAt(time);
    body.UpdateDerived();
    body.start_linear_velocity = body.linear_velocity;
  }
  for (const std::uint32_t i : moving_bodies_) {
    paths[i].dt = 0.0;
    paths[i].fast = false;
    paths[i].reach = 0.0;
  }
  UpdateSleep(dt);
}

// Only moving bodies change state within a step, so only they are checked.
void WorldImpl::DisableNonFiniteBodies() {
  for (const std::uint32_t i : moving_bodies_) {
    Body& body = bodies_[i];
    if (!body.in_use || body.is_static || body.disabled || body.HasFiniteState()) continue;
    body.disabled = true;
    body.awake = false;
    woke_since_prune_ = true;
    if (body.has_proxy) {
      broad_phase_.RemoveProxy(static_cast<int>(i));
      body.has_proxy = false;
    }
    // Its cached pairs are no longer seen from the next step on, and go.
    non_finite_bodies_.push_back(BodyId{i, body.generation});
  }
}

// Whether a body has kept speeding up for sleep.speeding_up_time. Slow is
// not at rest: a box on a slope 0.2 degrees steeper than its friction angle
// accelerates at 0.04 m/s^2 and stays below 0.05 m/s for 1.3 s, long enough
// to fall asleep mid-slide. A settling body's speed rises and falls from
// step to step; one getting under way gains speed at every step. Speeds
// below 2 % of the sleep thresholds are noise: the residual velocities of a
// stack at rest can grow steadily without going anywhere, and counted, they
// kept the benchmark's pyramids awake.
bool WorldImpl::UpdateSpeedingUp(double dt, Body* body) const {
  constexpr double kNoiseFraction = 0.02;
  const SleepSettings& sleep = settings_.sleep;
  const double speed = body->linear_velocity.norm();
  const double angular_speed = body->angular_velocity.norm();
  const bool gaining =
      (speed > body->last_speed && speed > kNoiseFraction * sleep.linear_velocity) ||
      (angular_speed > body->last_angular_speed &&
       angular_speed > kNoiseFraction * sleep.angular_velocity);
  body->last_speed = speed;
  body->last_angular_speed = angular_speed;
  body->speeding_up_time = gaining ? body->speeding_up_time + dt : 0.0;
  return sleep.speeding_up_time > 0.0 && body->speeding_up_time >= sleep.speeding_up_time;
}

// Islands are the connected components of the contact graph through moving
// bodies (union-find). An island sleeps when every body in it has been slower
// than the thresholds, and not speeding up, for time_to_sleep; it costs
// nothing until woken.
void WorldImpl::UpdateSleep(double dt) {
  const SleepSettings& sleep = settings_.sleep;
  if (!sleep.enabled) return;
  UnionFind islands(bodies_.size());
  for (const ShapePairContact* pair : contact_cache_.touching()) {
    const Body& a = bodies_[pair->body_a];
    const Body& b = bodies_[pair->body_b];
    if (a.is_static || b.is_static) continue;
    islands.Join(pair->body_a, pair->body_b);
  }
  std::vector<double> island_sleep_time(bodies_.size(), std::numeric_limits<double>::infinity());
  for (const std::uint32_t i : moving_bodies_) {
    Body& body = bodies_[i];
    if (!body.awake) continue;
    const bool speeding_up = UpdateSpeedingUp(dt, &body);
    const bool slow =
        !speeding_up &&
        body.linear_velocity.squaredNorm() < sleep.linear_velocity * sleep.linear_velocity &&
        body.angular_velocity.squaredNorm() < sleep.angular_velocity * sleep.angular_velocity;
    body.sleep_time = slow ? body.sleep_time + dt : 0.0;
    double& island = island_sleep_time[islands.Find(i)];
    island = std::min(island, body.sleep_time);
  }
  for (const std::uint32_t i : moving_bodies_) {
    Body& body = bodies_[i];
    if (!body.awake) continue;
    if (island_sleep_time[islands.Find(i)] < sleep.time_to_sleep) continue;
    body.awake = false;
    body.linear_momentum.setZero();
    body.angular_momentum.setZero();
    body.UpdateDerived();
  }
}

}  // namespace rigid_body_sim::physics
