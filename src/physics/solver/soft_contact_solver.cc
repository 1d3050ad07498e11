#include "physics/solver/soft_contact_solver.h"

#include <algorithm>
#include <cassert>
#include <cmath>


namespace rigid_body_sim::physics {
namespace {

// The share [begin, end) of `count` items that thread `thread` of
// `threads` takes: contiguous, and the same split on every run.
std::pair<std::size_t, std::size_t> Share(std::size_t count, int thread, int threads) {
  const std::size_t begin = count * static_cast<std::size_t>(thread) / threads;
  const std::size_t end = count * static_cast<std::size_t>(thread + 1) / threads;
  return {begin, end};
}

}  // namespace

// Start loading the two bodies of constraints [first, end): the manifolds
// are read front to back, their bodies in any order.
void SoftContactSolver::PrefetchBodies(std::uint32_t first, std::uint32_t end) const {
  for (std::uint32_t k = first; k < end; ++k) {
    const SolverManifold& manifold = (*manifolds_)[k];
    PrefetchBytes(&(*bodies_)[manifold.body_a], sizeof(SoftBody));
    PrefetchBytes(&(*bodies_)[manifold.body_b], sizeof(SoftBody));
  }
}

// Each block's constraints are prepared four at a time into its lanes,
// which keep the only copy; then this thread's share of the overflow set
// is prepared into the constraints. Past the cache (compact_), each block
// waited for its bodies' lines: so the bodies of the block kBodiesAhead
// blocks on start loading.
void SoftContactSolver::PrepareBlocks(int thread, int threads) {
  const std::vector<std::uint32_t>& start = colouring_->colour_start;
  for (int colour = 0; colour < colouring_->colour_count(); ++colour) {
    const std::size_t first_block = block_start_[colour];
    const auto [begin, end] = ColourBlocks(colour, thread, threads);
    for (std::size_t b = begin; b < end; ++b) {
      const std::uint32_t first =
          start[colour] + static_cast<std::uint32_t>((b - first_block) * kBatchLanes);
      const int lanes =
          static_cast<int>(std::min<std::size_t>(kBatchLanes, start[colour + 1] - first));
      if (compact_) {
        const std::uint32_t ahead =
            std::min<std::uint32_t>(start[colour + 1], first + kBodiesAhead * kBatchLanes);
        PrefetchBodies(ahead, std::min<std::uint32_t>(start[colour + 1], ahead + kBatchLanes));
      }
      WithBlocks([&](auto& blocks) { PrepareBlock(first, lanes, &blocks[b]); });
    }
  }
  const auto [begin, end] = Share(colouring_->overflow_count(), thread, threads);
  for (std::size_t k = start.back() + begin; k < start.back() + end; ++k) {
    Prepare(*bodies_, (*manifolds_)[k], (*anchors_)[k], &constraints_[k]);
  }
}

void SoftContactSolver::Step(const SoftStepInput& input, TaskPool* pool,
                             std::vector<SoftBody>* bodies, std::vector<SolverManifold>* manifolds,
                             std::vector<FrictionAnchor>* anchors) {
  bodies_ = bodies;
  manifolds_ = manifolds;
  anchors_ = anchors;
  substeps_ = input.settings.substeps;
  h_ = input.dt / substeps_;
  max_push_velocity_ = input.settings.max_push_velocity;
  collision_velocity_threshold_ = input.collision_velocity_threshold;
  touch_tolerance_ = input.touch_tolerance;
  load_tracking_ = input.settings.load_tracking;
  lanes_ = input.settings.simd_lanes;
  compact_blocks_from_ = input.settings.compact_blocks_from;
  may_bounce_.store(false, std::memory_order_relaxed);
  colouring_ = input.colouring;
  assert(colouring_->order.size() == manifolds->size());
  LoadStates(input);
  constraints_.resize(manifolds->size());
  ListBlocks();
  MakeSoftnesses(input);
  // Every thread prepares, solves and stores its share; the barriers keep
  // the stages apart.
  const int threads = pool->threads();
  SpinBarrier barrier(threads);
  auto run = [&](int thread) {
    if (!HasBlocks()) {
      const auto [begin, end] = Share(constraints_.size(), thread, threads);
      for (std::size_t k = begin; k < end; ++k) {
        Prepare(*bodies, (*manifolds)[k], (*anchors)[k], &constraints_[k]);
      }
    } else {
      PrepareBlocks(thread, threads);
    }
    barrier.Wait();
    RunSubsteps(thread, threads, &barrier);
    // The constraints not in a block: all of them without lanes, else the
    // overflow set.
    const std::size_t first_scalar = HasBlocks() ? colouring_->colour_start.back() : 0;
    const auto [begin, end] = Share(constraints_.size() - first_scalar, thread, threads);
    for (std::size_t k = first_scalar + begin; k < first_scalar + end; ++k) {
      Store(k, constraints_[k]);
    }
    const auto [first, last] = Share(moving_.size(), thread, threads);
    for (std::size_t k = first; k < last; ++k) {
      SoftBody& body = (*bodies)[moving_[k]];
      const State& state = states_[moving_[k]];
      body.linear_velocity = state.linear_velocity;
      body.angular_velocity = state.angular_velocity;
      body.delta_position = state.delta_position;
    }
  };
  if (threads == 1) {
    run(0);
  } else {
    pool->RunOnAll(run);
  }
}

// The moving bodies' velocities into the states, and the other bodies the
// manifolds reach as bodies the solve never moves.
void SoftContactSolver::LoadStates(const SoftStepInput& input) {
  moving_.clear();
  moving_mask_.assign(bodies_->size(), 0);
  states_.resize(bodies_->size());
  auto load = [&](std::uint32_t i) {
    const SoftBody& body = (*bodies_)[i];
    states_[i] = State{body.linear_velocity, body.angular_velocity, Vec3::Zero(), Vec3::Zero()};
  };
  for (const std::uint32_t i : *input.moving) {
    if (!(*bodies_)[i].moving) continue;
    moving_.push_back(i);
    moving_mask_[i] = 1;
    load(i);
    (*bodies_)[i].delta_rotation = Quat::Identity();
  }
  // The manifolds' bodies from the dense list beside them: a manifold is
  // hundreds of bytes, and walking them here would load each one's line.
  const std::vector<std::array<std::uint32_t, 2>>& pair_bodies = *input.manifold_bodies;
  assert(pair_bodies.size() == manifolds_->size());
  anchors_->resize(manifolds_->size());
  for (const auto& [a, b] : pair_bodies) {
    if (!moving_mask_[a]) load(a);
    if (!moving_mask_[b]) load(b);
  }
}

void SoftContactSolver::RunSubsteps(int thread, int threads, SpinBarrier* barrier) {
  for (int k = 0; k < substeps_; ++k) {
    IntegrateVelocities(thread, threads);
    barrier->Wait();
    RunPass(Pass::kWarmStart, thread, threads, barrier);
    RunPass(Pass::kSolve, thread, threads, barrier);
    IntegratePositions(thread, threads);
    barrier->Wait();
    RunPass(Pass::kRelax, thread, threads, barrier);
  }
  // Every thread reads the flag after the last relax pass's barrier, so all
  // take the same branch.
  const bool bounce = may_bounce_.load(std::memory_order_relaxed);
  if (!HasBlocks()) {
    if (bounce) RunPass(Pass::kRestitution, thread, threads, barrier);
    return;
  }
  StoreBlocks(bounce, thread, threads, barrier);
}

// Each block's constraints taken out of their lanes, restituted (when a
// point closed fast) and stored, colour by colour; then the overflow set's
// restitution. A constraint's store reads only its own rows, so it follows
// its restitution at once.
void SoftContactSolver::StoreBlocks(bool bounce, int thread, int threads, SpinBarrier* barrier) {
  Constraint c;
  for (int colour = 0; colour < colouring_->colour_count(); ++colour) {
    // Named copies, not a structured binding: C++17 lambdas cannot capture
    // a binding (clang refuses it).
    const std::pair<std::size_t, std::size_t> share = ColourBlocks(colour, thread, threads);
    const std::size_t begin = share.first;
    const std::size_t end = share.second;
    WithBlocks([&](const auto& blocks) {
      for (std::size_t b = begin; b < end; ++b) {
        for (int lane = 0; lane < blocks[b].lanes; ++lane) {
          ExtractSoftConstraint(blocks[b], lane, /*rows=*/bounce, &c);
          if (bounce) Restitute(&c);
          Store(blocks[b].constraint[lane], c);
        }
      }
    });
    if (bounce) barrier->Wait();
  }
  if (!bounce || colouring_->overflow_count() == 0) return;
  if (thread == 0) {
    for (std::size_t k = colouring_->colour_start.back(); k < constraints_.size(); ++k) {
      Restitute(&constraints_[k]);
    }
  }
  barrier->Wait();
}

void SoftContactSolver::RunPass(Pass pass, int thread, int threads, SpinBarrier* barrier) {
  const std::vector<std::uint32_t>& start = colouring_->colour_start;
  for (int colour = 0; colour < colouring_->colour_count(); ++colour) {
    if (HasBlocks() && pass != Pass::kRestitution) {
      ApplyToBlocks(pass, colour, thread, threads);
    } else {
      const std::size_t size = start[colour + 1] - start[colour];
      const auto [begin, end] = Share(size, thread, threads);
      for (std::size_t k = start[colour] + begin; k < start[colour] + end; ++k) {
        Apply(pass, &constraints_[k]);
      }
    }
    barrier->Wait();
  }
  if (colouring_->overflow_count() == 0) return;
  if (thread == 0) {
    for (std::size_t k = start.back(); k < constraints_.size(); ++k) {
      Apply(pass, &constraints_[k]);
    }
  }
  barrier->Wait();
}

std::pair<std::size_t, std::size_t> SoftContactSolver::ColourBlocks(int colour, int thread,
                                                                    int threads) const {
  const std::size_t first_block = block_start_[colour];
  const auto [begin, end] = Share(block_start_[colour + 1] - first_block, thread, threads);
  return {first_block + begin, first_block + end};
}

// Four consecutive constraints of a colour to a block, the colour's last
// block holding what is left; none without simd_lanes. From
// compact_blocks_from blocks on, the blocks are compact: the passes stream
// every block, and past the cache a block's bytes cost more than its
// floats' conversions (docs/performance.md).
void SoftContactSolver::ListBlocks() {
  block_start_.assign(1, 0);
  const std::vector<std::uint32_t>& start = colouring_->colour_start;
  std::size_t count = 0;
  for (int colour = 0; colour < colouring_->colour_count(); ++colour) {
    const std::size_t size = start[colour + 1] - start[colour];
    count += (size + kBatchLanes - 1) / kBatchLanes;
    block_start_.push_back(static_cast<std::uint32_t>(count));
  }
  // Without lanes the step is compact as it would be with them: the scalar
  // update rounds the same rows.
  compact_ = count >= static_cast<std::size_t>(compact_blocks_from_);
  if (!lanes_) return;
  // Kept from step to step: PrepareBlock writes every field of a block.
  WithBlocks([count](auto& blocks) {
    if (blocks.size() < count) blocks.resize(count);
  });
}

void SoftContactSolver::ApplyToBlocks(Pass pass, int colour, int thread, int threads) {
  SoftLaneContext context;
  context.states = &states_;
  context.h = h_;
  context.max_push_velocity = max_push_velocity_;
  context.collision_velocity_threshold = collision_velocity_threshold_;
  const std::pair<std::size_t, std::size_t> share = ColourBlocks(colour, thread, threads);
  const std::size_t begin = share.first;
  const std::size_t end = share.second;
  WithBlocks([&](auto& blocks) {
    auto* const from = blocks.data() + begin;
    auto* const to = blocks.data() + end;
    if (pass == Pass::kWarmStart) {
      WarmStartSoftBlocks(context, from, to);
    } else if (SolveSoftBlocks(context, pass == Pass::kSolve, from, to)) {
      may_bounce_.store(true, std::memory_order_relaxed);
    }
  });
}

void SoftContactSolver::Apply(Pass pass, Constraint* constraint) {
  switch (pass) {
    case Pass::kWarmStart:
      WarmStart(constraint);
      break;
    case Pass::kSolve:
      Solve(constraint, /*use_bias=*/true);
      break;
    case Pass::kRelax:
      Solve(constraint, /*use_bias=*/false);
      break;
    case Pass::kRestitution:
      Restitute(constraint);
      break;
  }
}

// v += h (g + F/m), w += h I^-1 tau, for this thread's share of the moving
// bodies.
void SoftContactSolver::IntegrateVelocities(int thread, int threads) {
  const auto [begin, end] = Share(moving_.size(), thread, threads);
  const std::vector<SoftBody>& bodies = *bodies_;
  for (std::size_t k = begin; k < end; ++k) {
    const std::uint32_t i = moving_[k];
    State& state = states_[i];
    state.linear_velocity += h_ * bodies[i].linear_acceleration;
    state.angular_velocity += h_ * bodies[i].angular_acceleration;
  }
}

// x += h v; q += h/2 (0, w) q, normalised (first order, as Box2D's), and
// the rotation vector the rows read, dtheta += h w; the travel bound grows
// by h (|v| + |w| reach).
void SoftContactSolver::IntegratePositions(int thread, int threads) {
  const auto [begin, end] = Share(moving_.size(), thread, threads);
  std::vector<SoftBody>& bodies = *bodies_;
  for (std::size_t k = begin; k < end; ++k) {
    const std::uint32_t i = moving_[k];
    State& state = states_[i];
    state.delta_position += h_ * state.linear_velocity;
    state.delta_angle += h_ * state.angular_velocity;
    const Vec3 half_turn = 0.5 * h_ * state.angular_velocity;
    Quat& q = bodies[i].delta_rotation;
    const Quat spin(0.0, half_turn.x(), half_turn.y(), half_turn.z());
    q.coeffs() += (spin * q).coeffs();
    q.normalize();
    bodies[i].travel +=
        h_ * (state.linear_velocity.norm() + state.angular_velocity.norm() * bodies[i].reach);
  }
}

// The anchors stay while the last sub-step's friction stayed inside its
// cone (it held); after a slip they start again where the contact is.
void SoftContactSolver::StoreAnchor(const Constraint& c, FrictionAnchor* anchor) const {
  double normal = 0.0;
  for (int i = 0; i < c.point_count; ++i) normal += c.points[i].normal_impulse;
  constexpr double kHeld = 0.999;
  const double friction = std::sqrt(c.tangent_impulse[0] * c.tangent_impulse[0] +
                                    c.tangent_impulse[1] * c.tangent_impulse[1]);
  anchor->valid = normal > 0.0 && friction < kHeld * c.friction * normal;
  if (!anchor->valid) return;
  const SoftBody& a = (*bodies_)[c.body_a];
  const SoftBody& b = (*bodies_)[c.body_b];
  anchor->on_a = a.orientation.conjugate() * c.anchor_a;
  anchor->on_b = b.orientation.conjugate() * c.anchor_b;
}

// The step's impulses (the sum of its sub-steps'), each point's type
// (colliding when it touched after closing faster than the collision
// threshold, and was pushed; else resting), its new preload, and the
// approach speed of a point that closed but has not touched yet.
void SoftContactSolver::Store(std::size_t k, const Constraint& c) const {
  SolverManifold* manifold = &(*manifolds_)[k];
  StoreAnchor(c, &(*anchors_)[k]);
  manifold->tangent_world = c.tangent;
  // The friction impulse is shared among the points as their normal
  // impulses are (equally when none pushed).
  double normal = 0.0;
  for (int i = 0; i < c.point_count; ++i) normal += c.points[i].total_normal_impulse;
  for (int i = 0; i < c.point_count; ++i) {
    const Point& p = c.points[i];
    const double weight = normal > 0.0 ? p.total_normal_impulse / normal : 1.0 / c.point_count;
    SolverPoint& to = manifold->points[i];
    to.normal_impulse = p.total_normal_impulse;
    to.tangent_impulse = {c.total_tangent_impulse[0] * weight, c.total_tangent_impulse[1] * weight};
    to.preload =
        p.preload * substeps_ + load_tracking_ * (p.total_normal_impulse - p.preload * substeps_);
    to.collision_impulse = 0.0;
    to.normal_velocity_before = p.approach_velocity;
    const bool collided = p.touched && p.approach_velocity < -collision_velocity_threshold_ &&
                          p.total_normal_impulse > 0.0;
    to.type = collided ? ContactType::kColliding : ContactType::kResting;
    to.carried_approach = p.closed && !p.touched && !p.carried ? p.approach_velocity : 0.0;
  }
}

}  // namespace rigid_body_sim::physics
