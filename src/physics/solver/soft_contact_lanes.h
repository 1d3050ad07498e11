// The soft step's row updates four constraints at a time, one per lane of a
// SIMD vector (simd_lanes.h). The constraints of one colour share no moving
// body (constraint_colouring.h), so the soft step may update them in any
// order with the same result; a block holds up to four consecutive
// constraints of one colour. Each lane does what SoftContactSolver's scalar
// WarmStart and Solve do for its constraint, with the same floating-point
// operations in the same order; what the scalar code decides by a branch, a
// lane decides by selecting between the two results, and a point a lane's
// manifold lacks keeps every value. So the lanes give the scalar update's
// result bit for bit (soft_step_test), as the exact solver's batches do;
// Box2D v3 (Catto 2024, src/contact_solver.c) solves its colours' contacts
// in SIMD lanes the same way, in floats.
#ifndef RIGID_BODY_SIM_PHYSICS_SOLVER_SOFT_CONTACT_LANES_H_
#define RIGID_BODY_SIM_PHYSICS_SOLVER_SOFT_CONTACT_LANES_H_

#include <array>
#include <cstdint>
#include <vector>

#include "physics/solver/simd_lanes.h"
#include "physics/solver/soft_contact_rows.h"

namespace rigid_body_sim::physics {

// A point row of each lane's constraint; [axis] is x, y, z in the world.
// What the sub-steps only read is `Stored`: LaneDoubles in a wide block,
// LaneFloats in a compact one (kCompact). The scalar rows hold the same values rounded
// to floats (NarrowToFloat), so both layouts give the scalar update's bits.
template <bool kCompact>
struct SoftLanePointOf {
  using Stored = typename LaneStored<kCompact>::Type;
  Stored rn_a[3];  // r_a x n
  Stored rn_b[3];
  Stored ang_a[3];  // I_a^-1 (r_a x n)
  Stored ang_b[3];
  Stored start_separation;     // m
  Stored preload;              // N s
  LaneDoubles normal_mass;     // kg
  LaneDoubles normal_impulse;  // N s
  LaneDoubles max_normal_impulse;
  LaneDoubles total_normal_impulse;
  LaneDoubles approach_velocity;  // m/s
  LaneMask closed;
};

// Up to four constraints of one colour in structure-of-arrays form: the
// SoftConstraint fields the sub-steps read and write. The sub-steps stream
// every block once a pass, and the big scenes' blocks outgrow the cache: so
// the lanes form c x t_k and anchor x t_k from the centroids and anchors as
// they go (Cross), and a compact block (SoftStepSettings::
// compact_blocks_from) keeps what is only read in floats.
template <bool kCompact>
struct SoftLaneBlockOf {
  using Stored = typename LaneStored<kCompact>::Type;
  std::array<std::uint32_t, kBatchLanes> constraint;  // index in the solver's constraints
  std::array<std::uint32_t, kBatchLanes> body_a;
  std::array<std::uint32_t, kBatchLanes> body_b;
  std::array<bool, kBatchLanes> moves_a;  // the solve writes the body's velocities
  std::array<bool, kBatchLanes> moves_b;
  int lanes;       // lanes holding a constraint, the first ones
  int max_points;  // the most points of any lane's manifold
  Stored normal[3];
  Stored tangent[2][3];
  Stored friction;
  Stored bias_rate;  // 1/s
  Stored mass_scale;
  Stored impulse_scale;
  Stored centre_a[3];  // m, c_a
  Stored centre_b[3];
  Stored anchor_a[3];  // m
  Stored anchor_b[3];
  Stored ang_t_a[2][3];  // I_a^-1 (c_a x t_k)
  Stored ang_t_b[2][3];
  Stored twist_a[3];  // I_a^-1 n
  Stored twist_b[3];
  Stored twist_arm;  // m
  Stored slip_start[2];
  Stored restitution;  // read only after the sub-steps
  LaneDoubles inverse_mass_a;
  LaneDoubles inverse_mass_b;
  LaneDoubles tangent_block[3];
  LaneDoubles twist_mass;
  LaneDoubles tangent_impulse[2];
  LaneDoubles twist_impulse;
  LaneDoubles total_tangent_impulse[2];
  LaneMask point_count;  // a lane's point i is present where i < point_count
  std::array<SoftLanePointOf<kCompact>, ContactManifold::kMaxPoints> points;
  // Read only after the sub-steps, by the restitution pass and the store.
  LaneMask carried[ContactManifold::kMaxPoints];
};

using SoftLaneBlock = SoftLaneBlockOf<false>;        // 4,640 bytes
using CompactSoftLaneBlock = SoftLaneBlockOf<true>;  // 3,008 bytes

// What the lane updates read besides the blocks.
struct SoftLaneContext {
  std::vector<SoftRowState>* states = nullptr;  // per body
  double h = 0.0;                               // s, the sub-step
  double max_push_velocity = 0.0;               // m/s
  double collision_velocity_threshold = 0.0;    // m/s
};

// Lane `lane`'s constraint as the sub-steps left it, with the fields that
// the store reads (SoftContactSolver::Store) and, with `rows`, the normal
// rows' that the restitution pass reads (Restitute); the friction rows'
// Jacobians are left unset.
template <typename Block>
void ExtractSoftConstraint(const Block& block, int lane, bool rows, SoftConstraint* constraint);

// SoftContactSolver::WarmStart on each constraint of blocks [begin, end).
void WarmStartSoftBlocks(const SoftLaneContext& context, SoftLaneBlock* begin, SoftLaneBlock* end);
void WarmStartSoftBlocks(const SoftLaneContext& context, CompactSoftLaneBlock* begin,
                         CompactSoftLaneBlock* end);
// SoftContactSolver::Solve (use_bias: the solve pass, else the relax pass)
// on each constraint of blocks [begin, end). Returns whether a point closed
// faster than the collision threshold.
bool SolveSoftBlocks(const SoftLaneContext& context, bool use_bias, SoftLaneBlock* begin,
                     SoftLaneBlock* end);
bool SolveSoftBlocks(const SoftLaneContext& context, bool use_bias, CompactSoftLaneBlock* begin,
                     CompactSoftLaneBlock* end);

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_SOLVER_SOFT_CONTACT_LANES_H_
