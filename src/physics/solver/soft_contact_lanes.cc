#include "physics/solver/soft_contact_lanes.h"

#include <algorithm>
#include <cmath>

namespace rigid_body_sim::physics {
// The AVX2 clones load the lanes aligned; the vectors keep their alignment
// through LaneStored (a template argument would lose it).
static_assert(alignof(SoftLaneBlock) == sizeof(LaneDoubles) &&
                  alignof(CompactSoftLaneBlock) == sizeof(LaneDoubles),
              "lane blocks are aligned to a vector");
static_assert(alignof(decltype(CompactSoftLaneBlock::normal[0])) == sizeof(LaneFloats),
              "float lanes are aligned to their size");

namespace {

// The velocities of a block's bodies, lane l holding its constraint's body
// A and body B, and their motion since the step began.
struct LaneBodies {
  LaneDoubles v_a[3], w_a[3], v_b[3], w_b[3];              // m/s, rad/s
  LaneDoubles dx_a[3], dx_b[3], dtheta_a[3], dtheta_b[3];  // m, rad
};

// The velocities, and with kMotion the motion too (the warm start reads no
// motion).
template <bool kMotion, typename Block>
[[gnu::always_inline]] inline void Gather(const Block& block,
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
template <typename Block>
[[gnu::always_inline]] inline void Scatter(const Block& block, const LaneBodies& bodies,
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

// PairVelocities::Apply in the lanes of `on`: impulse p on A, -p on B,
// their turns given.
template <typename Block>
[[gnu::always_inline]] inline void Apply(const LaneMask& on, const LaneDoubles (&p)[3],
                                         const Block& c, const LaneDoubles (&turn_a)[3],
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
template <typename Block>
[[gnu::always_inline]] inline void ApplyNormal(const Block& c, int i, const LaneDoubles& impulse,
                                               LaneBodies* v) {
  const auto& p = c.points[i];
  LaneDoubles normal[3], ang_a[3], ang_b[3];
  Widen(c.normal, normal);
  Widen(p.ang_a, ang_a);
  Widen(p.ang_b, ang_b);
  LaneDoubles push[3], turn_a[3], turn_b[3];
  for (int axis = 0; axis < 3; ++axis) {
    push[axis] = impulse * normal[axis];
    turn_a[axis] = impulse * ang_a[axis];
    turn_b[axis] = impulse * ang_b[axis];
  }
  Apply(c.point_count > i, push, c, turn_a, turn_b, v);
}

template <typename Block>
[[gnu::always_inline]] inline void WarmStartBlock(const SoftLaneContext& context, const Block& c) {
  LaneBodies v;
  Gather</*kMotion=*/false>(c, *context.states, &v);
  for (int i = 0; i < c.max_points; ++i) {
    ApplyNormal(c, i, c.points[i].normal_impulse, &v);
  }
  const LaneDoubles(&t)[2] = c.tangent_impulse;
  LaneDoubles tangent[2][3], ang_t_a[2][3], ang_t_b[2][3], twist_a[3], twist_b[3];
  for (int k = 0; k < 2; ++k) {
    Widen(c.tangent[k], tangent[k]);
    Widen(c.ang_t_a[k], ang_t_a[k]);
    Widen(c.ang_t_b[k], ang_t_b[k]);
  }
  Widen(c.twist_a, twist_a);
  Widen(c.twist_b, twist_b);
  LaneDoubles push[3], turn_a[3], turn_b[3];
  for (int axis = 0; axis < 3; ++axis) {
    push[axis] = t[0] * tangent[0][axis] + t[1] * tangent[1][axis];
    turn_a[axis] =
        t[0] * ang_t_a[0][axis] + t[1] * ang_t_a[1][axis] + c.twist_impulse * twist_a[axis];
    turn_b[axis] =
        t[0] * ang_t_b[0][axis] + t[1] * ang_t_b[1][axis] + c.twist_impulse * twist_b[axis];
  }
  const LaneMask all = LaneMask{} == LaneMask{};
  Apply(all, push, c, turn_a, turn_b, &v);
  Scatter(c, v, context.states);
}

// Each point's separation now, and a point that would close within this
// sub-step marked closed with its approach speed (SoftContactSolver::Solve's
// first loop). Returns whether one closed faster than the threshold.
template <typename Block>
[[gnu::always_inline]] inline bool Separations(const SoftLaneContext& context, Block* c,
                                               const LaneBodies& v, LaneDoubles* separation) {
  LaneDoubles dx[3];
  for (int axis = 0; axis < 3; ++axis) dx[axis] = v.dx_a[axis] - v.dx_b[axis];
  LaneDoubles normal[3];
  Widen(c->normal, normal);
  LaneDoubles moved;
  Dot(normal, dx, &moved);
  const LaneDoubles h = LaneDoubles{} + context.h;
  const LaneDoubles threshold = LaneDoubles{} - context.collision_velocity_threshold;
  LaneMask fast = {};
  for (int i = 0; i < c->max_points; ++i) {
    auto& p = c->points[i];
    LaneDoubles rn_a[3], rn_b[3];
    Widen(p.rn_a, rn_a);
    Widen(p.rn_b, rn_b);
    LaneDoubles turn_a, turn_b;
    Dot(rn_a, v.dtheta_a, &turn_a);
    Dot(rn_b, v.dtheta_b, &turn_b);
    LaneDoubles start;
    Widen(p.start_separation, &start);
    separation[i] = start + moved + turn_a - turn_b;
    LaneDoubles vn;
    Along(v, normal, rn_a, rn_b, &vn);
    const LaneMask closing =
        (c->point_count > i) & ~p.closed & (separation[i] + h * vn <= LaneDoubles{});
    p.closed |= closing;
    p.approach_velocity = closing ? vn : p.approach_velocity;
    fast |= closing & (vn < threshold);
  }
  return AnyLane(fast);
}

// The solve pass's drift correction of the tangent rows: the slip of the
// friction anchors along t_k since the step began, s_k = s0_k + t_k.dx +
// (anchor_a x t_k).dtheta_a - (anchor_b x t_k).dtheta_b, adds b s_k to
// their velocities.
template <typename Block>
[[gnu::always_inline]] inline void AddSlipBias(const Block& c, const LaneBodies& v,
                                               const LaneDoubles (&tangent)[2][3],
                                               LaneDoubles (&velocity)[2]) {
  LaneDoubles dx[3], anchor_a[3], anchor_b[3], bias_rate;
  for (int axis = 0; axis < 3; ++axis) dx[axis] = v.dx_a[axis] - v.dx_b[axis];
  Widen(c.anchor_a, anchor_a);
  Widen(c.anchor_b, anchor_b);
  Widen(c.bias_rate, &bias_rate);
  for (int k = 0; k < 2; ++k) {
    LaneDoubles anchor_t_a[3], anchor_t_b[3];
    Cross(anchor_a, tangent[k], anchor_t_a);
    Cross(anchor_b, tangent[k], anchor_t_b);
    LaneDoubles along, turn_a, turn_b, slip_start;
    Dot(tangent[k], dx, &along);
    Dot(anchor_t_a, v.dtheta_a, &turn_a);
    Dot(anchor_t_b, v.dtheta_b, &turn_b);
    Widen(c.slip_start[k], &slip_start);
    const LaneDoubles slip = slip_start + along + turn_a - turn_b;
    velocity[k] += bias_rate * slip;
  }
}

// The twist row about the normal, bounded by mu times the normal impulse
// times the twist arm (SoftContactSolver::SolveFriction's last row).
template <typename Block>
[[gnu::always_inline]] inline void SolveTwistLanes(const LaneDoubles& limit, Block* c,
                                                   LaneBodies* v) {
  LaneDoubles twist_arm;
  Widen(c->twist_arm, &twist_arm);
  const LaneDoubles twist_limit = limit * twist_arm;
  LaneDoubles spin_rate[3], normal_axis[3], twist_a[3], twist_b[3];
  for (int axis = 0; axis < 3; ++axis) spin_rate[axis] = v->w_a[axis] - v->w_b[axis];
  Widen(c->normal, normal_axis);
  Widen(c->twist_a, twist_a);
  Widen(c->twist_b, twist_b);
  LaneDoubles spin;
  Dot(normal_axis, spin_rate, &spin);
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
    v->w_a[axis] = v->w_a[axis] + turn * twist_a[axis];
    v->v_b[axis] = v->v_b[axis] - zero * zero;
    v->w_b[axis] = v->w_b[axis] - turn * twist_b[axis];
  }
  c->twist_impulse = twist;
}

// Coulomb's cone at the centroid and the twist, as
// SoftContactSolver::SolveFriction.
template <typename Block>
[[gnu::always_inline]] inline void SolveFrictionLanes(bool use_bias, Block* c, LaneBodies* v) {
  LaneDoubles normal = {};
  for (int i = 0; i < c->max_points; ++i) {
    const auto& p = c->points[i];
    normal = c->point_count > i ? normal + p.normal_impulse : normal;
  }
  LaneDoubles friction;
  Widen(c->friction, &friction);
  const LaneDoubles limit = friction * normal;
  LaneDoubles tangent[2][3], centre_a[3], centre_b[3];
  Widen(c->tangent[0], tangent[0]);
  Widen(c->tangent[1], tangent[1]);
  Widen(c->centre_a, centre_a);
  Widen(c->centre_b, centre_b);
  LaneDoubles velocity[2];
  for (int k = 0; k < 2; ++k) {
    LaneDoubles ct_a[3], ct_b[3];
    Cross(centre_a, tangent[k], ct_a);
    Cross(centre_b, tangent[k], ct_b);
    Along(*v, tangent[k], ct_a, ct_b, &velocity[k]);
  }
  LaneDoubles mass_scale = LaneDoubles{} + 1.0;
  LaneDoubles impulse_scale = {};
  if (use_bias) {
    AddSlipBias(*c, *v, tangent, velocity);
    Widen(c->mass_scale, &mass_scale);
    Widen(c->impulse_scale, &impulse_scale);
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
  LaneDoubles ang_t_a[2][3], ang_t_b[2][3];
  for (int k = 0; k < 2; ++k) {
    Widen(c->ang_t_a[k], ang_t_a[k]);
    Widen(c->ang_t_b[k], ang_t_b[k]);
  }
  LaneDoubles push[3], turn_a[3], turn_b[3];
  for (int axis = 0; axis < 3; ++axis) {
    push[axis] = d0 * tangent[0][axis] + d1 * tangent[1][axis];
    turn_a[axis] = d0 * ang_t_a[0][axis] + d1 * ang_t_a[1][axis];
    turn_b[axis] = d0 * ang_t_b[0][axis] + d1 * ang_t_b[1][axis];
  }
  const LaneMask all = LaneMask{} == LaneMask{};
  Apply(all, push, *c, turn_a, turn_b, v);
  c->tangent_impulse[0] = next[0];
  c->tangent_impulse[1] = next[1];
  SolveTwistLanes(limit, c, v);
}

template <typename Block>
[[gnu::always_inline]] inline bool SolveBlock(const SoftLaneContext& context, bool use_bias,
                                              Block* c) {
  LaneBodies v;
  Gather</*kMotion=*/true>(*c, *context.states, &v);
  LaneDoubles separation[ContactManifold::kMaxPoints];
  const bool fast = Separations(context, c, v, separation);
  const LaneDoubles zero = {};
  const LaneDoubles inverse_h = zero + 1.0 / context.h;
  const LaneDoubles max_push = zero - context.max_push_velocity;
  const LaneDoubles one = zero + 1.0;
  LaneDoubles normal[3], bias_rate, soft_mass_scale, soft_impulse_scale;
  Widen(c->normal, normal);
  Widen(c->bias_rate, &bias_rate);
  Widen(c->mass_scale, &soft_mass_scale);
  Widen(c->impulse_scale, &soft_impulse_scale);
  for (int i = 0; i < c->max_points; ++i) {
    auto& p = c->points[i];
    const LaneDoubles s = separation[i];
    LaneDoubles rn_a[3], rn_b[3];
    Widen(p.rn_a, rn_a);
    Widen(p.rn_b, rn_b);
    LaneDoubles vn;
    Along(v, normal, rn_a, rn_b, &vn);
    const LaneMask apart = s > zero;
    LaneDoubles bias = zero;
    LaneDoubles mass_scale = one;
    LaneDoubles impulse_scale = zero;
    if (use_bias) {
      const LaneDoubles spring = bias_rate * s;
      bias = spring < max_push ? max_push : spring;
      mass_scale = soft_mass_scale;
      impulse_scale = soft_impulse_scale;
    }
    bias = apart ? s * inverse_h : bias;
    mass_scale = apart ? one : mass_scale;
    impulse_scale = apart ? zero : impulse_scale;
    LaneDoubles preload;
    Widen(p.preload, &preload);
    const LaneDoubles change =
        -p.normal_mass * mass_scale * (vn + bias) - impulse_scale * (p.normal_impulse - preload);
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
      auto& p = c->points[i];
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

template <typename Block>
void ExtractSoftConstraint(const Block& block, int lane, bool rows, SoftConstraint* constraint) {
  SoftConstraint& c = *constraint;
  auto get = [lane](const auto& lanes) {
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
    const auto& from = block.points[i];
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

namespace {

template <typename Block>
[[gnu::always_inline]] inline void WarmStartBlocks(const SoftLaneContext& context, Block* begin,
                                                   Block* end) {
  for (Block* block = begin; block != end; ++block) WarmStartBlock(context, *block);
}

template <typename Block>
[[gnu::always_inline]] inline bool SolveBlocks(const SoftLaneContext& context, bool use_bias,
                                               Block* begin, Block* end) {
  bool fast = false;
  for (Block* block = begin; block != end; ++block) {
    fast |= use_bias ? SolveBlock(context, true, block) : SolveBlock(context, false, block);
  }
  return fast;
}

}  // namespace

template void ExtractSoftConstraint(const SoftLaneBlock&, int, bool, SoftConstraint*);
template void ExtractSoftConstraint(const CompactSoftLaneBlock&, int, bool, SoftConstraint*);

// The entry points are plain functions, one per block layout, as GCC
// clones plain functions for the two targets (RBS_SIMD_CLONES).
RBS_SIMD_CLONES void WarmStartSoftBlocks(const SoftLaneContext& context, SoftLaneBlock* begin,
                                         SoftLaneBlock* end) {
  WarmStartBlocks(context, begin, end);
}

RBS_SIMD_CLONES void WarmStartSoftBlocks(const SoftLaneContext& context,
                                         CompactSoftLaneBlock* begin, CompactSoftLaneBlock* end) {
  WarmStartBlocks(context, begin, end);
}

RBS_SIMD_CLONES bool SolveSoftBlocks(const SoftLaneContext& context, bool use_bias,
                                     SoftLaneBlock* begin, SoftLaneBlock* end) {
  return SolveBlocks(context, use_bias, begin, end);
}

RBS_SIMD_CLONES bool SolveSoftBlocks(const SoftLaneContext& context, bool use_bias,
                                     CompactSoftLaneBlock* begin, CompactSoftLaneBlock* end) {
  return SolveBlocks(context, use_bias, begin, end);
}

}  // namespace rigid_body_sim::physics
