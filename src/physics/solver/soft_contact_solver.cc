#include "physics/solver/soft_contact_solver.h"

#include <algorithm>
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

// 1 / k for k > 0, else 0 (a row neither body can move).
double InverseOrZero(double k) { return k > 0.0 ? 1.0 / k : 0.0; }

}  // namespace

// A pair of bodies' velocities, read once per constraint and written back
// only to the bodies the solve moves (a body at rest is read by every
// thread, and written by none).
struct SoftContactSolver::PairVelocities {
  PairVelocities(State* a, State* b, bool a_moves, bool b_moves)
      : state_a(a),
        state_b(b),
        moves_a(a_moves),
        moves_b(b_moves),
        v_a(a->linear_velocity),
        w_a(a->angular_velocity),
        v_b(b->linear_velocity),
        w_b(b->angular_velocity) {}
  // d.(v_a - v_b) + j_a.w_a - j_b.w_b: a row's velocity from its Jacobian.
  // Forced inline (GCC and Clang): called once per row update, an out-of-
  // line call was a tenth of the soft step's time.
  [[gnu::always_inline]] double Along(const Vec3& d, const Vec3& j_a, const Vec3& j_b) const {
    return d.dot(v_a - v_b) + j_a.dot(w_a) - j_b.dot(w_b);
  }
  // Impulse p on A and -p on B, whose angular parts I^-1 (r x p) are given.
  [[gnu::always_inline]] void Apply(const Vec3& p, double inverse_mass_a, double inverse_mass_b,
                                    const Vec3& angular_a, const Vec3& angular_b) {
    v_a += inverse_mass_a * p;
    w_a += angular_a;
    v_b -= inverse_mass_b * p;
    w_b -= angular_b;
  }
  void Store() const {
    if (moves_a) {
      state_a->linear_velocity = v_a;
      state_a->angular_velocity = w_a;
    }
    if (moves_b) {
      state_b->linear_velocity = v_b;
      state_b->angular_velocity = w_b;
    }
  }
  State* state_a;
  State* state_b;
  bool moves_a;
  bool moves_b;
  Vec3 v_a, w_a, v_b, w_b;
};

// Each block's constraints are prepared and at once packed, while they are
// in the cache; then this thread's share of the overflow set is prepared.
template <typename PrepareConstraint>
void SoftContactSolver::PrepareAndPackBlocks(int thread, int threads,
                                             const PrepareConstraint& prepare) {
  const std::vector<std::uint32_t>& start = colouring_.colour_start;
  for (int colour = 0; colour < colouring_.colour_count(); ++colour) {
    const std::size_t first_block = block_start_[colour];
    const auto [begin, end] = Share(block_start_[colour + 1] - first_block, thread, threads);
    for (std::size_t b = begin; b < end; ++b) {
      const std::uint32_t first = start[colour] + static_cast<std::uint32_t>(b * kBatchLanes);
      const int lanes =
          static_cast<int>(std::min<std::size_t>(kBatchLanes, start[colour + 1] - first));
      for (int lane = 0; lane < lanes; ++lane) prepare(first + lane);
      PackSoftBlock(constraints_, moving_mask_, first, lanes, &blocks_[first_block + b]);
    }
  }
  const auto [begin, end] = Share(colouring_.overflow_count(), thread, threads);
  for (std::size_t k = start.back() + begin; k < start.back() + end; ++k) prepare(k);
}

