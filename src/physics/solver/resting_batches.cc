#include "physics/solver/resting_batches.h"

#include <algorithm>
#include <cstdint>
#include <vector>

#include "physics/solver/contact_solver.h"

namespace rigid_body_sim::physics {
namespace {

// The first batch at or after `batch` with a free lane (batches.size() when
// none is), halving the paths of next_open as it walks them. next_open[i] is
// i for a batch with a free lane, else a later batch to look at.
std::uint32_t FindOpenBatch(std::uint32_t batch, std::vector<std::uint32_t>* next_open) {
  std::vector<std::uint32_t>& next = *next_open;
  const auto count = static_cast<std::uint32_t>(next.size());
  while (batch < count && next[batch] != batch) {
    const std::uint32_t later = next[batch];
    if (later < count && next[later] != later) next[batch] = next[later];
    batch = later;
  }
  return batch;
}

// Places the run [begin, end) of one manifold, with the moving-body bits
// `moving` (SweepTask::kFirstA, kFirstB), in the first batch with a free
// lane after every batch that holds one of its moving bodies.
void PlaceRun(std::uint32_t begin, std::uint32_t end, std::uint8_t moving,
              const std::vector<RestingRow>& rows, const std::vector<std::uint32_t>& row_island,
              RestingBatches* out) {
  const RestingRow& first = rows[begin];
  std::int32_t after = -1;
  if (moving & SweepTask::kFirstA) after = std::max(after, out->last_batch_of_body[first.body_a]);
  if (moving & SweepTask::kFirstB) after = std::max(after, out->last_batch_of_body[first.body_b]);
  const std::uint32_t index = FindOpenBatch(static_cast<std::uint32_t>(after + 1), &out->next_open);
  if (index == out->batches.size()) {
    out->batches.emplace_back();
    out->next_open.push_back(index);
  }
  RunBatch& batch = out->batches[index];
  const std::uint32_t lane = batch.lanes++;
  batch.row_begin[lane] = begin;
  batch.row_end[lane] = end;
  batch.body_a[lane] = first.body_a;
  batch.body_b[lane] = first.body_b;
  batch.island[lane] = row_island[begin];
  batch.moving[lane] = moving;
  batch.row_count[lane] = end - begin;
  batch.block_count = std::max(batch.block_count, end - begin);
  for (std::uint32_t r = begin; r < end; ++r) batch.penetrates |= rows[r].depth > 0.0;
  for (int axis = 0; axis < 3; ++axis) {
    batch.normal[axis][lane] = first.normal[axis];
    batch.tangent[0][axis][lane] = first.tangent[0][axis];
    batch.tangent[1][axis][lane] = first.tangent[1][axis];
  }
  batch.friction[lane] = first.friction;
  batch.inverse_mass_a[lane] = first.inverse_mass_a;
  batch.inverse_mass_b[lane] = first.inverse_mass_b;
  if (batch.lanes == kBatchLanes) out->next_open[index] = index + 1;
  const auto placed = static_cast<std::int32_t>(index);
  if (moving & SweepTask::kFirstA) out->last_batch_of_body[first.body_a] = placed;
  if (moving & SweepTask::kFirstB) out->last_batch_of_body[first.body_b] = placed;
}

// Places the run [begin, end) of one body pair as one run per manifold:
// rows of one manifold share their frame and friction.
void PlaceRuns(std::uint32_t begin, std::uint32_t end, std::uint8_t moving,
               const std::vector<RestingRow>& rows, const std::vector<std::uint32_t>& row_island,
               RestingBatches* out) {
  auto same_manifold = [&](const RestingRow& a, const RestingRow& b) {
    return a.normal == b.normal && a.tangent[0] == b.tangent[0] && a.friction == b.friction;
  };
  while (begin < end) {
    std::uint32_t split = begin + 1;
    while (split < end && same_manifold(rows[begin], rows[split])) ++split;
    PlaceRun(begin, split, moving, rows, row_island, out);
    begin = split;
  }
}

// Copies what a sweep changes in a row (its impulses and last velocity)
// into lane `lane` of its block.
void PackState(const RestingRow& row, int lane, RowBlock* block) {
  block->normal_impulse[lane] = row.normal_impulse;
  block->tangent_impulse[0][lane] = row.tangent_impulse[0];
  block->tangent_impulse[1][lane] = row.tangent_impulse[1];
  for (int axis = 0; axis < 3; ++axis) block->last_velocity[axis][lane] = row.last_velocity[axis];
  block->pseudo_impulse[lane] = row.pseudo_impulse;
}

// Copies a row's own fields, and its state, into lane `lane` of its block.
void PackRow(const RestingRow& row, int lane, RowBlock* block) {
  for (int axis = 0; axis < 3; ++axis) {
    block->r_a[axis][lane] = row.r_a[axis];
    block->r_b[axis][lane] = row.r_b[axis];
    for (int direction = 0; direction < 3; ++direction) {
      block->angular_a[direction][axis][lane] = row.angular_a[direction][axis];
      block->angular_b[direction][axis][lane] = row.angular_b[direction][axis];
    }
  }
  block->normal_mass[lane] = row.normal_mass;
  block->tangent_mass[lane] = row.tangent_mass;
  block->normal_coupling[0][lane] = row.normal_coupling[0];
  block->normal_coupling[1][lane] = row.normal_coupling[1];
  block->target[lane] = row.target;
  block->depth[lane] = row.depth;
  PackState(row, lane, block);
}

// Zero in every field of a lane without a row, so that its arithmetic is
// harmless (row_count tells the sweep which lanes hold rows).
void ClearLane(int lane, RowBlock* block) {
  static const RestingRow kNoRow;  // zero lever arms, responses, masses and impulses
  PackRow(kNoRow, lane, block);
}

// Calls visit(row, lane, block) for every row of every batch.
template <typename Batches, typename Visit>
void ForEachRow(Batches* batches, const Visit& visit) {
  for (const RunBatch& batch : batches->batches) {
    for (std::uint32_t lane = 0; lane < batch.lanes; ++lane) {
      for (std::uint32_t row = batch.row_begin[lane]; row < batch.row_end[lane]; ++row) {
        visit(row, static_cast<int>(lane),
              &batches->blocks[batch.block_begin + (row - batch.row_begin[lane])]);
      }
    }
  }
}

}  // namespace

void BuildRestingBatches(const std::vector<SweepTask>& schedule,
                         const std::vector<RestingRow>& rows,
                         const std::vector<std::uint32_t>& row_island, std::size_t body_count,
                         RestingBatches* batches) {
  batches->batches.clear();
  batches->next_open.clear();
  batches->last_batch_of_body.assign(body_count, -1);
  for (const SweepTask& task : schedule) {
    PlaceRuns(task.first_begin, task.first_end, task.moving & 3, rows, row_island, batches);
    if (task.second_begin != task.second_end) {
      PlaceRuns(task.second_begin, task.second_end, static_cast<std::uint8_t>(task.moving >> 2),
                rows, row_island, batches);
    }
  }
  std::uint32_t block_count = 0;
  for (RunBatch& batch : batches->batches) {
    batch.block_begin = block_count;
    block_count += batch.block_count;
  }
  // Blocks are reused from step to step: every lane is written.
  batches->blocks.resize(block_count);
  for (const RunBatch& batch : batches->batches) {
    RowBlock* blocks = batches->blocks.data() + batch.block_begin;
    for (int lane = 0; lane < kBatchLanes; ++lane) {
      const auto count = static_cast<std::uint32_t>(batch.row_count[lane]);
      for (std::uint32_t k = 0; k < batch.block_count; ++k) {
        if (k < count) {
          PackRow(rows[batch.row_begin[lane] + k], lane, &blocks[k]);
        } else {
          ClearLane(lane, &blocks[k]);
        }
      }
    }
  }
}

void StoreBatchState(const RestingBatches& batches, std::vector<RestingRow>* rows) {
  ForEachRow(&batches, [&](std::uint32_t index, int lane, const RowBlock* block) {
    RestingRow& row = (*rows)[index];
    row.normal_impulse = block->normal_impulse[lane];
    row.tangent_impulse = {block->tangent_impulse[0][lane], block->tangent_impulse[1][lane]};
    row.last_velocity = Vec3(block->last_velocity[0][lane], block->last_velocity[1][lane],
                             block->last_velocity[2][lane]);
    row.pseudo_impulse = block->pseudo_impulse[lane];
  });
}

void LoadBatchState(const std::vector<RestingRow>& rows, RestingBatches* batches) {
  ForEachRow(batches, [&](std::uint32_t index, int lane, RowBlock* block) {
    PackState(rows[index], lane, block);
  });
}

}  // namespace rigid_body_sim::physics
