// The exact solver's rest of a step after an impact (stage 5 continued). A body that would
// enter another within the step is backed up to the time of impact
// (Baraff 1997, "Rigid Body Simulation II", section 6), and then, instead of
// losing what is left of the step, it and everything that touches it
// simulate that rest as a step of their own: the collision is resolved at
// the time it happens, and the bodies end the step where the closed form
// puts them. This is Baraff's restart of the integrator at t_c, done for
// the island of the impact only, so that an impact in one corner of the
// world does not back up the rest of it.
#include <algorithm>
#include <limits>
#include <numeric>

#include "physics/collision/narrow_phase.h"
#include "physics/solver/exact_solver.h"
#include "physics/world/union_find.h"
#include "physics/world/world_impl.h"

namespace rigid_body_sim::physics {
namespace {

// Rounds of impacts within one step that are followed to the end of the
// step; later ones keep the bodies at their time of impact, as the step
// does for an impact that is not a collision (a resting body grazed).
constexpr int kMaxImpactRounds = 8;
// Islands of more bodies than this keep their bodies at their times of
// impact, as before the rest of the step was simulated: a box landing on a
// settling pile of a thousand would have the whole pile stepped again, and
// the position lost is at most the approach speed times the rest of the
// step for the landing box only.
constexpr std::size_t kMaxSubStepBodies = 32;

}  // namespace

// The impacts of one (sub)step of length h: each island of moving bodies
// (linked by touching pairs and by colliding impacts) that holds a colliding
// impact goes back to its earliest impact and simulates the rest of h. A
// body with only other impacts stays at its own earliest one.
void ExactSolver::ResolveImpacts(const StepContext& step, const std::vector<Impact>& impacts,
                                 const std::vector<ShapePairContact*>& touching, int round) {
  const std::vector<std::uint32_t> moving = world_.moving_bodies_;
  std::vector<std::vector<std::uint32_t>> islands;
  std::vector<double> island_times;
  if (!impacts.empty()) {
    std::vector<double> body_time(world_.bodies_.size(), std::numeric_limits<double>::infinity());
    UnionFind sets;
    sets.Reset(world_.bodies_.size());
    const auto moves = [&](std::uint32_t body) { return paths_[body].dt > 0.0; };
    for (const ShapePairContact* pair : touching) {
      if (moves(pair->body_a) && moves(pair->body_b)) sets.Join(pair->body_a, pair->body_b);
    }
    for (const Impact& impact : impacts) {
      for (const std::uint32_t body : {impact.pair->body_a, impact.pair->body_b}) {
        body_time[body] = std::min(body_time[body], impact.time);
      }
      if (impact.colliding && moves(impact.pair->body_a) && moves(impact.pair->body_b)) {
        sets.Join(impact.pair->body_a, impact.pair->body_b);
      }
    }
    // An island's time is its earliest impact; only an island with a
    // colliding impact goes on to the end of the interval.
    std::vector<double> root_time(world_.bodies_.size(), std::numeric_limits<double>::infinity());
    std::vector<char> root_collides(world_.bodies_.size(), 0);
    for (const Impact& impact : impacts) {
      for (const std::uint32_t body : {impact.pair->body_a, impact.pair->body_b}) {
        if (!moves(body)) continue;
        const std::uint32_t root = sets.Find(body);
        root_time[root] = std::min(root_time[root], impact.time);
        root_collides[root] |= impact.colliding && round < kMaxImpactRounds;
      }
    }
    std::vector<std::uint32_t> island_size(world_.bodies_.size(), 0);
    for (const std::uint32_t body : moving) {
      if (moves(body)) ++island_size[sets.Find(body)];
    }
    for (const std::uint32_t body : moving) {
      const std::uint32_t root = moves(body) ? sets.Find(body) : body;
      if (island_size[root] > kMaxSubStepBodies) root_collides[root] = 0;
    }
    std::vector<int> island_of_root(world_.bodies_.size(), -1);
    for (const std::uint32_t body : moving) {
      if (!moves(body)) continue;
      const std::uint32_t root = sets.Find(body);
      if (root_collides[root]) {
        if (island_of_root[root] < 0) {
          island_of_root[root] = static_cast<int>(islands.size());
          islands.emplace_back();
          island_times.push_back(root_time[root]);
        }
        islands[island_of_root[root]].push_back(body);
        body_time[body] = root_time[root];
      }
      const double time = body_time[body];
      if (std::isfinite(time)) BackUpBody(body, time);
    }
  }
  for (const std::uint32_t body : moving) paths_[body] = BodyPath{};
  // The sub-steps collide their pairs and build their manifolds afresh.
  if (!islands.empty()) world_.FlushReports();
  for (std::size_t k = 0; k < islands.size(); ++k) {
    const double rest = step.dt - island_times[k];
    if (rest > 0.0) SubStep(islands[k], step.Interval(rest), round + 1);
  }
  world_.moving_bodies_ = moving;
}

// The body where its path puts it at time t, with the velocity it had then.
void ExactSolver::BackUpBody(std::uint32_t index, double time) {
  Body& body = world_.bodies_[index];
  const BodyPath& path = paths_[index];
  const Pose pose = path.At(time);
  body.position = pose.translation;
  body.orientation = pose.rotation.normalized();
  body.linear_momentum = body.mass * path.VelocityAt(time);
  body.UpdateDerived();
  body.start_linear_velocity = body.linear_velocity;
  body.start_angular_momentum = body.angular_momentum;
}

// `island` (moving bodies at one time) simulates h as a step of its own
// against the rest of the world where it now is: fresh manifolds at the
// current poses, the contact solve (collisions first), the drift, and the
// impacts within h.
void ExactSolver::SubStep(const std::vector<std::uint32_t>& island, const StepContext& step,
                          int round) {
  std::vector<char> member(world_.bodies_.size(), 0);
  for (const std::uint32_t body : island) member[body] = 1;
  std::vector<ShapePairContact*> pairs;
  for (ShapePairContact* pair : world_.contact_cache_.seen()) {
    if (member[pair->body_a] || member[pair->body_b]) pairs.push_back(pair);
  }
  std::vector<ShapePairContact*> touching;
  for (ShapePairContact* pair : pairs) {
    world_.collision_.RecollidePair(step, pair);
    if (pair->manifold.point_count == 0) continue;
    if (world_.bodies_[pair->body_a].articulation >= 0 ||
        world_.bodies_[pair->body_b].articulation >= 0)
      continue;
    MatchWarmStarts(pair);
    touching.push_back(pair);
  }
  world_.moving_bodies_ = island;
  SolveTouching(step, touching);
  world_.reports_.ReportSolved(touching, step, /*impacts_only=*/true);
  DriftBodies(step);
  BoundBodyMotion(step);
  ResolveImpacts(step, FindImpacts(step, pairs), touching, round);
}

}  // namespace rigid_body_sim::physics
