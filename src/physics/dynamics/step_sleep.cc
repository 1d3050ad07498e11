// Stage 5's end, for both solvers: bodies whose state is not finite are
// disabled, and quiet islands are put to sleep.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "physics/dynamics/integrator.h"
#include "physics/world/union_find.h"
#include "physics/world/world_impl.h"

namespace rigid_body_sim::physics {

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

// Whether a body has kept speeding up for sleep.speeding_up_time. Slow is
// not at rest: a box on a slope 0.2 degrees steeper than its friction angle
// accelerates at 0.04 m/s^2 and stays below 0.05 m/s for 1.3 s, long enough
// to fall asleep mid-slide. A settling body's speed rises and falls from
// step to step; one getting under way gains speed at every step. Speeds
// below 2 % of the sleep thresholds are noise: the residual velocities of a
// stack at rest can grow steadily without going anywhere, and counted, they
// kept the benchmark's pyramids awake.
bool WorldImpl::UpdateSpeedingUp(const StepContext& step, Body* body) const {
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
  body->speeding_up_time = gaining ? body->speeding_up_time + step.dt : 0.0;
  return sleep.speeding_up_time > 0.0 && body->speeding_up_time >= sleep.speeding_up_time;
}

// How long an awake body has been quiet (slow and not speeding up, or
// within its sleep window), s; 0 in an island with a link. It updates the
// body's sleep_time and speed history and its sleep window.
double WorldImpl::QuietTime(const StepContext& step, const SleepWindowLimits& limits,
                            bool island_has_link, std::uint32_t i) {
  const SleepSettings& sleep = settings_.sleep;
  Body& body = bodies_[i];
  if (!body.awake) return std::numeric_limits<double>::infinity();
  const bool speeding_up = UpdateSpeedingUp(step, &body);
  if (island_has_link) {
    // Held by, resting on or pushed by a link: its quiet time starts
    // over, so that once the link lets go it must be quiet for
    // time_to_sleep again; counted on, a box held still for a second fell
    // asleep in mid-air the step the gripper opened.
    body.sleep_time = 0.0;
    RestartSleepWindow(i);
    return 0.0;
  }
  const bool slow =
      !speeding_up &&
      body.linear_velocity.squaredNorm() < sleep.linear_velocity * sleep.linear_velocity &&
      body.angular_velocity.squaredNorm() < sleep.angular_velocity * sleep.angular_velocity;
  body.sleep_time = slow ? body.sleep_time + step.dt : 0.0;
  // Slow for long enough, or gone nowhere for long enough (sleep_window.h).
  if (speeding_up) RestartSleepWindow(i);
  const double still_time =
      UpdateSleepWindow(body.WorldFromPrincipal(), limits, step.dt, &sleep_windows_[i]);
  return std::max(body.sleep_time, still_time);
}

// Islands are the connected components of the contact graph through moving
// bodies (union-find). An island sleeps when every body in it has been slower
// than the thresholds, or has kept within its sleep window, and not speeding
// up, for time_to_sleep; it costs nothing until woken.
void WorldImpl::UpdateSleep(const StepContext& step) {
  const SleepSettings& sleep = settings_.sleep;
  if (!sleep.enabled) return;
  // The islands' scratch keeps its memory from step to step.
  UnionFind& islands = sleep_scratch_.islands;
  islands.Reset(bodies_.size());
  // The touching pairs' bodies come from their keys (no entry is loaded);
  // whether each joins an island is read on the pool (each body a load the
  // caches no longer hold), and the joins are made here from the list.
  const std::vector<std::array<std::uint32_t, 2>>& touching = contact_cache_.touching_bodies();
  std::vector<std::array<std::uint32_t, 2>>& edges = sleep_scratch_.edges;
  edges.resize(touching.size());
  constexpr std::size_t kPairsPerChunk = 256;
  step.pool->ParallelFor(touching.size(), kPairsPerChunk, [&](std::size_t m) {
    const std::uint32_t a = touching[m][0];
    const std::uint32_t b = touching[m][1];
    const bool joins = !bodies_[a].is_static && !bodies_[b].is_static;
    edges[m] = joins ? std::array<std::uint32_t, 2>{a, b} : std::array<std::uint32_t, 2>{a, a};
  });
  for (const std::array<std::uint32_t, 2>& edge : edges) {
    if (edge[0] != edge[1]) islands.Join(edge[0], edge[1]);
  }
  // Articulations never sleep, nor does what touches them.
  std::vector<char>& island_has_link = sleep_scratch_.island_has_link;
  island_has_link.assign(bodies_.size(), 0);
  for (const ShapePairContact* pair : articulations_.link_pairs()) {
    for (const std::uint32_t index : {pair->body_a, pair->body_b}) {
      if (bodies_[index].articulation >= 0) island_has_link[islands.Find(index)] = 1;
    }
  }
  std::vector<double>& island_sleep_time = sleep_scratch_.island_sleep_time;
  island_sleep_time.assign(bodies_.size(), std::numeric_limits<double>::infinity());
  sleep_windows_.resize(bodies_.size());
  // Each moving body's island, found here because Find compresses paths;
  // then each body's quiet time on the pool (it reads and writes only its
  // own body and window), and each island's, their least, here.
  std::vector<std::uint32_t>& root = sleep_scratch_.root;
  std::vector<double>& quiet_time = sleep_scratch_.quiet_time;
  root.resize(moving_bodies_.size());
  quiet_time.resize(moving_bodies_.size());
  for (std::size_t k = 0; k < moving_bodies_.size(); ++k) root[k] = islands.Find(moving_bodies_[k]);
  const SleepWindowLimits limits =
      MakeSleepWindowLimits(sleep.linear_velocity, sleep.angular_velocity, sleep.time_to_sleep);
  constexpr std::size_t kBodiesPerChunk = 128;
  step.pool->ParallelFor(moving_bodies_.size(), kBodiesPerChunk, [&](std::size_t k) {
    quiet_time[k] = QuietTime(step, limits, island_has_link[root[k]] != 0, moving_bodies_[k]);
  });
  // A body asleep already is quiet for ever, and changes no island's time.
  for (std::size_t k = 0; k < moving_bodies_.size(); ++k) {
    double& island = island_sleep_time[root[k]];
    island = std::min(island, quiet_time[k]);
  }
  for (std::size_t k = 0; k < moving_bodies_.size(); ++k) {
    if (island_sleep_time[root[k]] < sleep.time_to_sleep) continue;
    Body& body = bodies_[moving_bodies_[k]];
    if (!body.awake) continue;
    body.awake = false;
    body.linear_momentum.setZero();
    body.angular_momentum.setZero();
    body.UpdateDerived();
  }
}

}  // namespace rigid_body_sim::physics
