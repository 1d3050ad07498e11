// Stage 5's end, for both solvers: quiet islands are put to sleep
// (SleepSystem).
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "physics/dynamics/integrator.h"
#include "physics/dynamics/sleep_system.h"
#include "physics/world/union_find.h"

namespace rigid_body_sim::physics {

SleepSystem::SleepSystem(const WorldParts& world)
    : bodies_(*world.bodies),
      contact_cache_(*world.contact_cache),
      settings_(*world.settings),
      articulations_(*world.articulations) {}

void SleepSystem::RestartWindow(std::uint32_t index) {
  if (index < windows_.size()) windows_[index] = SleepWindow{};
}

// Whether a body has kept speeding up for sleep.speeding_up_time. Slow is
// not at rest: a box on a slope 0.2 degrees steeper than its friction angle
// accelerates at 0.04 m/s^2 and stays below 0.05 m/s for 1.3 s, long enough
// to fall asleep mid-slide. A settling body's speed rises and falls from
// step to step; one getting under way gains speed at every step. Speeds
// below 2 % of the sleep thresholds are noise: the residual velocities of a
// stack at rest can grow steadily without going anywhere, and counted, they
// kept the benchmark's pyramids awake.
bool SleepSystem::UpdateSpeedingUp(const StepContext& step, Body* body) const {
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
double SleepSystem::QuietTime(const StepContext& step, const SleepWindowLimits& limits,
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
    RestartWindow(i);
    return 0.0;
  }
  const bool slow =
      !speeding_up &&
      body.linear_velocity.squaredNorm() < sleep.linear_velocity * sleep.linear_velocity &&
      body.angular_velocity.squaredNorm() < sleep.angular_velocity * sleep.angular_velocity;
  body.sleep_time = slow ? body.sleep_time + step.dt : 0.0;
  // Slow for long enough, or gone nowhere for long enough (sleep_window.h).
  if (speeding_up) RestartWindow(i);
  const double still_time =
      UpdateSleepWindow(body.WorldFromPrincipal(), limits, step.dt, &windows_[i]);
  return std::max(body.sleep_time, still_time);
}

// Islands are the connected components of the contact graph through moving
// bodies (union-find). An island sleeps when every body in it has been slower
// than the thresholds, or has kept within its sleep window, and not speeding
// up, for time_to_sleep; it costs nothing until woken.
void SleepSystem::Update(const StepContext& step, const std::vector<std::uint32_t>& moving) {
  const SleepSettings& sleep = settings_.sleep;
  if (!sleep.enabled) return;
  // The islands' scratch keeps its memory from step to step.
  islands_.Reset(bodies_.size());
  // The touching pairs' bodies come from their keys (no entry is loaded);
  // whether each joins an island is read on the pool (each body a load the
  // caches no longer hold), and the joins are made here from the list.
  const std::vector<std::array<std::uint32_t, 2>>& touching = contact_cache_.touching_bodies();
  edges_.resize(touching.size());
  constexpr std::size_t kPairsPerChunk = 256;
  step.pool->ParallelFor(touching.size(), kPairsPerChunk, [&](std::size_t m) {
    const std::uint32_t a = touching[m][0];
    const std::uint32_t b = touching[m][1];
    const bool joins = !bodies_[a].is_static && !bodies_[b].is_static;
    edges_[m] = joins ? std::array<std::uint32_t, 2>{a, b} : std::array<std::uint32_t, 2>{a, a};
  });
  for (const std::array<std::uint32_t, 2>& edge : edges_) {
    if (edge[0] != edge[1]) islands_.Join(edge[0], edge[1]);
  }
  // Articulations never sleep, nor does what touches them.
  island_has_link_.assign(bodies_.size(), 0);
  for (const ShapePairContact* pair : articulations_.link_pairs()) {
    for (const std::uint32_t index : {pair->body_a, pair->body_b}) {
      if (bodies_[index].articulation >= 0) island_has_link_[islands_.Find(index)] = 1;
    }
  }
  island_sleep_time_.assign(bodies_.size(), std::numeric_limits<double>::infinity());
  windows_.resize(bodies_.size());
  // Each moving body's island, found here because Find compresses paths;
  // then each body's quiet time on the pool (it reads and writes only its
  // own body and window), and each island's, their least, here.
  root_.resize(moving.size());
  quiet_time_.resize(moving.size());
  for (std::size_t k = 0; k < moving.size(); ++k) root_[k] = islands_.Find(moving[k]);
  const SleepWindowLimits limits =
      MakeSleepWindowLimits(sleep.linear_velocity, sleep.angular_velocity, sleep.time_to_sleep);
  constexpr std::size_t kBodiesPerChunk = 128;
  step.pool->ParallelFor(moving.size(), kBodiesPerChunk, [&](std::size_t k) {
    quiet_time_[k] = QuietTime(step, limits, island_has_link_[root_[k]] != 0, moving[k]);
  });
  // A body asleep already is quiet for ever, and changes no island's time.
  for (std::size_t k = 0; k < moving.size(); ++k) {
    double& island = island_sleep_time_[root_[k]];
    island = std::min(island, quiet_time_[k]);
  }
  for (std::size_t k = 0; k < moving.size(); ++k) {
    if (island_sleep_time_[root_[k]] < sleep.time_to_sleep) continue;
    Body& body = bodies_[moving[k]];
    if (!body.awake) continue;
    body.awake = false;
    body.linear_momentum.setZero();
    body.angular_momentum.setZero();
    body.UpdateDerived();
  }
}

}  // namespace rigid_body_sim::physics
