// The lane-by-lane row update of SweepBatches (resting_batches.h). Each
// lane does what UpdateRestingRow (resting_row.h) does for its row, with the
// same floating-point operations in the same order; what the scalar code
// decides by a branch, a lane decides by selecting between the two results,
// so a lane whose row is absent, whose island has converged, or whose
// friction is zero keeps every value the scalar update would keep, bit for
// bit. No function here takes a vector by value: with the baseline x86-64
// instruction set, GCC passes 32-byte vectors differently from AVX builds.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "physics/solver/contact_solver.h"
#include "physics/solver/resting_batches.h"

namespace rigid_body_sim::physics {
namespace {

// The velocities of a batch's bodies, lane l holding those of its run's
// body A and body B; [axis] in the world frame.
struct BatchVelocities {
  LaneDoubles linear_a[3];   // m/s
  LaneDoubles angular_a[3];  // rad/s
  LaneDoubles linear_b[3];
  LaneDoubles angular_b[3];
};

// *target = value in the lanes of `active`; with kAllActive every lane is,
// and no lane needs selecting.
template <bool kAllActive>
[[gnu::always_inline]] inline void AssignActive(const LaneMask& active, const LaneDoubles& value,
                                                LaneDoubles* target) {
  if constexpr (kAllActive) {
    *target = value;
  } else {
    *target = active ? value : *target;
  }
}

// Each lane's (t_0, t_1) scaled onto the disc |t| <= limit where it lies
// outside; the square roots only when some lane does.
[[gnu::always_inline]] inline void ProjectOntoDisc(const LaneDoubles& limit,
                                                   LaneDoubles tangent[2]) {
  const LaneDoubles zero = {};
  const LaneDoubles norm_squared = tangent[0] * tangent[0] + tangent[1] * tangent[1];
  const LaneMask outside = norm_squared > limit * limit;
  if (!AnyLane(outside)) return;
  const LaneDoubles norm = {std::sqrt(norm_squared[0]), std::sqrt(norm_squared[1]),
                            std::sqrt(norm_squared[2]), std::sqrt(norm_squared[3])};
  const LaneDoubles scale = norm > zero ? limit / norm : zero;
  tangent[0] = outside ? tangent[0] * scale : tangent[0];
  tangent[1] = outside ? tangent[1] * scale : tangent[1];
}

// UpdateRestingRow for the rows of one block, in the lanes of `active`:
// v_r, the friction impulse projected onto its disc, the normal velocity
// corrected by the friction change, the normal impulse projected onto
// f >= 0, and the three changes applied at once; *run_change keeps the
// largest |v - v_previous sweep|^2 of each lane.
template <bool kAllActive>
[[gnu::always_inline]] inline void UpdateBlock(const RunBatch& run, const LaneMask& active,
                                               RowBlock* row, BatchVelocities* velocities,
                                               LaneDoubles* run_change) {
  const LaneDoubles zero = {};
  LaneDoubles cross_a[3];
  LaneDoubles cross_b[3];
  Cross(velocities->angular_a, row->r_a, cross_a);
  Cross(velocities->angular_b, row->r_b, cross_b);
  LaneDoubles v[3];
  LaneDoubles difference[3];
  for (int axis = 0; axis < 3; ++axis) {
    v[axis] =
        ((velocities->linear_a[axis] + cross_a[axis]) - velocities->linear_b[axis]) - cross_b[axis];
    difference[axis] = v[axis] - row->last_velocity[axis];
    AssignActive<kAllActive>(active, v[axis], &row->last_velocity[axis]);
  }
  LaneDoubles change_squared;
  Dot(difference, difference, &change_squared);
  LaneDoubles normal_velocity;
  Dot(run.normal, v, &normal_velocity);

  // Friction: a tangent step, projected onto |f_t| <= mu f_n.
  const LaneMask has_friction = run.friction > zero;
  const LaneDoubles old_tangent[2] = {row->tangent_impulse[0], row->tangent_impulse[1]};
  LaneDoubles tangent[2];
  for (int k = 0; k < 2; ++k) {
    LaneDoubles tangent_velocity;
    Dot(run.tangent[k], v, &tangent_velocity);
    tangent[k] = old_tangent[k] - row->tangent_mass * tangent_velocity;
  }
  ProjectOntoDisc(run.friction * row->normal_impulse, tangent);
  LaneDoubles change[3];
  for (int k = 0; k < 2; ++k) {
    change[k + 1] = has_friction ? tangent[k] - old_tangent[k] : zero;
    normal_velocity =
        has_friction ? normal_velocity + row->normal_coupling[k] * change[k + 1] : normal_velocity;
    row->tangent_impulse[k] = (active & has_friction) ? tangent[k] : old_tangent[k];
  }

  // Normal: projected onto f >= 0, as std::max(0.0, f) does.
  const LaneDoubles old_normal = row->normal_impulse;
  const LaneDoubles unprojected = old_normal + row->normal_mass * (row->target - normal_velocity);
  const LaneDoubles normal = zero < unprojected ? unprojected : zero;
  change[0] = normal - old_normal;
  AssignActive<kAllActive>(active, normal, &row->normal_impulse);

  // AddRowImpulse: J = j_n n + j_0 t_0 + j_1 t_1, dv = +-J / M,
  // dw = +-sum_k j_k I^-1 (r x d_k).
  for (int axis = 0; axis < 3; ++axis) {
    const LaneDoubles impulse = (change[0] * run.normal[axis] + change[1] * run.tangent[0][axis]) +
                                change[2] * run.tangent[1][axis];
    const LaneDoubles turn_a =
        (change[0] * row->angular_a[0][axis] + change[1] * row->angular_a[1][axis]) +
        change[2] * row->angular_a[2][axis];
    const LaneDoubles turn_b =
        (change[0] * row->angular_b[0][axis] + change[1] * row->angular_b[1][axis]) +
        change[2] * row->angular_b[2][axis];
    LaneDoubles& linear_a = velocities->linear_a[axis];
    LaneDoubles& angular_a = velocities->angular_a[axis];
    LaneDoubles& linear_b = velocities->linear_b[axis];
    LaneDoubles& angular_b = velocities->angular_b[axis];
    AssignActive<kAllActive>(active, linear_a + run.inverse_mass_a * impulse, &linear_a);
    AssignActive<kAllActive>(active, angular_a + turn_a, &angular_a);
    AssignActive<kAllActive>(active, linear_b - run.inverse_mass_b * impulse, &linear_b);
    AssignActive<kAllActive>(active, angular_b - turn_b, &angular_b);
  }
  LaneMask larger = *run_change < change_squared;
  if constexpr (!kAllActive) larger &= active;
  *run_change = larger ? change_squared : *run_change;
}

// The bodies' real velocities, or with kPseudo the split impulse's.
template <bool kPseudo>
constexpr Vec3 SolverBody::*kLinear =
    kPseudo ? &SolverBody::pseudo_linear_velocity : &SolverBody::linear_velocity;
template <bool kPseudo>
constexpr Vec3 SolverBody::*kAngular =
    kPseudo ? &SolverBody::pseudo_angular_velocity : &SolverBody::angular_velocity;

// Each vector is built from its four lanes at once: written lane by lane
// into memory and read back whole, it would wait on each read for the four
// writes (a failed store-to-load forward).
template <bool kPseudo>
[[gnu::always_inline]] inline void LoadVelocities(const RunBatch& batch, const LaneMask& active,
                                                  const std::vector<SolverBody>& bodies,
                                                  BatchVelocities* velocities) {
  static_assert(kBatchLanes == 4);
  constexpr Vec3 SolverBody::*linear = kLinear<kPseudo>;
  constexpr Vec3 SolverBody::*angular = kAngular<kPseudo>;
  static const SolverBody kResting;
  std::array<const SolverBody*, kBatchLanes> a;
  std::array<const SolverBody*, kBatchLanes> b;
  for (int lane = 0; lane < kBatchLanes; ++lane) {
    a[lane] = active[lane] != 0 ? &bodies[batch.body_a[lane]] : &kResting;
    b[lane] = active[lane] != 0 ? &bodies[batch.body_b[lane]] : &kResting;
  }
  for (int axis = 0; axis < 3; ++axis) {
    velocities->linear_a[axis] = LaneDoubles{(a[0]->*linear)[axis], (a[1]->*linear)[axis],
                                             (a[2]->*linear)[axis], (a[3]->*linear)[axis]};
    velocities->angular_a[axis] = LaneDoubles{(a[0]->*angular)[axis], (a[1]->*angular)[axis],
                                              (a[2]->*angular)[axis], (a[3]->*angular)[axis]};
    velocities->linear_b[axis] = LaneDoubles{(b[0]->*linear)[axis], (b[1]->*linear)[axis],
                                             (b[2]->*linear)[axis], (b[3]->*linear)[axis]};
    velocities->angular_b[axis] = LaneDoubles{(b[0]->*angular)[axis], (b[1]->*angular)[axis],
                                              (b[2]->*angular)[axis], (b[3]->*angular)[axis]};
  }
}

// A body the solve does not move keeps its velocity (its inverse mass and
// inertia are zero), so it is not stored: two groups sweeping rows on the
// same static body on two threads never write it.
template <bool kPseudo>
[[gnu::always_inline]] inline void StoreVelocities(const RunBatch& batch, const LaneMask& active,
                                                   const BatchVelocities& velocities,
                                                   std::vector<SolverBody>* bodies) {
  constexpr Vec3 SolverBody::*linear = kLinear<kPseudo>;
  constexpr Vec3 SolverBody::*angular = kAngular<kPseudo>;
  for (std::uint32_t lane = 0; lane < batch.lanes; ++lane) {
    if (active[lane] == 0) continue;
    if (batch.moving[lane] & SweepTask::kFirstA) {
      SolverBody& a = (*bodies)[batch.body_a[lane]];
      for (int axis = 0; axis < 3; ++axis) {
        (a.*linear)[axis] = velocities.linear_a[axis][lane];
        (a.*angular)[axis] = velocities.angular_a[axis][lane];
      }
    }
    if (batch.moving[lane] & SweepTask::kFirstB) {
      SolverBody& b = (*bodies)[batch.body_b[lane]];
      for (int axis = 0; axis < 3; ++axis) {
        (b.*linear)[axis] = velocities.linear_b[axis][lane];
        (b.*angular)[axis] = velocities.angular_b[axis][lane];
      }
    }
  }
}

// UpdatePseudoRow for the rows of one block, in the lanes of `active` whose
// row penetrates beyond the slop: the pseudo velocity along the normal is
// driven to position_correction depth / dt with a non-negative impulse.
[[gnu::always_inline]] inline void UpdatePseudoBlock(const RunBatch& run, const LaneMask& lanes,
                                                     const LaneDoubles& correction,
                                                     const LaneDoubles& inverse_dt, RowBlock* row,
                                                     BatchVelocities* velocities) {
  const LaneDoubles zero = {};
  const LaneMask active = lanes & (row->depth > zero);
  const LaneDoubles target = (correction * row->depth) * inverse_dt;
  LaneDoubles cross_a[3];
  LaneDoubles cross_b[3];
  Cross(velocities->angular_a, row->r_a, cross_a);
  Cross(velocities->angular_b, row->r_b, cross_b);
  LaneDoubles v[3];
  for (int axis = 0; axis < 3; ++axis) {
    v[axis] =
        ((velocities->linear_a[axis] + cross_a[axis]) - velocities->linear_b[axis]) - cross_b[axis];
  }
  LaneDoubles normal_velocity;
  Dot(run.normal, v, &normal_velocity);
  const LaneDoubles old_impulse = row->pseudo_impulse;
  const LaneDoubles unprojected = old_impulse + row->normal_mass * (target - normal_velocity);
  const LaneDoubles impulse = zero < unprojected ? unprojected : zero;
  const LaneDoubles change = impulse - old_impulse;
  AssignActive<false>(active, impulse, &row->pseudo_impulse);
  for (int axis = 0; axis < 3; ++axis) {
    LaneDoubles& linear_a = velocities->linear_a[axis];
    LaneDoubles& angular_a = velocities->angular_a[axis];
    LaneDoubles& linear_b = velocities->linear_b[axis];
    LaneDoubles& angular_b = velocities->angular_b[axis];
    AssignActive<false>(active, linear_a + (run.inverse_mass_a * change) * run.normal[axis],
                        &linear_a);
    AssignActive<false>(active, angular_a + change * row->angular_a[0][axis], &angular_a);
    AssignActive<false>(active, linear_b - (run.inverse_mass_b * change) * run.normal[axis],
                        &linear_b);
    AssignActive<false>(active, angular_b - change * row->angular_b[0][axis], &angular_b);
  }
}

[[gnu::always_inline]] inline void SweepAllPseudoBatches(RestingBatches* batches,
                                                         std::vector<SolverBody>* bodies,
                                                         double position_correction,
                                                         double inverse_dt) {
  const LaneDoubles correction = LaneDoubles{} + position_correction;
  const LaneDoubles per_second = LaneDoubles{} + inverse_dt;
  for (const RunBatch& batch : batches->batches) {
    if (!batch.penetrates) continue;
    const LaneMask lane_active = LaneMask{} < batch.row_count;
    BatchVelocities velocities;
    LoadVelocities</*kPseudo=*/true>(batch, lane_active, *bodies, &velocities);
    RowBlock* block = batches->blocks.data() + batch.block_begin;
    for (std::uint32_t k = 0; k < batch.block_count; ++k, ++block) {
      const LaneMask row_index = LaneMask{} + static_cast<std::int64_t>(k);
      UpdatePseudoBlock(batch, lane_active & (row_index < batch.row_count), correction, per_second,
                        block, &velocities);
    }
    StoreVelocities</*kPseudo=*/true>(batch, lane_active, velocities, bodies);
  }
}

[[gnu::always_inline]] inline void SweepAllBatches(RestingBatches* batches,
                                                   std::vector<SolverBody>* bodies,
                                                   std::vector<RestingIsland>* islands) {
  for (const RunBatch& batch : batches->batches) {
    LaneMask lane_active = {};
    bool any_active = false;
    for (std::uint32_t lane = 0; lane < batch.lanes; ++lane) {
      if (!(*islands)[batch.island[lane]].converged) {
        lane_active[lane] = -1;
        any_active = true;
      }
    }
    if (!any_active) continue;
    BatchVelocities velocities;
    LoadVelocities</*kPseudo=*/false>(batch, lane_active, *bodies, &velocities);
    LaneDoubles run_change = {};
    RowBlock* block = batches->blocks.data() + batch.block_begin;
    for (std::uint32_t k = 0; k < batch.block_count; ++k, ++block) {
      const LaneMask row_index = LaneMask{} + static_cast<std::int64_t>(k);
      const LaneMask active = lane_active & (row_index < batch.row_count);
      if ((active[0] & active[1] & active[2] & active[3]) != 0) {
        UpdateBlock<true>(batch, active, block, &velocities, &run_change);
      } else {
        UpdateBlock<false>(batch, active, block, &velocities, &run_change);
      }
    }
    StoreVelocities</*kPseudo=*/false>(batch, lane_active, velocities, bodies);
    for (std::uint32_t lane = 0; lane < batch.lanes; ++lane) {
      if (lane_active[lane] == 0) continue;
      double& largest = (*islands)[batch.island[lane]].largest_change_squared;
      largest = std::max(largest, run_change[lane]);
    }
  }
}

}  // namespace

// Built twice, for AVX2 (four lanes per instruction) and for the baseline
// x86-64 (two), the loader picking the one the processor runs; neither
// fuses a multiply and an add, so both give the scalar sweep's result.
RBS_SIMD_CLONES void SweepBatches(RestingBatches* batches, std::vector<SolverBody>* bodies,
                                  std::vector<RestingIsland>* islands) {
  SweepAllBatches(batches, bodies, islands);
}

RBS_SIMD_CLONES void SweepPseudoBatches(RestingBatches* batches, std::vector<SolverBody>* bodies,
                                        double position_correction, double inverse_dt) {
  SweepAllPseudoBatches(batches, bodies, position_correction, inverse_dt);
}

}  // namespace rigid_body_sim::physics
