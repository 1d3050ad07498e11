// The soft step's rows prepared from the solver manifolds (docs/design.md,
// "The soft step"): one constraint at a time for the scalar update and the
// overflow set (Prepare), or four at a time straight into a block's lanes
// (PrepareBlock). Both take each constraint's frame (normal, softness,
// friction centroid, twist arm and anchors) from the same scalar code
// (MakeFrame), and the softness from the step's two (MakeSoftnesses); the
// lanes then form the tangents, the rows' Jacobians, masses and starting
// impulses with the scalar code's floating-point operations in its order,
// so a block holds the bits that the scalar rows do (threads_test).
#include <algorithm>
#include <cmath>
#include <limits>

#include "physics/contact/contact_frame.h"
#include "physics/solver/soft_contact_solver.h"

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

// x as the rows keep what the sub-steps only read: rounded to a float in a
// step with compact blocks (SoftStepSettings::compact_blocks_from), so
// that the scalar update and the lanes compute with what those blocks hold.
double Kept(bool compact, double x) { return compact ? NarrowToFloat(x) : x; }
Vec3 Kept(bool compact, const Vec3& x) { return compact ? NarrowToFloat(x) : x; }

// NarrowToFloat in each lane of *x: std::clamp to a float's range, then
// rounded to the nearest float.
[[gnu::always_inline]] inline void Keep(bool compact, LaneDoubles* x) {
  if (!compact) return;
  constexpr double kLargest = std::numeric_limits<float>::max();
  const LaneDoubles low = LaneDoubles{} - kLargest;
  const LaneDoubles high = LaneDoubles{} + kLargest;
  const LaneDoubles clamped = *x < low ? low : (high < *x ? high : *x);
  *x = __builtin_convertvector(__builtin_convertvector(clamped, LaneFloats), LaneDoubles);
}

[[gnu::always_inline]] inline void Keep3(bool compact, LaneDoubles (&x)[3]) {
  for (LaneDoubles& axis : x) Keep(compact, &axis);
}

// 1 / k for k > 0, else 0 (a row neither body can move).
double InverseOrZero(double k) { return k > 0.0 ? 1.0 / k : 0.0; }

[[gnu::always_inline]] inline void InverseOrZero(const LaneDoubles& k, LaneDoubles* out) {
  const LaneDoubles zero = {};
  *out = k > zero ? (zero + 1.0) / k : zero;
}

// out = m x with Multiply's operations (types.h): row r is
// (m_r0 x_0 + m_r1 x_1) + m_r2 x_2. m is row-major, m[3 r + c].
[[gnu::always_inline]] inline void MultiplyLanes(const LaneDoubles (&m)[9],
                                                 const LaneDoubles (&x)[3], LaneDoubles (&out)[3]) {
  for (int row = 0; row < 3; ++row) {
    out[row] = m[3 * row] * x[0] + m[3 * row + 1] * x[1] + m[3 * row + 2] * x[2];
  }
}

// The lanes into a block's stored form: doubles as they are, or floats,
// which a compact step's values (Kept) are exactly.
[[gnu::always_inline]] inline void Put(const LaneDoubles& x, LaneDoubles* to) { *to = x; }
[[gnu::always_inline]] inline void Put(const LaneDoubles& x, LaneFloats* to) {
  *to = __builtin_convertvector(x, LaneFloats);
}
template <typename Stored>
[[gnu::always_inline]] inline void Put(const LaneDoubles (&x)[3], Stored (&to)[3]) {
  for (int axis = 0; axis < 3; ++axis) Put(x[axis], &to[axis]);
}

// Lane `lane` of the lanes set from v (lanes[axis] from v[axis]).
void SetLane(const Vec3& v, int lane, LaneDoubles (&lanes)[3]) {
  for (int axis = 0; axis < 3; ++axis) lanes[axis][lane] = v[axis];
}

// One side's bodies in lanes: what the rows read of them.
struct LaneBodySide {
  LaneDoubles inverse_mass;
  LaneDoubles inverse_inertia[9];  // world, row-major
  LaneDoubles linear_velocity[3];
  LaneDoubles angular_velocity[3];
  LaneDoubles position[3];
};

