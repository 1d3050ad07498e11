#include "physics/solver/soft_contact_solver.h"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "physics/contact/contact_frame.h"

namespace rigid_body_sim::physics {
namespace {

// The implicit spring-damper as a soft row (Catto 2011, "Soft Constraints",
// GDC; Box2D v3's b2MakeSoft): for frequency f, damping ratio z and step h,
// the bias rate b and the scales of the row's mass and of its accumulated
// impulse.
struct Softness {
  double bias_rate;
  double mass_scale;
  double impulse_scale;
};

Softness MakeSoftness(double hertz, double damping_ratio, double h) {
  const double omega = 2.0 * M_PI * hertz;
  const double a1 = 2.0 * damping_ratio + h * omega;
  const double a2 = h * omega * a1;
  const double a3 = 1.0 / (1.0 + a2);
  return Softness{omega / a1, a2 * a3, a3};
}

// The share [begin, end) of `count` items that thread `thread` of
// `threads` takes: contiguous, and the same split on every run.
std::pair<std::size_t, std::size_t> Share(std::size_t count, int thread, int threads) {
  const std::size_t begin = count * static_cast<std::size_t>(thread) / threads;
  const std::size_t end = count * static_cast<std::size_t>(thread + 1) / threads;
  return {begin, end};
}

// x as the rows keep what the sub-steps only read: rounded to a float in a
// step with compact blocks (SoftStepSettings::compact_blocks_from), so
// that the scalar update and the lanes compute with what those blocks hold.
double Kept(bool compact, double x) { return compact ? NarrowToFloat(x) : x; }
Vec3 Kept(bool compact, const Vec3& x) { return compact ? NarrowToFloat(x) : x; }

// 1 / k for k > 0, else 0 (a row neither body can move).
double InverseOrZero(double k) { return k > 0.0 ? 1.0 / k : 0.0; }

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

// Each block's constraints are prepared into a scratch block of four, in
// the cache, and packed from there: the lanes keep the only copy. Then this
// thread's share of the overflow set is prepared into the constraints.
// Past the cache (compact_), each Prepare waited for its bodies' lines: so
// the bodies of the block kBodiesAhead blocks on start loading.
template <typename PrepareConstraint>
void SoftContactSolver::PrepareAndPackBlocks(int thread, int threads,
                                             const PrepareConstraint& prepare) {
  const std::vector<std::uint32_t>& start = colouring_->colour_start;
  std::array<Constraint, kBatchLanes> scratch;
  for (int colour = 0; colour < colouring_->colour_count(); ++colour) {
    const std::size_t first_block = block_start_[colour];
    const auto [begin, end] = ColourBlocks(colour, thread, threads);
    for (std::size_t b = begin; b < end; ++b) {
      const std::uint32_t first =
          start[colour] + static_cast<std::uint32_t>((b - first_block) * kBatchLanes);
      const int lanes =
          static_cast<int>(std::min<std::size_t>(kBatchLanes, start[colour + 1] - first));
      if (compact_) {
        const std::uint32_t colour_end = start[colour + 1];
        auto ahead = [&](std::uint32_t blocks) {
          return std::min<std::uint32_t>(colour_end, first + blocks * kBatchLanes);
        };
        PrefetchBodies(ahead(kBodiesAhead), ahead(kBodiesAhead + 1));
      }
      for (int lane = 0; lane < lanes; ++lane) prepare(first + lane, &scratch[lane]);
      WithBlocks([&](auto& blocks) {
        PackSoftBlock(scratch.data(), first, lanes, moving_mask_, &blocks[b]);
      });
    }
  }
  const auto [begin, end] = Share(colouring_->overflow_count(), thread, threads);
  for (std::size_t k = start.back() + begin; k < start.back() + end; ++k) {
    prepare(k, &constraints_[k]);
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
  // Every thread prepares, solves and stores its share; the barriers keep
  // the stages apart.
  const int threads = pool->threads();
  SpinBarrier barrier(threads);
  auto prepare = [&](std::size_t k, Constraint* constraint) {
    Prepare(input, *bodies, (*manifolds)[k], (*anchors)[k], constraint);
  };
  auto run = [&](int thread) {
    if (!HasBlocks()) {
      const auto [begin, end] = Share(constraints_.size(), thread, threads);
      for (std::size_t k = begin; k < end; ++k) prepare(k, &constraints_[k]);
    } else {
      PrepareAndPackBlocks(thread, threads, prepare);
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

// A manifold's rows: each point's Jacobian, row mass and the impulse it
// starts from (the step's cached impulse shared equally among the
// sub-steps), and its friction rows.
void SoftContactSolver::Prepare(const SoftStepInput& input, const std::vector<SoftBody>& bodies,
                                const SolverManifold& manifold, const FrictionAnchor& anchor,
                                Constraint* constraint) {
  Constraint& c = *constraint;
  const SoftBody& a = bodies[manifold.body_a];
  const SoftBody& b = bodies[manifold.body_b];
  c.body_a = manifold.body_a;
  c.body_b = manifold.body_b;
  // What the sub-steps only read is rounded to floats in a compact step
  // (Kept); the masses and impulses stay doubles.
  c.normal = Kept(compact_, manifold.normal_world);
  c.tangent = TangentBasis(c.normal);
  for (Vec3& t : c.tangent) t = Kept(compact_, t);
  c.inverse_mass_a = a.inverse_mass;
  c.inverse_mass_b = b.inverse_mass;
  c.friction = Kept(compact_, manifold.friction);
  c.restitution = Kept(compact_, manifold.restitution);
  // A spring stiffer than a quarter of the sub-step rate is not followed by
  // one iteration a sub-step (Box2D v3 caps it the same way); a contact
  // with a body that does not move takes twice the frequency.
  const double max_hertz = 0.25 / h_;
  const double hertz = input.settings.contact_hertz * (a.moving && b.moving ? 1.0 : 2.0);
  const Softness soft =
      MakeSoftness(std::min(hertz, max_hertz), input.settings.contact_damping_ratio, h_);
  c.bias_rate = Kept(compact_, soft.bias_rate);
  c.mass_scale = Kept(compact_, soft.mass_scale);
  c.impulse_scale = Kept(compact_, soft.impulse_scale);
  c.point_count = manifold.point_count;
  const double share = 1.0 / substeps_;
  for (int i = 0; i < c.point_count; ++i) {
    const SolverPoint& from = manifold.points[i];
    Point& p = c.points[i];
    p.rn_a = Kept(compact_, from.r_a.cross(c.normal));
    p.rn_b = Kept(compact_, from.r_b.cross(c.normal));
    p.ang_a = Kept(compact_, a.inverse_inertia_world * p.rn_a);
    p.ang_b = Kept(compact_, b.inverse_inertia_world * p.rn_b);
    p.start_separation = Kept(compact_, from.separation);
    p.normal_mass =
        InverseOrZero(a.inverse_mass + b.inverse_mass + p.rn_a.dot(p.ang_a) + p.rn_b.dot(p.ang_b));
    p.normal_impulse = share * std::max(from.normal_impulse, 0.0);
    p.preload = Kept(compact_, share * std::max(from.preload, 0.0));
    p.max_normal_impulse = 0.0;
    p.total_normal_impulse = 0.0;
    // A point that closed at the end of the last step, before it touched,
    // keeps the speed it closed at (the speculative row has slowed it).
    p.closed = from.carried_approach < 0.0;
    p.carried = p.closed;
    if (from.carried_approach < -collision_velocity_threshold_) {
      may_bounce_.store(true, std::memory_order_relaxed);
    }
    p.approach_velocity = p.closed
                              ? from.carried_approach
                              : c.normal.dot(a.linear_velocity - b.linear_velocity) +
                                    p.rn_a.dot(a.angular_velocity) - p.rn_b.dot(b.angular_velocity);
    p.touched = false;
  }
  PrepareFriction(a, b, manifold, anchor, share, &c);
}

// The friction rows at the centroid c of the manifold's points: the tangent
// block (K_t)_kl = (1/m_a + 1/m_b) t_k.t_l + (c_a x t_k).I_a^-1 (c_a x t_l)
// + (B's likewise), inverted, and the twist row's mass
// 1 / (n.(I_a^-1 + I_b^-1) n); they start from the manifold's cached tangent
// impulses, summed, and from its anchors.
void SoftContactSolver::PrepareFriction(const SoftBody& a, const SoftBody& b,
                                        const SolverManifold& manifold,
                                        const FrictionAnchor& anchor, double share,
                                        Constraint* c) const {
  Vec3 centre_a = Vec3::Zero();
  Vec3 centre_b = Vec3::Zero();
  c->tangent_impulse = {0.0, 0.0};
  for (int i = 0; i < c->point_count; ++i) {
    centre_a += manifold.points[i].r_a;
    centre_b += manifold.points[i].r_b;
    c->tangent_impulse[0] += share * manifold.points[i].tangent_impulse[0];
    c->tangent_impulse[1] += share * manifold.points[i].tangent_impulse[1];
  }
  const double inverse_count = c->point_count > 0 ? 1.0 / c->point_count : 0.0;
  centre_a *= inverse_count;
  centre_b *= inverse_count;
  c->twist_arm = 0.0;
  for (int i = 0; i < c->point_count; ++i) {
    const Vec3 offset = manifold.points[i].r_a - centre_a;
    c->twist_arm += inverse_count * (offset - offset.dot(c->normal) * c->normal).norm();
  }
  c->twist_arm = Kept(compact_, c->twist_arm);
  centre_a = Kept(compact_, centre_a);
  centre_b = Kept(compact_, centre_b);
  c->centre_a = centre_a;
  c->centre_b = centre_b;
  c->anchor_a = anchor.valid ? Kept(compact_, a.orientation * anchor.on_a) : centre_a;
  c->anchor_b = anchor.valid ? Kept(compact_, b.orientation * anchor.on_b) : centre_b;
  const Vec3 anchors_apart = a.position + c->anchor_a - b.position - c->anchor_b;
  for (int k = 0; k < 2; ++k) {
    const Vec3& t = c->tangent[k];
    c->ct_a[k] = centre_a.cross(t);
    c->ct_b[k] = centre_b.cross(t);
    c->ang_t_a[k] = Kept(compact_, a.inverse_inertia_world * c->ct_a[k]);
    c->ang_t_b[k] = Kept(compact_, b.inverse_inertia_world * c->ct_b[k]);
    c->slip_start[k] = Kept(compact_, t.dot(anchors_apart));
    c->anchor_t_a[k] = c->anchor_a.cross(t);
    c->anchor_t_b[k] = c->anchor_b.cross(t);
  }
  const double inverse_masses = a.inverse_mass + b.inverse_mass;
  auto block = [&](int k, int l) {
    return inverse_masses * c->tangent[k].dot(c->tangent[l]) + c->ct_a[k].dot(c->ang_t_a[l]) +
           c->ct_b[k].dot(c->ang_t_b[l]);
  };
  const double kxx = block(0, 0);
  const double kxy = block(0, 1);
  const double kyy = block(1, 1);
  const double det = kxx * kyy - kxy * kxy;
  c->tangent_block = det > 0.0 ? std::array<double, 3>{kyy / det, -kxy / det, kxx / det}
                               : std::array<double, 3>{0.0, 0.0, 0.0};
  c->twist_a = Kept(compact_, a.inverse_inertia_world * c->normal);
  c->twist_b = Kept(compact_, b.inverse_inertia_world * c->normal);
  c->twist_mass = InverseOrZero(c->normal.dot(c->twist_a + c->twist_b));
  c->twist_impulse = 0.0;
  c->total_tangent_impulse = {0.0, 0.0};
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
  // Kept from step to step: PackSoftBlock writes what a block's rows use.
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
  const double friction = std::hypot(c.tangent_impulse[0], c.tangent_impulse[1]);
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