void SoftContactSolver::Step(const SoftStepInput& input, TaskPool* pool,
                             std::vector<SoftBody>* bodies, std::vector<SolverManifold>* manifolds,
                             std::vector<FrictionAnchor>* anchors) {
  bodies_ = bodies;
  substeps_ = input.settings.substeps;
  h_ = input.dt / substeps_;
  max_push_velocity_ = input.settings.max_push_velocity;
  collision_velocity_threshold_ = input.collision_velocity_threshold;
  touch_tolerance_ = input.touch_tolerance;
  load_tracking_ = input.settings.load_tracking;
  lanes_ = input.settings.simd_lanes;
  may_bounce_.store(false, std::memory_order_relaxed);
  moving_.clear();
  moving_mask_.assign(bodies->size(), 0);
  states_.resize(bodies->size());
  auto load = [&](std::uint32_t i) {
    const SoftBody& body = (*bodies)[i];
    states_[i] = State{body.linear_velocity, body.angular_velocity, Vec3::Zero(), Vec3::Zero()};
  };
  for (const std::uint32_t i : *input.moving) {
    if (!(*bodies)[i].moving) continue;
    moving_.push_back(i);
    moving_mask_[i] = 1;
    load(i);
    (*bodies)[i].delta_rotation = Quat::Identity();
  }
  for (const SolverManifold& manifold : *manifolds) {
    if (!moving_mask_[manifold.body_a]) load(manifold.body_a);
    if (!moving_mask_[manifold.body_b]) load(manifold.body_b);
  }
  anchors->resize(manifolds->size());
  body_a_.resize(manifolds->size());
  body_b_.resize(manifolds->size());
  for (std::size_t m = 0; m < manifolds->size(); ++m) {
    body_a_[m] = (*manifolds)[m].body_a;
    body_b_[m] = (*manifolds)[m].body_b;
  }
  ColourConstraints(body_a_, body_b_, moving_mask_, &colour_masks_, &colour_of_, &colouring_);
  // The constraints are stored in the colouring's order, so that each pass
  // walks them front to back in memory: constraint k is manifold order[k].
  constraints_.resize(manifolds->size());
  const std::vector<std::uint32_t>& order = colouring_.order;
  ListBlocks();
  // Every thread prepares, solves and stores its share; the barriers keep
  // the stages apart.
  const int threads = pool->threads();
  SpinBarrier barrier(threads);
  auto prepare = [&](std::size_t k) {
    const std::uint32_t m = order[k];
    Prepare(input, *bodies, (*manifolds)[m], (*anchors)[m], &constraints_[k]);
  };
  auto run = [&](int thread) {
    const auto [begin, end] = Share(constraints_.size(), thread, threads);
    if (blocks_.empty()) {
      for (std::size_t k = begin; k < end; ++k) prepare(k);
    } else {
      PrepareAndPackBlocks(thread, threads, prepare);
    }
    barrier.Wait();
    RunSubsteps(thread, threads, &barrier);
    for (std::size_t k = begin; k < end; ++k) {
      const std::uint32_t m = order[k];
      Store(constraints_[k], &(*manifolds)[m], &(*anchors)[m]);
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
  c.normal = manifold.normal_world;
  c.tangent = TangentBasis(c.normal);
  c.inverse_mass_a = a.inverse_mass;
  c.inverse_mass_b = b.inverse_mass;
  c.friction = manifold.friction;
  c.restitution = manifold.restitution;
  // A spring stiffer than a quarter of the sub-step rate is not followed by
  // one iteration a sub-step (Box2D v3 caps it the same way); a contact
  // with a body that does not move takes twice the frequency.
  const double max_hertz = 0.25 / h_;
  const double hertz = input.settings.contact_hertz * (a.moving && b.moving ? 1.0 : 2.0);
  const Softness soft =
      MakeSoftness(std::min(hertz, max_hertz), input.settings.contact_damping_ratio, h_);
  c.bias_rate = soft.bias_rate;
  c.mass_scale = soft.mass_scale;
  c.impulse_scale = soft.impulse_scale;
  c.point_count = manifold.point_count;
  const double share = 1.0 / substeps_;
  for (int i = 0; i < c.point_count; ++i) {
    const SolverPoint& from = manifold.points[i];
    Point& p = c.points[i];
    p.rn_a = from.r_a.cross(c.normal);
    p.rn_b = from.r_b.cross(c.normal);
    p.ang_a = a.inverse_inertia_world * p.rn_a;
    p.ang_b = b.inverse_inertia_world * p.rn_b;
    p.start_separation = from.separation;
    p.normal_mass =
        InverseOrZero(a.inverse_mass + b.inverse_mass + p.rn_a.dot(p.ang_a) + p.rn_b.dot(p.ang_b));
    p.normal_impulse = share * std::max(from.normal_impulse, 0.0);
    p.preload = share * std::max(from.preload, 0.0);
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
  c->anchor_a = anchor.valid ? a.orientation * anchor.on_a : centre_a;
  c->anchor_b = anchor.valid ? b.orientation * anchor.on_b : centre_b;
  const Vec3 anchors_apart = a.position + c->anchor_a - b.position - c->anchor_b;
  for (int k = 0; k < 2; ++k) {
    const Vec3& t = c->tangent[k];
    c->ct_a[k] = centre_a.cross(t);
    c->ct_b[k] = centre_b.cross(t);
    c->ang_t_a[k] = a.inverse_inertia_world * c->ct_a[k];
    c->ang_t_b[k] = b.inverse_inertia_world * c->ct_b[k];
    c->slip_start[k] = t.dot(anchors_apart);
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
  c->twist_a = a.inverse_inertia_world * c->normal;
  c->twist_b = b.inverse_inertia_world * c->normal;
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
  UnpackBlocks(thread, threads);
  barrier->Wait();
  // Every thread reads the flag after the last relax pass's barrier, so all
  // take the same branch.
  if (may_bounce_.load(std::memory_order_relaxed)) {
    RunPass(Pass::kRestitution, thread, threads, barrier);
  }
}

void SoftContactSolver::RunPass(Pass pass, int thread, int threads, SpinBarrier* barrier) {
  const std::vector<std::uint32_t>& start = colouring_.colour_start;
  for (int colour = 0; colour < colouring_.colour_count(); ++colour) {
    if (!blocks_.empty() && pass != Pass::kRestitution) {
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
  if (colouring_.overflow_count() == 0) return;
  if (thread == 0) {
    for (std::size_t k = start.back(); k < constraints_.size(); ++k) {
      Apply(pass, &constraints_[k]);
    }
  }
  barrier->Wait();
}

// Four consecutive constraints of a colour to a block, the colour's last
// block holding what is left; none without simd_lanes.
void SoftContactSolver::ListBlocks() {
  block_start_.assign(1, 0);
  if (!lanes_) {
    blocks_.clear();
    return;
  }
  const std::vector<std::uint32_t>& start = colouring_.colour_start;
  std::size_t count = 0;
  for (int colour = 0; colour < colouring_.colour_count(); ++colour) {
    const std::size_t size = start[colour + 1] - start[colour];
    count += (size + kBatchLanes - 1) / kBatchLanes;
    block_start_.push_back(static_cast<std::uint32_t>(count));
  }
  // Kept from step to step: PackSoftBlock writes what a block's rows use.
  blocks_.resize(count);
}

void SoftContactSolver::UnpackBlocks(int thread, int threads) {
  const auto [begin, end] = Share(blocks_.size(), thread, threads);
  for (std::size_t b = begin; b < end; ++b) UnpackSoftBlock(blocks_[b], &constraints_);
}

void SoftContactSolver::ApplyToBlocks(Pass pass, int colour, int thread, int threads) {
  SoftLaneContext context;
  context.states = &states_;
  context.h = h_;
  context.max_push_velocity = max_push_velocity_;
  context.collision_velocity_threshold = collision_velocity_threshold_;
  const std::size_t first_block = block_start_[colour];
  const auto [begin, end] = Share(block_start_[colour + 1] - first_block, thread, threads);
  SoftLaneBlock* const from = blocks_.data() + first_block + begin;
  SoftLaneBlock* const to = blocks_.data() + first_block + end;
  if (pass == Pass::kWarmStart) {
    WarmStartSoftBlocks(context, from, to);
  } else if (SolveSoftBlocks(context, pass == Pass::kSolve, from, to)) {
    may_bounce_.store(true, std::memory_order_relaxed);
  }
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

// Each point's impulse of the last sub-step, applied again.
void SoftContactSolver::WarmStart(Constraint* c) {
  PairVelocities v(&states_[c->body_a], &states_[c->body_b], moving_mask_[c->body_a],
                   moving_mask_[c->body_b]);
  for (int i = 0; i < c->point_count; ++i) {
    const Point& p = c->points[i];
    v.Apply(p.normal_impulse * c->normal, c->inverse_mass_a, c->inverse_mass_b,
            p.normal_impulse * p.ang_a, p.normal_impulse * p.ang_b);
  }
  const std::array<double, 2>& t = c->tangent_impulse;
  v.Apply(t[0] * c->tangent[0] + t[1] * c->tangent[1], c->inverse_mass_a, c->inverse_mass_b,
          t[0] * c->ang_t_a[0] + t[1] * c->ang_t_a[1] + c->twist_impulse * c->twist_a,
          t[0] * c->ang_t_b[0] + t[1] * c->ang_t_b[1] + c->twist_impulse * c->twist_b);
  v.Store();
}

// One Gauss-Seidel update of each point's normal row, then of the friction.
// With use_bias the penetrating rows are soft (the spring pushes them apart
// at most at max_push_velocity); without (the relax pass) every touching row
// is rigid, v_n >= 0. A point still apart, s > 0, is a speculative row
// either way: it may close by s within the sub-step, no more. The relax
// pass ends the sub-step, and adds its impulses to the step's totals. The
// separation now is s = s0 + n.(dx_a - dx_b) + (r_a x n).dtheta_a -
// (r_b x n).dtheta_b, the bodies' motion since the step began to first
// order in their turn.
void SoftContactSolver::Solve(Constraint* c, bool use_bias) {
  const State& a = states_[c->body_a];
  const State& b = states_[c->body_b];
  PairVelocities v(&states_[c->body_a], &states_[c->body_b], moving_mask_[c->body_a],
                   moving_mask_[c->body_b]);
  const Vec3& n = c->normal;
  const double inverse_h = 1.0 / h_;
  const double moved = n.dot(a.delta_position - b.delta_position);
  std::array<double, ContactManifold::kMaxPoints> separation;
  for (int i = 0; i < c->point_count; ++i) {
    Point& p = c->points[i];
    separation[i] =
        p.start_separation + moved + p.rn_a.dot(a.delta_angle) - p.rn_b.dot(b.delta_angle);
    const double vn = v.Along(n, p.rn_a, p.rn_b);
    if (!p.closed && separation[i] + h_ * vn <= 0.0) {
      // The point would touch within this sub-step: the speed it closes at,
      // before any of this manifold's impulses, is the one its restitution
      // answers. Either pass may be the first to see it (the relax pass
      // follows the positions' update).
      p.closed = true;
      p.approach_velocity = vn;
      if (vn < -collision_velocity_threshold_) may_bounce_.store(true, std::memory_order_relaxed);
    }
  }
  for (int i = 0; i < c->point_count; ++i) {
    Point& p = c->points[i];
    const double s = separation[i];
    const double vn = v.Along(n, p.rn_a, p.rn_b);
    double bias = 0.0;
    double mass_scale = 1.0;
    double impulse_scale = 0.0;
    if (s > 0.0) {
      bias = s * inverse_h;
    } else if (use_bias) {
      bias = std::max(c->bias_rate * s, -max_push_velocity_);
      mass_scale = c->mass_scale;
      impulse_scale = c->impulse_scale;
    }
    const double change =
        -p.normal_mass * mass_scale * (vn + bias) - impulse_scale * (p.normal_impulse - p.preload);
    const double next = std::max(p.normal_impulse + change, 0.0);
    const double applied = next - p.normal_impulse;
    p.normal_impulse = next;
    p.max_normal_impulse = std::max(p.max_normal_impulse, applied);
    v.Apply(applied * n, c->inverse_mass_a, c->inverse_mass_b, applied * p.ang_a,
            applied * p.ang_b);
  }
  SolveFriction(c, use_bias, &v);
  if (!use_bias) {
    for (int i = 0; i < c->point_count; ++i) {
      c->points[i].total_normal_impulse += c->points[i].normal_impulse;
    }
    c->total_tangent_impulse[0] += c->tangent_impulse[0];
    c->total_tangent_impulse[1] += c->tangent_impulse[1];
  }
  v.Store();
}

// Coulomb's cone at the centroid, |l_t| <= mu sum l_n, the tangent impulse
// clamped as a vector; then the twist, |l_w| <= mu sum l_n arm. One bound
// for the whole face keeps friction from following each corner's load as
// a box rocks: per point, the loads' flicker fed a rocking mode of the
// stacks. With use_bias the tangent rows are soft springs on the anchors'
// slip, t_k.((x_a + anchor_a) - (x_b + anchor_b)) moved with the bodies.
void SoftContactSolver::SolveFriction(Constraint* c, bool use_bias, PairVelocities* v) const {
  double normal = 0.0;
  for (int i = 0; i < c->point_count; ++i) normal += c->points[i].normal_impulse;
  const double limit = c->friction * normal;
  std::array<double, 2> velocity;
  for (int k = 0; k < 2; ++k) velocity[k] = v->Along(c->tangent[k], c->ct_a[k], c->ct_b[k]);
  double mass_scale = 1.0;
  double impulse_scale = 0.0;
  if (use_bias) {
    const State& a = *v->state_a;
    const State& b = *v->state_b;
    const Vec3 moved = a.delta_position - b.delta_position;
    for (int k = 0; k < 2; ++k) {
      const double slip = c->slip_start[k] + c->tangent[k].dot(moved) +
                          c->anchor_t_a[k].dot(a.delta_angle) - c->anchor_t_b[k].dot(b.delta_angle);
      velocity[k] += c->bias_rate * slip;
    }
    mass_scale = c->mass_scale;
    impulse_scale = c->impulse_scale;
  }
  const std::array<double, 3>& block = c->tangent_block;
  const std::array<double, 2>& old = c->tangent_impulse;
  std::array<double, 2> next = {
      old[0] - mass_scale * (block[0] * velocity[0] + block[1] * velocity[1]) -
          impulse_scale * old[0],
      old[1] - mass_scale * (block[1] * velocity[0] + block[2] * velocity[1]) -
          impulse_scale * old[1]};
  const double length_squared = next[0] * next[0] + next[1] * next[1];
  if (length_squared > limit * limit) {
    const double scale = limit / std::sqrt(length_squared);
    next = {next[0] * scale, next[1] * scale};
  }
  const double d0 = next[0] - old[0];
  const double d1 = next[1] - old[1];
  v->Apply(d0 * c->tangent[0] + d1 * c->tangent[1], c->inverse_mass_a, c->inverse_mass_b,
           d0 * c->ang_t_a[0] + d1 * c->ang_t_a[1], d0 * c->ang_t_b[0] + d1 * c->ang_t_b[1]);
  c->tangent_impulse = next;
  const double twist_limit = limit * c->twist_arm;
  const double spin = c->normal.dot(v->w_a - v->w_b);
  const double twist =
      std::clamp(c->twist_impulse - c->twist_mass * spin, -twist_limit, twist_limit);
  const double turn = twist - c->twist_impulse;
  v->Apply(Vec3::Zero(), 0.0, 0.0, turn * c->twist_a, turn * c->twist_b);
  c->twist_impulse = twist;
}

// After the sub-steps: a point that closed faster than the collision
// threshold, and was pushed, leaves at e times the speed it closed at,
// v_n >= -e v_approach (Newton's law of restitution, which Baraff's
// colliding contact obeys), the normal impulse only growing. With e = 0
// this ends the approach within the step. Only a point that touches at the
// step's end (s within touch_tolerance) bounces: one that closed in the last
// sub-step's relax pass is still apart (its speculative row holds it at
// s / h), and carries its approach speed to the next step, where it
// touches; carried once, so a point that closed and stayed apart (its body
// stopped by its other points) does not report an old speed later.
void SoftContactSolver::Restitute(Constraint* c) {
  const State& a = states_[c->body_a];
  const State& b = states_[c->body_b];
  PairVelocities v(&states_[c->body_a], &states_[c->body_b], moving_mask_[c->body_a],
                   moving_mask_[c->body_b]);
  const double moved = c->normal.dot(a.delta_position - b.delta_position);
  for (int i = 0; i < c->point_count; ++i) {
    Point& p = c->points[i];
    const double s =
        p.start_separation + moved + p.rn_a.dot(a.delta_angle) - p.rn_b.dot(b.delta_angle);
    p.touched = p.closed && s <= touch_tolerance_;
    if (!p.touched || p.approach_velocity > -collision_velocity_threshold_ ||
        p.max_normal_impulse == 0.0) {
      continue;
    }
    const double vn = v.Along(c->normal, p.rn_a, p.rn_b);
    const double change = -p.normal_mass * (vn + c->restitution * p.approach_velocity);
    const double next = std::max(p.normal_impulse + change, 0.0);
    const double applied = next - p.normal_impulse;
    p.normal_impulse = next;
    p.total_normal_impulse += applied;
    v.Apply(applied * c->normal, c->inverse_mass_a, c->inverse_mass_b, applied * p.ang_a,
            applied * p.ang_b);
  }
  v.Store();
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
void SoftContactSolver::Store(const Constraint& c, SolverManifold* manifold,
                              FrictionAnchor* anchor) const {
  StoreAnchor(c, anchor);
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