void SetLane(const SoftBody& body, int lane, LaneBodySide* side) {
  side->inverse_mass[lane] = body.inverse_mass;
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col) {
      side->inverse_inertia[3 * row + col][lane] = body.inverse_inertia_world(row, col);
    }
  }
  SetLane(body.linear_velocity, lane, side->linear_velocity);
  SetLane(body.angular_velocity, lane, side->angular_velocity);
  SetLane(body.position, lane, side->position);
}

// What the lanes' preparing reads besides the manifolds and bodies.
struct LanePrepareContext {
  bool compact;                         // the step's blocks are compact: Kept rounds
  double share;                         // 1 / sub-steps
  double collision_velocity_threshold;  // m/s
};

// The normal rows of PrepareBlock's lanes, as Prepare's loop over the
// points; a lane's points past its count start from zeros.
template <typename Block>
[[gnu::always_inline]] inline bool PreparePointLanes(
    const LanePrepareContext& context,
    const std::array<const SolverManifold*, kBatchLanes>& manifolds, const LaneBodySide& a,
    const LaneBodySide& b, const LaneDoubles (&normal)[3], Block* block) {
  const bool compact = context.compact;
  const LaneDoubles zero = {};
  const LaneDoubles share = zero + context.share;
  LaneDoubles relative[3];
  for (int axis = 0; axis < 3; ++axis)
    relative[axis] = a.linear_velocity[axis] - b.linear_velocity[axis];
  LaneMask fast = {};
  for (int i = 0; i < block->max_points; ++i) {
    LaneDoubles r_a[3] = {}, r_b[3] = {};
    LaneDoubles separation = {}, normal_impulse = {}, preload = {}, carried = {};
    for (int lane = 0; lane < kBatchLanes; ++lane) {
      if (i >= block->point_count[lane]) continue;
      const SolverPoint& from = manifolds[lane]->points[i];
      SetLane(from.r_a, lane, r_a);
      SetLane(from.r_b, lane, r_b);
      separation[lane] = from.separation;
      normal_impulse[lane] = from.normal_impulse;
      preload[lane] = from.preload;
      carried[lane] = from.carried_approach;
    }
    auto& p = block->points[i];
    LaneDoubles rn_a[3], rn_b[3], ang_a[3], ang_b[3];
    Cross(r_a, normal, rn_a);
    Cross(r_b, normal, rn_b);
    Keep3(compact, rn_a);
    Keep3(compact, rn_b);
    MultiplyLanes(a.inverse_inertia, rn_a, ang_a);
    MultiplyLanes(b.inverse_inertia, rn_b, ang_b);
    Keep3(compact, ang_a);
    Keep3(compact, ang_b);
    Put(rn_a, p.rn_a);
    Put(rn_b, p.rn_b);
    Put(ang_a, p.ang_a);
    Put(ang_b, p.ang_b);
    Keep(compact, &separation);
    Put(separation, &p.start_separation);
    LaneDoubles mass_a, mass_b;
    Dot(rn_a, ang_a, &mass_a);
    Dot(rn_b, ang_b, &mass_b);
    InverseOrZero(a.inverse_mass + b.inverse_mass + mass_a + mass_b, &p.normal_mass);
    p.normal_impulse = share * (normal_impulse < zero ? zero : normal_impulse);
    LaneDoubles kept_preload = share * (preload < zero ? zero : preload);
    Keep(compact, &kept_preload);
    Put(kept_preload, &p.preload);
    p.max_normal_impulse = zero;
    p.total_normal_impulse = zero;
    p.closed = carried < zero;
    block->carried[i] = p.closed;
    fast |= (block->point_count > i) & (carried < zero - context.collision_velocity_threshold);
    LaneDoubles along, turn_a, turn_b;
    Dot(normal, relative, &along);
    Dot(rn_a, a.angular_velocity, &turn_a);
    Dot(rn_b, b.angular_velocity, &turn_b);
    p.approach_velocity = p.closed ? carried : along + turn_a - turn_b;
  }
  return AnyLane(fast);
}

