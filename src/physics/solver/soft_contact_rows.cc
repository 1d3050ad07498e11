// The soft step's scalar row updates (docs/design.md, "The soft step"): a
// manifold's warm start, its solve or relax pass with its friction, and its
// restitution, one manifold at a time. They are the reference the lanes of
// soft_contact_lanes.cc reproduce bit for bit, and they update the overflow
// set, the restitution pass and, without SoftStepSettings::simd_lanes,
// every manifold.
#include <algorithm>
#include <array>
#include <cmath>

#include "physics/solver/soft_contact_solver.h"

namespace rigid_body_sim::physics {

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

}  // namespace rigid_body_sim::physics
