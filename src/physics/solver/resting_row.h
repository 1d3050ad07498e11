// The resting solve's row kernels, shared by its sweeps (resting_contact.cc)
// and by the exact finish of its islands (resting_islands.cc): the
// projected Gauss-Seidel update of one row, and applying a row's impulse.
#ifndef RIGID_BODY_SIM_PHYSICS_SOLVER_RESTING_ROW_H_
#define RIGID_BODY_SIM_PHYSICS_SOLVER_RESTING_ROW_H_

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "physics/contact/contact_frame.h"
#include "physics/solver/contact_solver.h"

namespace rigid_body_sim::physics {

// The velocities of the two bodies of one run of rows, held in locals while
// the run's rows update them, so that one row's result reaches the next in
// registers instead of through memory.
struct RunVelocities {
  Vec3 linear_a;
  Vec3 angular_a;
  Vec3 linear_b;
  Vec3 angular_b;
};

// The two bodies' real velocities, or with kPseudo the split impulse's.
template <bool kPseudo>
RunVelocities LoadRun(const SolverBody& a, const SolverBody& b) {
  if constexpr (kPseudo) {
    return {a.pseudo_linear_velocity, a.pseudo_angular_velocity, b.pseudo_linear_velocity,
            b.pseudo_angular_velocity};
  } else {
    return {a.linear_velocity, a.angular_velocity, b.linear_velocity, b.angular_velocity};
  }
}

// Stores the run's velocities into the bodies given; a null body is left
// as it is.
template <bool kPseudo>
void StoreRun(const RunVelocities& velocities, SolverBody* a, SolverBody* b) {
  if constexpr (kPseudo) {
    if (a != nullptr) {
      a->pseudo_linear_velocity = velocities.linear_a;
      a->pseudo_angular_velocity = velocities.angular_a;
    }
    if (b != nullptr) {
      b->pseudo_linear_velocity = velocities.linear_b;
      b->pseudo_angular_velocity = velocities.angular_b;
    }
  } else {
    if (a != nullptr) {
      a->linear_velocity = velocities.linear_a;
      a->angular_velocity = velocities.angular_a;
    }
    if (b != nullptr) {
      b->linear_velocity = velocities.linear_b;
      b->angular_velocity = velocities.angular_b;
    }
  }
}

// Adds the impulse (normal, tangent 0, tangent 1) components of a row to its
// bodies: dv = +-J / M, dw = +-sum_k j_k I^-1 (r x d_k) with the responses
// I^-1 (r x d_k) made once per step, so a sweep does no 3x3 product.
inline void AddRowImpulse(const RestingRow& row, const Vec3& components,
                          RunVelocities* velocities) {
  const Vec3 impulse_world =
      components[0] * row.normal + components[1] * row.tangent[0] + components[2] * row.tangent[1];
  velocities->linear_a += row.inverse_mass_a * impulse_world;
  velocities->angular_a += components[0] * row.angular_a[0] + components[1] * row.angular_a[1] +
                           components[2] * row.angular_a[2];
  velocities->linear_b -= row.inverse_mass_b * impulse_world;
  velocities->angular_b -= components[0] * row.angular_b[0] + components[1] * row.angular_b[1] +
                           components[2] * row.angular_b[2];
}

// One projected Gauss-Seidel update of a point: the relative velocity is
// read once; the friction impulse is projected onto the disc
// |f_t| <= mu f_n, the normal velocity is corrected by what that change
// adds (normal_coupling, n.K t = t.K n), the normal impulse is projected
// onto f >= 0, and the sum of the three changes is applied once. Returns
// |v - v_previous sweep|^2, m^2/s^2.
inline double UpdateRestingRow(RestingRow* row, RunVelocities* velocities) {
  const Vec3 v = velocities->linear_a + velocities->angular_a.cross(row->r_a) -
                 velocities->linear_b - velocities->angular_b.cross(row->r_b);
  const double change_squared = (v - row->last_velocity).squaredNorm();
  row->last_velocity = v;
  Vec3 change = Vec3::Zero();  // normal, tangent 0, tangent 1
  double normal_velocity = row->normal.dot(v);
  if (row->friction > 0.0) {
    const std::array<double, 2> old_tangent = row->tangent_impulse;
    for (int k = 0; k < 2; ++k) {
      row->tangent_impulse[k] -= row->tangent_mass * row->tangent[k].dot(v);
    }
    ClampToDisc(row->friction * row->normal_impulse, &row->tangent_impulse);
    for (int k = 0; k < 2; ++k) {
      change[k + 1] = row->tangent_impulse[k] - old_tangent[k];
      normal_velocity += row->normal_coupling[k] * change[k + 1];
    }
  }
  const double old_normal = row->normal_impulse;
  row->normal_impulse =
      std::max(0.0, old_normal + row->normal_mass * (row->target - normal_velocity));
  change[0] = row->normal_impulse - old_normal;
  AddRowImpulse(*row, change, velocities);
  return change_squared;
}

// One update of a point's split impulse: the pseudo velocity along the
// normal is driven to position_correction depth / dt, with a non-negative
// impulse.
inline void UpdatePseudoRow(double position_correction, double inverse_dt, RestingRow* row,
                            RunVelocities* velocities) {
  if (row->depth <= 0.0) return;
  const double target = position_correction * row->depth * inverse_dt;
  const double v_r = row->normal.dot(velocities->linear_a + velocities->angular_a.cross(row->r_a) -
                                     velocities->linear_b - velocities->angular_b.cross(row->r_b));
  const double old_impulse = row->pseudo_impulse;
  row->pseudo_impulse = std::max(0.0, old_impulse + row->normal_mass * (target - v_r));
  const double change = row->pseudo_impulse - old_impulse;
  velocities->linear_a += (row->inverse_mass_a * change) * row->normal;
  velocities->angular_a += change * row->angular_a[0];
  velocities->linear_b -= (row->inverse_mass_b * change) * row->normal;
  velocities->angular_b -= change * row->angular_b[0];
}

// The update of a sweep over the real velocities (UpdateRestingRow) or, with
// kPseudo, the split impulse's (UpdatePseudoRow, which returns 0).
template <bool kPseudo>
double UpdateRow(double position_correction, double inverse_dt, RestingRow* row,
                 RunVelocities* velocities) {
  if constexpr (kPseudo) {
    UpdatePseudoRow(position_correction, inverse_dt, row, velocities);
    return 0.0;
  } else {
    return UpdateRestingRow(row, velocities);
  }
}

// v_r of a row from the solver's bodies: v_a + w_a x r_a - v_b - w_b x r_b.
inline Vec3 RowVelocity(const RestingRow& row, const std::vector<SolverBody>& bodies) {
  const SolverBody& a = bodies[row.body_a];
  const SolverBody& b = bodies[row.body_b];
  return a.linear_velocity + a.angular_velocity.cross(row.r_a) - b.linear_velocity -
         b.angular_velocity.cross(row.r_b);
}

inline void ApplyRowImpulse(const RestingRow& row, const Vec3& components,
                            std::vector<SolverBody>* bodies) {
  SolverBody& a = (*bodies)[row.body_a];
  SolverBody& b = (*bodies)[row.body_b];
  RunVelocities velocities = LoadRun</*kPseudo=*/false>(a, b);
  AddRowImpulse(row, components, &velocities);
  StoreRun</*kPseudo=*/false>(velocities, &a, &b);
}

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_SOLVER_RESTING_ROW_H_