// The friction rows of PrepareBlock's lanes, as PrepareFriction.
template <typename Block>
[[gnu::always_inline]] inline void PrepareFrictionLanes(
    const LanePrepareContext& context, const LaneBodySide& a, const LaneBodySide& b,
    const LaneDoubles (&normal)[3], const LaneDoubles (&tangent)[2][3], Block* block) {
  const bool compact = context.compact;
  LaneDoubles centre_a[3], centre_b[3], anchors_apart[3];
  Widen(block->centre_a, centre_a);
  Widen(block->centre_b, centre_b);
  {
    LaneDoubles anchor_a[3], anchor_b[3];
    Widen(block->anchor_a, anchor_a);
    Widen(block->anchor_b, anchor_b);
    for (int axis = 0; axis < 3; ++axis) {
      anchors_apart[axis] = a.position[axis] + anchor_a[axis] - b.position[axis] - anchor_b[axis];
    }
  }
  LaneDoubles ct_a[2][3], ct_b[2][3], ang_t_a[2][3], ang_t_b[2][3];
  for (int k = 0; k < 2; ++k) {
    Put(tangent[k], block->tangent[k]);
    Cross(centre_a, tangent[k], ct_a[k]);
    Cross(centre_b, tangent[k], ct_b[k]);
    MultiplyLanes(a.inverse_inertia, ct_a[k], ang_t_a[k]);
    MultiplyLanes(b.inverse_inertia, ct_b[k], ang_t_b[k]);
    Keep3(compact, ang_t_a[k]);
    Keep3(compact, ang_t_b[k]);
    Put(ang_t_a[k], block->ang_t_a[k]);
    Put(ang_t_b[k], block->ang_t_b[k]);
    LaneDoubles slip;
    Dot(tangent[k], anchors_apart, &slip);
    Keep(compact, &slip);
    Put(slip, &block->slip_start[k]);
  }
  const LaneDoubles inverse_masses = a.inverse_mass + b.inverse_mass;
  auto entry = [&](int k, int l, LaneDoubles* out) {
    LaneDoubles along, turn_a, turn_b;
    Dot(tangent[k], tangent[l], &along);
    Dot(ct_a[k], ang_t_a[l], &turn_a);
    Dot(ct_b[k], ang_t_b[l], &turn_b);
    *out = inverse_masses * along + turn_a + turn_b;
  };
  LaneDoubles kxx, kxy, kyy;
  entry(0, 0, &kxx);
  entry(0, 1, &kxy);
  entry(1, 1, &kyy);
  const LaneDoubles det = kxx * kyy - kxy * kxy;
  const LaneDoubles zero = {};
  const LaneMask invertible = det > zero;
  block->tangent_block[0] = invertible ? kyy / det : zero;
  block->tangent_block[1] = invertible ? -kxy / det : zero;
  block->tangent_block[2] = invertible ? kxx / det : zero;
  LaneDoubles twist_a[3], twist_b[3], twist_sum[3];
  MultiplyLanes(a.inverse_inertia, normal, twist_a);
  MultiplyLanes(b.inverse_inertia, normal, twist_b);
  Keep3(compact, twist_a);
  Keep3(compact, twist_b);
  Put(twist_a, block->twist_a);
  Put(twist_b, block->twist_b);
  for (int axis = 0; axis < 3; ++axis) twist_sum[axis] = twist_a[axis] + twist_b[axis];
  LaneDoubles twist;
  Dot(normal, twist_sum, &twist);
  InverseOrZero(twist, &block->twist_mass);
}

// The rows of a block whose frames and bodies are in lanes: plain
// functions, one per block layout, compiled for AVX2 and for the baseline
// (RBS_SIMD_CLONES). Return whether a point closed faster than the
// collision threshold in the last step.
struct LanePrepareInput {
  LanePrepareContext context;
  std::array<const SolverManifold*, kBatchLanes> manifolds;
  LaneBodySide a;
  LaneBodySide b;
  LaneDoubles normal[3];
};

