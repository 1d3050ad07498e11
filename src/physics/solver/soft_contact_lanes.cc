#include "physics/solver/soft_contact_lanes.h"

#include <algorithm>
#include <cmath>

namespace rigid_body_sim::physics {
namespace {

// Lane `lane` of the 3-vectors lanes[axis] set from v.
void SetLane(const Vec3& v, int lane, LaneDoubles (&lanes)[3]) {
  for (int axis = 0; axis < 3; ++axis) lanes[axis][lane] = v[axis];
}

void PackPoint(const SoftPoint& from, int lane, SoftLanePoint* to, LaneMask* carried) {
  SetLane(from.rn_a, lane, to->rn_a);
  SetLane(from.rn_b, lane, to->rn_b);
  SetLane(from.ang_a, lane, to->ang_a);
  SetLane(from.ang_b, lane, to->ang_b);
  to->start_separation[lane] = from.start_separation;
  to->normal_mass[lane] = from.normal_mass;
  to->normal_impulse[lane] = from.normal_impulse;
  to->preload[lane] = from.preload;
  to->max_normal_impulse[lane] = from.max_normal_impulse;
  to->total_normal_impulse[lane] = from.total_normal_impulse;
  to->approach_velocity[lane] = from.approach_velocity;
  to->closed[lane] = from.closed ? -1 : 0;
  (*carried)[lane] = from.carried ? -1 : 0;
}

void PackFriction(const SoftConstraint& c, int lane, SoftLaneBlock* block) {
  for (int k = 0; k < 2; ++k) {
    SetLane(c.tangent[k], lane, block->tangent[k]);
    SetLane(c.ang_t_a[k], lane, block->ang_t_a[k]);
    SetLane(c.ang_t_b[k], lane, block->ang_t_b[k]);
    block->slip_start[k][lane] = c.slip_start[k];
    block->tangent_impulse[k][lane] = c.tangent_impulse[k];
    block->total_tangent_impulse[k][lane] = c.total_tangent_impulse[k];
  }
  SetLane(c.centre_a, lane, block->centre_a);
  SetLane(c.centre_b, lane, block->centre_b);
  SetLane(c.twist_a, lane, block->twist_a);
  SetLane(c.twist_b, lane, block->twist_b);
  for (int k = 0; k < 3; ++k) block->tangent_block[k][lane] = c.tangent_block[k];
  block->twist_mass[lane] = c.twist_mass;
  block->twist_arm[lane] = c.twist_arm;
  block->twist_impulse[lane] = c.twist_impulse;
}

// The velocities of a block's bodies, lane l holding its constraint's body
// A and body B, and their motion since the step began.
struct LaneBodies {
  LaneDoubles v_a[3], w_a[3], v_b[3], w_b[3];              // m/s, rad/s
  LaneDoubles dx_a[3], dx_b[3], dtheta_a[3], dtheta_b[3];  // m, rad
};

// The velocities, and with kMotion the motion too (the warm start reads no
// motion).
template <bool kMotion>
[[gnu::always_inline]] inline void Gather(const SoftLaneBlock& block,
                                          const std::vector<SoftRowState>& states,
                                          LaneBodies* bodies) {
  for (int lane = 0; lane < kBatchLanes; ++lane) {
    const SoftRowState& a = states[block.body_a[lane]];
    const SoftRowState& b = states[block.body_b[lane]];
    for (int axis = 0; axis < 3; ++axis) {
      bodies->v_a[axis][lane] = a.linear_velocity[axis];
      bodies->w_a[axis][lane] = a.angular_velocity[axis];
      bodies->v_b[axis][lane] = b.linear_velocity[axis];
      bodies->w_b[axis][lane] = b.angular_velocity[axis];
      if constexpr (!kMotion) continue;
      bodies->dx_a[axis][lane] = a.delta_position[axis];
      bodies->dx_b[axis][lane] = b.delta_position[axis];
      bodies->dtheta_a[axis][lane] = a.delta_angle[axis];
      bodies->dtheta_b[axis][lane] = b.delta_angle[axis];
    }
  }
}

// Only the moving bodies of the lanes that hold a constraint are written.
[[gnu::always_inline]] inline void Scatter(const SoftLaneBlock& block, const LaneBodies& bodies,
                                           std::vector<SoftRowState>* states) {
  for (int lane = 0; lane < block.lanes; ++lane) {
    if (block.moves_a[lane]) {
      SoftRowState& a = (*states)[block.body_a[lane]];
      for (int axis = 0; axis < 3; ++axis) {
        a.linear_velocity[axis] = bodies.v_a[axis][lane];
        a.angular_velocity[axis] = bodies.w_a[axis][lane];
      }
    }
    if (block.moves_b[lane]) {
      SoftRowState& b = (*states)[block.body_b[lane]];
      for (int axis = 0; axis < 3; ++axis) {
        b.linear_velocity[axis] = bodies.v_b[axis][lane];
        b.angular_velocity[axis] = bodies.w_b[axis][lane];
      }
    }
  }
}

// d.(v_a - v_b) + j_a.w_a - j_b.w_b, as PairVelocities::Along adds it.
[[gnu::always_inline]] inline void Along(const LaneBodies& v, const LaneDoubles (&d)[3],
                                         const LaneDoubles (&j_a)[3], const LaneDoubles (&j_b)[3],
                                         LaneDoubles* out) {
  LaneDoubles relative[3];
  for (int axis = 0; axis < 3; ++axis) relative[axis] = v.v_a[axis] - v.v_b[axis];
  LaneDoubles along, turn_a, turn_b;
  Dot(d, relative, &along);
  Dot(j_a, v.w_a, &turn_a);
  Dot(j_b, v.w_b, &turn_b);
  *out = along + turn_a - turn_b;
}

// a x b, with Eigen's cross's operations in its order (so a lane gives
// the bits that the scalar rows' precomputed products hold).
[[gnu::always_inline]] inline void Cross(const LaneDoubles (&a)[3], const LaneDoubles (&b)[3],
                                         LaneDoubles (&out)[3]) {
  out[0] = a[1] * b[2] - a[2] * b[1];
  out[1] = a[2] * b[0] - a[0] * b[2];
  out[2] = a[0] * b[1] - a[1] * b[0];
}

// PairVelocities::Apply in the lanes of `on`: impulse p on A, -p on B,
// their turns given.
[[gnu::always_inline]] inline void Apply(const LaneMask& on, const LaneDoubles (&p)[3],
                                         const SoftLaneBlock& c, const LaneDoubles (&turn_a)[3],
                                         const LaneDoubles (&turn_b)[3], LaneBodies* v) {
  for (int axis = 0; axis < 3; ++axis) {
    const LaneDoubles v_a = v->v_a[axis] + c.inverse_mass_a * p[axis];
    const LaneDoubles w_a = v->w_a[axis] + turn_a[axis];
    const LaneDoubles v_b = v->v_b[axis] - c.inverse_mass_b * p[axis];
    const LaneDoubles w_b = v->w_b[axis] - turn_b[axis];
    v->v_a[axis] = on ? v_a : v->v_a[axis];
    v->w_a[axis] = on ? w_a : v->w_a[axis];
    v->v_b[axis] = on ? v_b : v->v_b[axis];
    v->w_b[axis] = on ? w_b : v->w_b[axis];
  }
}

// The normal impulse `impulse` of point i applied (WarmStart's and the
// solve's push along n).
[[gnu::always_inline]] inline void ApplyNormal(const SoftLaneBlock& c, int i,
                                               const LaneDoubles& impulse, LaneBodies* v) {
  const SoftLanePoint& p = c.points[i];
  LaneDoubles push[3], turn_a[3], turn_b[3];
  for (int axis = 0; axis < 3; ++axis) {
    push[axis] = impulse * c.normal[axis];
    turn_a[axis] = impulse * p.ang_a[axis];
    turn_b[axis] = impulse * p.ang_b[axis];
  }
  Apply(c.point_count > i, push, c, turn_a, turn_b, v);
}

[[gnu::always_inline]] inline void WarmStartBlock(const SoftLaneContext& context,
                                                  const SoftLaneBlock& c) {
  LaneBodies v;
  Gather</*kMotion=*/false>(c, *context.states, &v);
  for (int i = 0; i < c.max_points; ++i) {
    ApplyNormal(c, i, c.points[i].normal_impulse, &v);
  }
  const LaneDoubles(&t)[2] = c.tangent_impulse;
  LaneDoubles push[3], turn_a[3], turn_b[3];
  for (int axis = 0; axis < 3; ++axis) {
    push[axis] = t[0] * c.tangent[0][axis] + t[1] * c.tangent[1][axis];
    turn_a[axis] =
        t[0] * c.ang_t_a[0][axis] + t[1] * c.ang_t_a[1][axis] + c.twist_impulse * c.twist_a[axis];
    turn_b[axis] =
        t[0] * c.ang_t_b[0][axis] + t[1] * c.ang_t_b[1][axis] + c.twist_impulse * c.twist_b[axis];
  }
  const LaneMask all = LaneMask{} == LaneMask{};
  Apply(all, push, c, turn_a, turn_b, &v);
  Scatter(c, v, context.states);
}

// Each point's separation now, and a point that would close within this
// sub-step marked closed with its approach speed (SoftContactSolver::Solve's
// first loop). Returns whether one closed faster than the threshold.
[[gnu::always_inline]] inline bool Separations(const SoftLaneContext& context, SoftLaneBlock* c,
                                               const LaneBodies& v, LaneDoubles* separation) {
  LaneDoubles dx[3];
  for (int axis = 0; axis < 3; ++axis) dx[axis] = v.dx_a[axis] - v.dx_b[axis];
  LaneDoubles moved;
  Dot(c->normal, dx, &moved);
  const LaneDoubles h = LaneDoubles{} + context.h;
  const LaneDoubles threshold = LaneDoubles{} - context.collision_velocity_threshold;
  LaneMask fast = {};
  for (int i = 0; i < c->max_points; ++i) {
    SoftLanePoint& p = c->points[i];
    LaneDoubles turn_a, turn_b;
    Dot(p.rn_a, v.dtheta_a, &turn_a);
    Dot(p.rn_b, v.dtheta_b, &turn_b);
    separation[i] = p.start_separation + moved + turn_a - turn_b;
    LaneDoubles vn;
    Along(v, c->normal, p.rn_a, p.rn_b, &vn);
    const LaneMask closing =
        (c->point_count > i) & ~p.closed & (separation[i] + h * vn <= LaneDoubles{});
    p.closed |= closing;
    p.approach_velocity = closing ? vn : p.approach_velocity;
    fast |= closing & (vn < threshold);
  }
  return AnyLane(fast);
}

// Coulomb's cone at the centroid and the twist, as
// SoftContactSolver::SolveFriction.
[[gnu::always_inline]] inline void SolveFrictionLanes(bool use_bias, SoftLaneBlock* c,
                                                      LaneBodies* v) {
  LaneDoubles normal = {};
  for (int i = 0; i < c->max_points; ++i) {
    const SoftLanePoint& p = c->points[i];
    normal = c->point_count > i ? normal + p.normal_impulse : normal;
  }
  const LaneDoubles limit = c->friction * normal;
  LaneDoubles velocity[2];
  for (int k = 0; k < 2; ++k) {
    LaneDoubles ct_a[3], ct_b[3];
    Cross(c->centre_a, c->tangent[k], ct_a);
    Cross(c->centre_b, c->tangent[k], ct_b);
    Along(*v, c->tangent[k], ct_a, ct_b, &velocity[k]);
  }
  LaneDoubles mass_scale = LaneDoubles{} + 1.0;
  LaneDoubles impulse_scale = {};
  if (use_bias) {
    LaneDoubles dx[3];
    for (int axis = 0; axis < 3; ++axis) dx[axis] = v->dx_a[axis] - v->dx_b[axis];
    for (int k = 0; k < 2; ++k) {
      LaneDoubles anchor_t_a[3], anchor_t_b[3];
      Cross(c->anchor_a, c->tangent[k], anchor_t_a);
      Cross(c->anchor_b, c->tangent[k], anchor_t_b);
      LaneDoubles along, turn_a, turn_b;
      Dot(c->tangent[k], dx, &along);
      Dot(anchor_t_a, v->dtheta_a, &turn_a);
      Dot(anchor_t_b, v->dtheta_b, &turn_b);
      const LaneDoubles slip = c->slip_start[k] + along + turn_a - turn_b;
      velocity[k] += c->bias_rate * slip;
    }
    mass_scale = c->mass_scale;
    impulse_scale = c->impulse_scale;
  }
  const LaneDoubles(&block)[3] = c->tangent_block;
  const LaneDoubles old[2] = {c->tangent_impulse[0], c->tangent_impulse[1]};
  LaneDoubles next[2] = {old[0] - mass_scale * (block[0] * velocity[0] + block[1] * velocity[1]) -
                             impulse_scale * old[0],
                         old[1] - mass_scale * (block[1] * velocity[0] + block[2] * velocity[1]) -
                             impulse_scale * old[1]};
  const LaneDoubles length_squared = next[0] * next[0] + next[1] * next[1];
  const LaneMask outside = length_squared > limit * limit;
  if (AnyLane(outside)) {
    for (int lane = 0; lane < kBatchLanes; ++lane) {
      if (!outside[lane]) continue;
      const double scale = limit[lane] / std::sqrt(length_squared[lane]);
      next[0][lane] *= scale;
      next[1][lane] *= scale;
    }
  }
  const LaneDoubles d0 = next[0] - old[0];
  const LaneDoubles d1 = next[1] - old[1];
  LaneDoubles push[3], turn_a[3], turn_b[3];
  for (int axis = 0; axis < 3; ++axis) {
    push[axis] = d0 * c->tangent[0][axis] + d1 * c->tangent[1][axis];
    turn_a[axis] = d0 * c->ang_t_a[0][axis] + d1 * c->ang_t_a[1][axis];
    turn_b[axis] = d0 * c->ang_t_b[0][axis] + d1 * c->ang_t_b[1][axis];
  }
  const LaneMask all = LaneMask{} == LaneMask{};
  Apply(all, push, *c, turn_a, turn_b, v);
  c->tangent_impulse[0] = next[0];
  c->tangent_impulse[1] = next[1];
  const LaneDoubles twist_limit = limit * c->twist_arm;
  LaneDoubles spin_rate[3];
  for (int axis = 0; axis < 3; ++axis) spin_rate[axis] = v->w_a[axis] - v->w_b[axis];
  LaneDoubles spin;
  Dot(c->normal, spin_rate, &spin);
  // std::clamp(x, lo, hi): lo where x < lo, else hi where hi < x, else x.
  const LaneDoubles x = c->twist_impulse - c->twist_mass * spin;
  const LaneDoubles low = -twist_limit;
  const LaneDoubles twist = x < low ? low : (twist_limit < x ? twist_limit : x);
  const LaneDoubles turn = twist - c->twist_impulse;
  // The scalar update applies its twist as an impulse of zero with inverse
  // masses of zero, adding 0 * 0 to each linear velocity; so do the lanes,
  // which keeps the sign of a velocity component of zero as it does.
  const LaneDoubles zero = {};
  for (int axis = 0; axis < 3; ++axis) {
    v->v_a[axis] = v->v_a[axis] + zero * zero;
    v->w_a[axis] = v->w_a[axis] + turn * c->twist_a[axis];
    v->v_b[axis] = v->v_b[axis] - zero * zero;
    v->w_b[axis] = v->w_b[axis] - turn * c->twist_b[axis];
  }
  c->twist_impulse = twist;
}

[[gnu::always_inline]] inline bool SolveBlock(const SoftLaneContext& context, bool use_bias,
                                              SoftLaneBlock* c) {
  LaneBodies v;
  Gather</*kMotion=*/true>(*c, *context.states, &v);
  LaneDoubles separation[ContactManifold::kMaxPoints];
  const bool fast = Separations(context, c, v, separation);
  const LaneDoubles zero = {};
  const LaneDoubles inverse_h = zero + 1.0 / context.h;
  const LaneDoubles max_push = zero - context.max_push_velocity;
  const LaneDoubles one = zero + 1.0;
  for (int i = 0; i < c->max_points; ++i) {
    SoftLanePoint& p = c->points[i];
    const LaneDoubles s = separation[i];
    LaneDoubles vn;
    Along(v, c->normal, p.rn_a, p.rn_b, &vn);
    const LaneMask apart = s > zero;
    LaneDoubles bias = zero;
    LaneDoubles mass_scale = one;
    LaneDoubles impulse_scale = zero;
    if (use_bias) {
      const LaneDoubles spring = c->bias_rate * s;
      bias = spring < max_push ? max_push : spring;
      mass_scale = c->mass_scale;
      impulse_scale = c->impulse_scale;
    }
    bias = apart ? s * inverse_h : bias;
    mass_scale = apart ? one : mass_scale;
    impulse_scale = apart ? zero : impulse_scale;
    const LaneDoubles change =
        -p.normal_mass * mass_scale * (vn + bias) - impulse_scale * (p.normal_impulse - p.preload);
    const LaneDoubles sum = p.normal_impulse + change;
    const LaneDoubles next = sum < zero ? zero : sum;
    const LaneDoubles applied = next - p.normal_impulse;
    const LaneMask present = c->point_count > i;
    p.normal_impulse = present ? next : p.normal_impulse;
    const LaneDoubles larger = p.max_normal_impulse < applied ? applied : p.max_normal_impulse;
    p.max_normal_impulse = present ? larger : p.max_normal_impulse;
    ApplyNormal(*c, i, applied, &v);
  }
  SolveFrictionLanes(use_bias, c, &v);
  if (!use_bias) {
    for (int i = 0; i < c->max_points; ++i) {
      SoftLanePoint& p = c->points[i];
      const LaneDoubles total = p.total_normal_impulse + p.normal_impulse;
      p.total_normal_impulse = c->point_count > i ? total : p.total_normal_impulse;
    }
    c->total_tangent_impulse[0] += c->tangent_impulse[0];
    c->total_tangent_impulse[1] += c->tangent_impulse[1];
  }
  Scatter(*c, v, context.states);
  return fast;
}

}  // namespace

void PackSoftBlock(const SoftConstraint* constraints, std::uint32_t first, int lanes,
                   const std::vector<std::uint8_t>& moving, SoftLaneBlock* block) {
  // Only the lanes and points that hold a row are written: the others keep
  // whatever finite values an earlier step left (a new block starts at
  // zero), which the updates compute with and then discard.
  block->lanes = lanes;
  block->max_points = 0;
  for (int lane = 0; lane < kBatchLanes; ++lane) {
    block->point_count[lane] = lane < lanes ? constraints[lane].point_count : 0;
  }
  for (int lane = 0; lane < kBatchLanes; ++lane) {
    // A lane without a constraint reads the first lane's bodies, and is
    // neither written back nor stored.
    const int from = lane < lanes ? lane : 0;
    const SoftConstraint& c = constraints[from];
    block->constraint[lane] = first + static_cast<std::uint32_t>(from);
    block->body_a[lane] = c.body_a;
    block->body_b[lane] = c.body_b;
    block->moves_a[lane] = lane < lanes && moving[c.body_a] != 0;
    block->moves_b[lane] = lane < lanes && moving[c.body_b] != 0;
    if (lane >= lanes) continue;
    block->max_points = std::max(block->max_points, c.point_count);
    SetLane(c.normal, lane, block->normal);
    block->inverse_mass_a[lane] = c.inverse_mass_a;
    block->inverse_mass_b[lane] = c.inverse_mass_b;
    block->friction[lane] = c.friction;
    block->restitution[lane] = c.restitution;
    block->bias_rate[lane] = c.bias_rate;
    block->mass_scale[lane] = c.mass_scale;
    block->impulse_scale[lane] = c.impulse_scale;
    SetLane(c.anchor_a, lane, block->anchor_a);
    SetLane(c.anchor_b, lane, block->anchor_b);
    PackFriction(c, lane, block);
    for (int i = 0; i < c.point_count; ++i) {
      PackPoint(c.points[i], lane, &block->points[i], &block->carried[i]);
    }
  }
}

void ExtractSoftConstraint(const SoftLaneBlock& block, int lane, bool rows,
                           SoftConstraint* constraint) {
  SoftConstraint& c = *constraint;
  auto get = [lane](const LaneDoubles(&lanes)[3]) {
    return Vec3(lanes[0][lane], lanes[1][lane], lanes[2][lane]);
  };
  c.body_a = block.body_a[lane];
  c.body_b = block.body_b[lane];
  if (rows) {
    c.normal = get(block.normal);
    c.inverse_mass_a = block.inverse_mass_a[lane];
    c.inverse_mass_b = block.inverse_mass_b[lane];
    c.restitution = block.restitution[lane];
  }
  c.friction = block.friction[lane];
  c.point_count = static_cast<int>(block.point_count[lane]);
  c.anchor_a = get(block.anchor_a);
  c.anchor_b = get(block.anchor_b);
  for (int k = 0; k < 2; ++k) {
    c.tangent[k] = get(block.tangent[k]);
    c.tangent_impulse[k] = block.tangent_impulse[k][lane];
    c.total_tangent_impulse[k] = block.total_tangent_impulse[k][lane];
  }
  c.twist_impulse = block.twist_impulse[lane];
  for (int i = 0; i < c.point_count; ++i) {
    const SoftLanePoint& from = block.points[i];
    SoftPoint& p = c.points[i];
    if (rows) {
      p.rn_a = get(from.rn_a);
      p.rn_b = get(from.rn_b);
      p.ang_a = get(from.ang_a);
      p.ang_b = get(from.ang_b);
      p.start_separation = from.start_separation[lane];
      p.normal_mass = from.normal_mass[lane];
    }
    p.normal_impulse = from.normal_impulse[lane];
    p.preload = from.preload[lane];
    p.max_normal_impulse = from.max_normal_impulse[lane];
    p.total_normal_impulse = from.total_normal_impulse[lane];
    p.approach_velocity = from.approach_velocity[lane];
    p.closed = from.closed[lane] != 0;
    p.carried = block.carried[i][lane] != 0;
    p.touched = false;
  }
}

RBS_SIMD_CLONES void WarmStartSoftBlocks(const SoftLaneContext& context, SoftLaneBlock* begin,
                                         SoftLaneBlock* end) {
  for (SoftLaneBlock* block = begin; block != end; ++block) WarmStartBlock(context, *block);
}

RBS_SIMD_CLONES bool SolveSoftBlocks(const SoftLaneContext& context, bool use_bias,
                                     SoftLaneBlock* begin, SoftLaneBlock* end) {
  bool fast = false;
  for (SoftLaneBlock* block = begin; block != end; ++block) {
    fast |= use_bias ? SolveBlock(context, true, block) : SolveBlock(context, false, block);
  }
  return fast;
}

}  // namespace rigid_body_sim::physics
