// The resting solve's sweep over batches: up to four runs of rows (each run
// the rows of one manifold) that share no moving body, updated at once, one
// run per lane of a SIMD vector.
//
// Why it gives the reference sweep bit for bit: a projected Gauss-Seidel
// update reads and writes only its row and its two bodies' velocities, so
// any order that keeps, for each moving body, the order of the rows that
// touch it, gives every update the same operands as the reference order
// does. The batching below places each run in the first batch after the
// last batch that holds one of its moving bodies (greedy list scheduling
// of the dependence graph, four lanes per time slot; Graham 1966, "Bounds
// for certain multiprocessing anomalies"), so per body the order is kept;
// and each lane does the reference update's floating-point operations, in
// the same order, with no fused multiply-add. Box2D v3 (Catto 2024,
// src/contact_solver.c) also updates contacts in SIMD lanes, but over graph
// colours, which changes the Gauss-Seidel order and so the result; this
// keeps it.
#ifndef RIGID_BODY_SIM_PHYSICS_SOLVER_RESTING_BATCHES_H_
#define RIGID_BODY_SIM_PHYSICS_SOLVER_RESTING_BATCHES_H_

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "physics/solver/simd_lanes.h"

namespace rigid_body_sim::physics {

// Declared in contact_solver.h, which holds the batches.
struct RestingIsland;
struct RestingRow;
struct SolverBody;
struct SweepTask;

// The k-th row of each run of a batch, what differs from row to row of a
// RestingRow, in structure-of-arrays form; [axis] is x, y, z in the world
// frame. What a run's rows share is in its RunBatch.
struct RowBlock {
  LaneDoubles r_a[3];  // m
  LaneDoubles r_b[3];
  LaneDoubles angular_a[3][3];  // [direction n, t0, t1][axis], rad/s per N s
  LaneDoubles angular_b[3][3];
  LaneDoubles normal_mass;         // kg
  LaneDoubles tangent_mass;        // kg
  LaneDoubles normal_coupling[2];  // 1/kg
  LaneDoubles target;              // m/s
  LaneDoubles normal_impulse;      // N s
  LaneDoubles tangent_impulse[2];  // N s
  LaneDoubles last_velocity[3];    // m/s
  LaneDoubles depth;               // m, penetration beyond the slop
  LaneDoubles pseudo_impulse;      // N s, split impulse
};

// Up to kBatchLanes runs, lane l holding rows [row_begin[l], row_end[l])
// of rows_, whose k-th rows are blocks[block_begin + k]. A run here is the
// rows of one manifold (one contact frame and friction), the lane's fields
// below.
struct RunBatch {
  LaneDoubles normal[3];
  LaneDoubles tangent[2][3];
  LaneDoubles friction;        // mu
  LaneDoubles inverse_mass_a;  // 1/kg
  LaneDoubles inverse_mass_b;
  LaneMask row_count;  // rows of each lane's run, 0 for a lane without one
  std::uint32_t block_begin = 0;
  std::uint32_t block_count = 0;
  std::uint32_t lanes = 0;  // lanes holding a run: the first `lanes`
  bool penetrates = false;  // whether a row penetrates beyond the slop
  std::array<std::uint32_t, kBatchLanes> row_begin{};
  std::array<std::uint32_t, kBatchLanes> row_end{};
  std::array<std::uint32_t, kBatchLanes> body_a{};
  std::array<std::uint32_t, kBatchLanes> body_b{};
  std::array<std::uint32_t, kBatchLanes> island{};
  // SweepTask::kFirstA and kFirstB of each lane's run: which of its bodies
  // the solve moves, and so stores.
  std::array<std::uint8_t, kBatchLanes> moving{};
};

// One group's batches, with the scratch that builds them (kept for its
// memory).
struct RestingBatches {
  std::vector<RunBatch> batches;
  std::vector<RowBlock> blocks;
  std::vector<std::int32_t> last_batch_of_body;
  std::vector<std::uint32_t> next_open;
};

// Packs the runs of one group's schedule, in its order, into batches, and
// copies their rows into blocks; a run of several manifolds (shapes of
// compound bodies) is split into one run per manifold.
void BuildRestingBatches(const std::vector<SweepTask>& schedule,
                         const std::vector<RestingRow>& rows,
                         const std::vector<std::uint32_t>& row_island, std::size_t body_count,
                         RestingBatches* batches);

// Copies what a sweep changes in a row (its impulses, split impulse and
// last velocity) from the blocks to rows, or back.
void StoreBatchState(const RestingBatches& batches, std::vector<RestingRow>* rows);
void LoadBatchState(const std::vector<RestingRow>& rows, RestingBatches* batches);

// One sweep of the rows' Gauss-Seidel update (UpdateRestingRow) over the
// batches, skipping the runs of converged islands and recording each
// island's largest |v - v_previous sweep|^2, as SweepSchedule does.
void SweepBatches(RestingBatches* batches, std::vector<SolverBody>* bodies,
                  std::vector<RestingIsland>* islands);

// One sweep of the split impulse's update (UpdatePseudoRow) over the
// batches, on the pseudo velocities, every island; a batch with no row
// penetrating beyond the slop is skipped, as its updates change nothing.
void SweepPseudoBatches(RestingBatches* batches, std::vector<SolverBody>* bodies,
                        double position_correction, double inverse_dt);

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_SOLVER_RESTING_BATCHES_H_