// TangentBasis (contact_frame.cc) in each lane, with its operations in its
// order: t_0 = (n x h) / |n x h| with h = x when |n_x| < 0.57, else y (left
// as n x h where that is zero); t_1 = n x t_0; both then as the rows keep
// them (Keep).
[[gnu::always_inline]] inline void TangentBasisLanes(bool compact, const LaneDoubles (&normal)[3],
                                                     LaneDoubles (&tangent)[2][3]) {
  const LaneDoubles zero = {};
  const LaneDoubles one = zero + 1.0;
  const LaneDoubles size_x = normal[0] < zero ? -normal[0] : normal[0];
  const LaneMask use_x = size_x < zero + 0.57;
  const LaneDoubles helper[3] = {use_x ? one : zero, use_x ? zero : one, zero};
  LaneDoubles across[3];
  Cross(normal, helper, across);
  LaneDoubles squared_norm, norm;
  Dot(across, across, &squared_norm);
  for (int lane = 0; lane < kBatchLanes; ++lane) norm[lane] = std::sqrt(squared_norm[lane]);
  const LaneMask positive = squared_norm > zero;
  for (int axis = 0; axis < 3; ++axis) {
    tangent[0][axis] = positive ? across[axis] / norm : across[axis];
  }
  Cross(normal, tangent[0], tangent[1]);
  Keep3(compact, tangent[0]);
  Keep3(compact, tangent[1]);
}

template <typename Block>
[[gnu::always_inline]] inline bool PrepareRowLanes(const LanePrepareInput& in, Block* block) {
  const bool fast = PreparePointLanes(in.context, in.manifolds, in.a, in.b, in.normal, block);
  LaneDoubles tangent[2][3];
  TangentBasisLanes(in.context.compact, in.normal, tangent);
  PrepareFrictionLanes(in.context, in.a, in.b, in.normal, tangent, block);
  return fast;
}

RBS_SIMD_CLONES bool PrepareRows(const LanePrepareInput& in, SoftLaneBlock* block) {
  return PrepareRowLanes(in, block);
}

RBS_SIMD_CLONES bool PrepareRows(const LanePrepareInput& in, CompactSoftLaneBlock* block) {
  return PrepareRowLanes(in, block);
}

}  // namespace

// What a constraint's rows share, each value as the rows keep it (Kept):
// the normal and its tangents, the spring's softness, and the friction
// rows' centroid, twist arm, starting impulses and anchors.
struct SoftContactSolver::Frame {
  Vec3 normal;
  double friction;
  double restitution;
  double bias_rate;  // 1/s
  double mass_scale;
  double impulse_scale;
  Vec3 centre_a;
  Vec3 centre_b;
  double twist_arm;
  std::array<double, 2> tangent_impulse;  // N s, of a sub-step
  Vec3 anchor_a;
  Vec3 anchor_b;
};

// The spring's softness for this step, as the rows keep it: [1] for a
// contact between two moving bodies, [0] for one with a body that does not
// move, which takes twice the frequency. A spring stiffer than a quarter of
// the sub-step rate is not followed by one iteration a sub-step (Box2D v3
// caps it the same way).
void SoftContactSolver::MakeSoftnesses(const SoftStepInput& input) {
  const double max_hertz = 0.25 / h_;
  for (int both_move = 0; both_move < 2; ++both_move) {
    const double hertz = input.settings.contact_hertz * (both_move ? 1.0 : 2.0);
    const Softness soft =
        MakeSoftness(std::min(hertz, max_hertz), input.settings.contact_damping_ratio, h_);
    softness_[both_move] = {Kept(compact_, soft.bias_rate), Kept(compact_, soft.mass_scale),
                            Kept(compact_, soft.impulse_scale)};
  }
}

