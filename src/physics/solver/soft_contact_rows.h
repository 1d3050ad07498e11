// The soft step's rows as the scalar update keeps them (soft_contact_solver.h
// says what each sub-step does with them): a body's state in the sub-steps,
// a contact point's normal row, and a manifold's rows with its friction.
#ifndef RIGID_BODY_SIM_PHYSICS_SOLVER_SOFT_CONTACT_ROWS_H_
#define RIGID_BODY_SIM_PHYSICS_SOLVER_SOFT_CONTACT_ROWS_H_

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>

#include "physics/contact/contact_manifold.h"
#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::physics {

// x rounded to the nearest float, held in a double: what the soft step's
// rows only read is stored in floats in the lanes' blocks
// (soft_contact_lanes.h), so the scalar rows round it the same way and both
// compute in double from the same values. Beyond a float's range it
// saturates, where no finite body's row reaches.
inline double NarrowToFloat(double x) {
  constexpr double kLargest = std::numeric_limits<float>::max();
  return static_cast<float>(std::clamp(x, -kLargest, kLargest));
}

inline Vec3 NarrowToFloat(const Vec3& v) {
  return Vec3(NarrowToFloat(v.x()), NarrowToFloat(v.y()), NarrowToFloat(v.z()));
}

// What the rows read and write of a body in the sub-steps, packed: the
// velocities, and the motion since the step began, dx and the rotation
// vector dtheta = sum h w, which the rows use to first order (a point r
// from the centre has moved dx + dtheta x r). The same turn, exactly, for
// the new pose is the body's SoftBody::delta_rotation, which only the
// position update reads, so the rows' 96 bytes a body stay apart from it.
struct SoftRowState {
  Vec3 linear_velocity;
  Vec3 angular_velocity;
  Vec3 delta_position;
  Vec3 delta_angle;
};
// A normal row, with its Jacobian's angular parts r x n and I^-1 (r x n)
// precomputed: v_n = n.(v_a - v_b) + (r_a x n).w_a - (r_b x n).w_b.
struct SoftPoint {
  Vec3 rn_a;  // r_a x n
  Vec3 rn_b;
  Vec3 ang_a;  // I_a^-1 (r_a x n)
  Vec3 ang_b;
  double start_separation;    // m, s0
  double normal_mass;         // kg
  double normal_impulse;      // N s, of the current sub-step
  double preload;             // N s per sub-step (CachedImpulse::preload)
  double max_normal_impulse;  // N s, the largest push of any sub-step
  double total_normal_impulse;
  double approach_velocity;  // m/s, v_n as the point closed (< 0: approaching)
  bool closed;               // a sub-step's motion would close its gap
  bool carried;              // closed in the last step (its approach_velocity is that)
  bool touched;              // closed, and within touch_tolerance at the step's end
};
// A manifold's rows. Friction acts at the points' centroid c: two tangent
// rows (their 2x2 block inverted) and a twist row about the normal, bounded
// by mu times the manifold's whole normal impulse (times the points' mean
// distance from c, for the twist).
struct SoftConstraint {
  std::uint32_t body_a;
  std::uint32_t body_b;
  Vec3 normal;  // from B to A
  std::array<Vec3, 2> tangent;
  double inverse_mass_a;
  double inverse_mass_b;
  double friction;
  double restitution;
  double bias_rate;  // 1/s
  double mass_scale;
  double impulse_scale;
  int point_count;
  std::array<Vec3, 2> ct_a;  // c_a x t_k
  std::array<Vec3, 2> ct_b;
  std::array<Vec3, 2> ang_t_a;  // I_a^-1 (c_a x t_k)
  std::array<Vec3, 2> ang_t_b;
  Vec3 twist_a;  // I_a^-1 n
  Vec3 twist_b;
  std::array<double, 3> tangent_block;  // K_t^-1: xx, xy, yy, kg
  double twist_mass;                    // kg m^2
  double twist_arm;                     // m
  // The friction anchors (FrictionAnchor) as offsets from the centres of
  // mass at the step's start; their slip along t_k at the start, and
  // anchor x t_k for its change with the bodies' turn.
  Vec3 anchor_a;
  Vec3 anchor_b;
  Vec3 centre_a;  // m, c_a (the lanes form c_a x t_k from it)
  Vec3 centre_b;
  std::array<double, 2> slip_start;
  std::array<Vec3, 2> anchor_t_a;
  std::array<Vec3, 2> anchor_t_b;
  std::array<double, 2> tangent_impulse;  // N s, of the current sub-step
  double twist_impulse;                   // N m s
  std::array<double, 2> total_tangent_impulse;
  std::array<SoftPoint, ContactManifold::kMaxPoints> points;
};

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_SOLVER_SOFT_CONTACT_ROWS_H_