// Friction acts at the points' centroid c, with the twist arm the points' mean distance from it
// across the normal, from the cached tangent impulses, summed, and from the
// friction anchors while they hold.
SoftContactSolver::Frame SoftContactSolver::MakeFrame(const SoftBody& a, const SoftBody& b,
                                                      const SolverManifold& manifold,
                                                      const FrictionAnchor& anchor) const {
  Frame f;
  f.normal = Kept(compact_, manifold.normal_world);
  f.friction = Kept(compact_, manifold.friction);
  f.restitution = Kept(compact_, manifold.restitution);
  const KeptSoftness& soft = softness_[a.moving && b.moving ? 1 : 0];
  f.bias_rate = soft.bias_rate;
  f.mass_scale = soft.mass_scale;
  f.impulse_scale = soft.impulse_scale;
  const double share = 1.0 / substeps_;
  Vec3 centre_a = Vec3::Zero();
  Vec3 centre_b = Vec3::Zero();
  f.tangent_impulse = {0.0, 0.0};
  for (int i = 0; i < manifold.point_count; ++i) {
    centre_a += manifold.points[i].r_a;
    centre_b += manifold.points[i].r_b;
    f.tangent_impulse[0] += share * manifold.points[i].tangent_impulse[0];
    f.tangent_impulse[1] += share * manifold.points[i].tangent_impulse[1];
  }
  const double inverse_count = manifold.point_count > 0 ? 1.0 / manifold.point_count : 0.0;
  centre_a *= inverse_count;
  centre_b *= inverse_count;
  double twist_arm = 0.0;
  for (int i = 0; i < manifold.point_count; ++i) {
    const Vec3 offset = manifold.points[i].r_a - centre_a;
    twist_arm += inverse_count * (offset - offset.dot(f.normal) * f.normal).norm();
  }
  f.twist_arm = Kept(compact_, twist_arm);
  f.centre_a = Kept(compact_, centre_a);
  f.centre_b = Kept(compact_, centre_b);
  f.anchor_a = anchor.valid ? Kept(compact_, a.orientation * anchor.on_a) : f.centre_a;
  f.anchor_b = anchor.valid ? Kept(compact_, b.orientation * anchor.on_b) : f.centre_b;
  return f;
}

// A manifold's rows: each point's Jacobian, row mass and the impulse it
// starts from (the step's cached impulse shared equally among the
// sub-steps), and its friction rows.
void SoftContactSolver::Prepare(const std::vector<SoftBody>& bodies, const SolverManifold& manifold,
                                const FrictionAnchor& anchor, Constraint* constraint) {
  Constraint& c = *constraint;
  const SoftBody& a = bodies[manifold.body_a];
  const SoftBody& b = bodies[manifold.body_b];
  const Frame frame = MakeFrame(a, b, manifold, anchor);
  c.body_a = manifold.body_a;
  c.body_b = manifold.body_b;
  c.normal = frame.normal;
  c.tangent = TangentBasis(c.normal);
  for (Vec3& t : c.tangent) t = Kept(compact_, t);
  c.inverse_mass_a = a.inverse_mass;
  c.inverse_mass_b = b.inverse_mass;
  c.friction = frame.friction;
  c.restitution = frame.restitution;
  c.bias_rate = frame.bias_rate;
  c.mass_scale = frame.mass_scale;
  c.impulse_scale = frame.impulse_scale;
  c.point_count = manifold.point_count;
  const double share = 1.0 / substeps_;
  for (int i = 0; i < c.point_count; ++i) {
    const SolverPoint& from = manifold.points[i];
    Point& p = c.points[i];
    p.rn_a = Kept(compact_, from.r_a.cross(c.normal));
    p.rn_b = Kept(compact_, from.r_b.cross(c.normal));
    p.ang_a = Kept(compact_, Multiply(a.inverse_inertia_world, p.rn_a));
    p.ang_b = Kept(compact_, Multiply(b.inverse_inertia_world, p.rn_b));
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
  PrepareFriction(a, b, frame, &c);
}

// The friction rows at the centroid c of the manifold's points: the tangent
// block (K_t)_kl = (1/m_a + 1/m_b) t_k.t_l + (c_a x t_k).I_a^-1 (c_a x t_l)
// + (B's likewise), inverted, and the twist row's mass
// 1 / (n.(I_a^-1 + I_b^-1) n).
void SoftContactSolver::PrepareFriction(const SoftBody& a, const SoftBody& b, const Frame& frame,
                                        Constraint* c) const {
  c->tangent_impulse = frame.tangent_impulse;
  c->twist_arm = frame.twist_arm;
  c->centre_a = frame.centre_a;
  c->centre_b = frame.centre_b;
  c->anchor_a = frame.anchor_a;
  c->anchor_b = frame.anchor_b;
  const Vec3 anchors_apart = a.position + c->anchor_a - b.position - c->anchor_b;
  for (int k = 0; k < 2; ++k) {
    const Vec3& t = c->tangent[k];
    c->ct_a[k] = c->centre_a.cross(t);
    c->ct_b[k] = c->centre_b.cross(t);
    c->ang_t_a[k] = Kept(compact_, Multiply(a.inverse_inertia_world, c->ct_a[k]));
    c->ang_t_b[k] = Kept(compact_, Multiply(b.inverse_inertia_world, c->ct_b[k]));
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
  c->twist_a = Kept(compact_, Multiply(a.inverse_inertia_world, c->normal));
  c->twist_b = Kept(compact_, Multiply(b.inverse_inertia_world, c->normal));
  c->twist_mass = InverseOrZero(c->normal.dot(c->twist_a + c->twist_b));
  c->twist_impulse = 0.0;
  c->total_tangent_impulse = {0.0, 0.0};
}

// Constraints first to first + lanes - 1 prepared as Prepare does, four at
// a time in the lanes of *block; a lane without a constraint takes the
// first lane's bodies and frame, with no point, and is neither written back
// nor stored. Each block field is written: a block is the only copy.
template <typename Block>
void SoftContactSolver::PrepareBlock(std::uint32_t first, int lanes, Block* block) {
  const std::vector<SoftBody>& bodies = *bodies_;
  LanePrepareInput in;
  in.context = {compact_, 1.0 / substeps_, collision_velocity_threshold_};
  LaneDoubles centre_a[3], centre_b[3], anchor_a[3], anchor_b[3];
  block->lanes = lanes;
  block->max_points = 0;
  for (int lane = 0; lane < kBatchLanes; ++lane) {
    const std::uint32_t k = first + static_cast<std::uint32_t>(lane < lanes ? lane : 0);
    const SolverManifold& manifold = (*manifolds_)[k];
    in.manifolds[lane] = &manifold;
    const SoftBody& a = bodies[manifold.body_a];
    const SoftBody& b = bodies[manifold.body_b];
    block->constraint[lane] = k;
    block->body_a[lane] = manifold.body_a;
    block->body_b[lane] = manifold.body_b;
    block->moves_a[lane] = lane < lanes && moving_mask_[manifold.body_a] != 0;
    block->moves_b[lane] = lane < lanes && moving_mask_[manifold.body_b] != 0;
    block->point_count[lane] = lane < lanes ? manifold.point_count : 0;
    if (lane < lanes) block->max_points = std::max(block->max_points, manifold.point_count);
    const Frame frame = MakeFrame(a, b, manifold, (*anchors_)[k]);
    SetLane(a, lane, &in.a);
    SetLane(b, lane, &in.b);
    SetLane(frame.normal, lane, in.normal);
    SetLane(frame.centre_a, lane, centre_a);
    SetLane(frame.centre_b, lane, centre_b);
    SetLane(frame.anchor_a, lane, anchor_a);
    SetLane(frame.anchor_b, lane, anchor_b);
    block->friction[lane] = frame.friction;
    block->restitution[lane] = frame.restitution;
    block->bias_rate[lane] = frame.bias_rate;
    block->mass_scale[lane] = frame.mass_scale;
    block->impulse_scale[lane] = frame.impulse_scale;
    block->twist_arm[lane] = frame.twist_arm;
    block->tangent_impulse[0][lane] = frame.tangent_impulse[0];
    block->tangent_impulse[1][lane] = frame.tangent_impulse[1];
  }
  Put(in.normal, block->normal);
  Put(centre_a, block->centre_a);
  Put(centre_b, block->centre_b);
  Put(anchor_a, block->anchor_a);
  Put(anchor_b, block->anchor_b);
  block->inverse_mass_a = in.a.inverse_mass;
  block->inverse_mass_b = in.b.inverse_mass;
  block->twist_impulse = LaneDoubles{};
  block->total_tangent_impulse[0] = LaneDoubles{};
  block->total_tangent_impulse[1] = LaneDoubles{};
  if (PrepareRows(in, block)) may_bounce_.store(true, std::memory_order_relaxed);
}

template void SoftContactSolver::PrepareBlock(std::uint32_t, int, SoftLaneBlock*);
template void SoftContactSolver::PrepareBlock(std::uint32_t, int, CompactSoftLaneBlock*);

}  // namespace rigid_body_sim::physics
