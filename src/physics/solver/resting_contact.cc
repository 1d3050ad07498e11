// Resting contact: the rows of the touching points, swept by projected
// Gauss-Seidel until each island of the contact graph has converged, then
// the split impulse's position correction.
#include "physics/solver/contact_solver.h"

#include <algorithm>
#include <cstdint>
#include <vector>

#include "physics/solver/resting_row.h"

namespace rigid_body_sim::physics {
namespace {

// Calls run(group) for each group, on the pool's threads when there are
// several groups (at most one per thread), else on the caller's.
template <typename Run>
void RunGroups(TaskPool* pool, std::size_t group_count, const Run& run) {
  if (group_count == 1 || pool == nullptr) {
    for (std::size_t group = 0; group < group_count; ++group) run(group);
    return;
  }
  const auto threads = static_cast<std::size_t>(pool->threads());
  pool->RunOnAll([&](int thread) {
    for (auto group = static_cast<std::size_t>(thread); group < group_count; group += threads) {
      run(group);
    }
  });
}

}  // namespace

void ContactSolver::SolveRestingContacts() {
  BuildRestingRows();
  FindIslands();
  GroupIslands();
  ScheduleRuns();
  if (settings_.batch_independent_runs) {
    batches_.resize(schedules_.size());
    RunGroups(pool_, schedules_.size(), [&](std::size_t group) {
      BuildRestingBatches(schedules_[group], rows_, row_island_, bodies_.size(), &batches_[group]);
    });
  }
  for (const RestingRow& row : rows_) {
    ApplyRowImpulse(row, Vec3(row.normal_impulse, row.tangent_impulse[0], row.tangent_impulse[1]),
                    &bodies_);
  }

  velocity_sweeps_ = 0;
  velocity_row_updates_ = 0;
  SweepUntilConverged();
  // Small islands still unconverged are solved exactly, then swept again
  // from there so that friction and the normal impulses agree.
  if (AnyIslandToFinish()) {
    StoreBatchStates();
    FinishIslandsExactly();
    LoadBatchStates();
    SweepUntilConverged();
  }

  // Split impulse: pseudo velocities remove penetration beyond the slop
  // without touching the real velocities, so no energy is added. The same
  // schedules, every island, each group on its thread; a task none of whose
  // rows penetrates beyond the slop is left out, as its updates change
  // nothing (UpdatePseudoRow returns at once), so the result is the same
  // bit for bit while a settled pile's sweeps skip most rows. Batched, the
  // same in SIMD lanes, skipping batches with no such row.
  pseudo_schedules_.resize(schedules_.size());
  auto penetrates = [this](std::uint32_t begin, std::uint32_t end) {
    for (std::uint32_t r = begin; r < end; ++r) {
      if (rows_[r].depth > 0.0) return true;
    }
    return false;
  };
  RunGroups(pool_, schedules_.size(), [&](std::size_t group) {
    if (settings_.batch_independent_runs) {
      for (int iteration = 0; iteration < settings_.position_iterations; ++iteration) {
        SweepPseudoBatches(&batches_[group], &bodies_, settings_.position_correction,
                           1.0 / time_step_);
      }
      return;
    }
    std::vector<SweepTask>& pseudo = pseudo_schedules_[group];
    pseudo.clear();
    for (const SweepTask& task : schedules_[group]) {
      if (penetrates(task.first_begin, task.first_end) ||
          penetrates(task.second_begin, task.second_end)) {
        pseudo.push_back(task);
      }
    }
    for (int iteration = 0; iteration < settings_.position_iterations; ++iteration) {
      SweepSchedule</*kPseudo=*/true>(pseudo);
    }
  });
  StoreBatchStates();
  for (const RestingRow& row : rows_) {
    row.point->normal_impulse = row.normal_impulse;
    row.point->tangent_impulse = row.tangent_impulse;
    row.point->pseudo_impulse = row.pseudo_impulse;
  }
}

// Rows of the resting solve: the touching points, copied into one array in
// manifold order so that a sweep walks memory once.
void ContactSolver::BuildRestingRows() {
  const double inverse_dt = 1.0 / time_step_;
  rows_.clear();
  for (SolverManifold& manifold : manifolds_) {
    const SolverBody& a = bodies_[manifold.body_a];
    const SolverBody& b = bodies_[manifold.body_b];
    for (int i = 0; i < manifold.point_count; ++i) {
      SolverPoint& point = manifold.points[i];
      // A point that is not touching yet is left to the time-of-impact
      // search, so that its collision keeps its approach speed and
      // restitution, e = 0 included: an inelastic box lands at the speed of
      // free fall, and the rest of its step is simulated after the impact.
      if (point.separation > settings_.contact_tolerance) {
        point.normal_impulse = 0.0;
        point.tangent_impulse = {0.0, 0.0};
        continue;
      }
      RestingRow& row = rows_.emplace_back();
      row.body_a = manifold.body_a;
      row.body_b = manifold.body_b;
      row.normal = manifold.normal_world;
      row.tangent = manifold.tangent_world;
      row.r_a = point.r_a;
      row.r_b = point.r_b;
      row.friction = manifold.friction;
      row.inverse_mass_a = a.inverse_mass;
      row.inverse_mass_b = b.inverse_mass;
      const std::array<Vec3, 3> directions{row.normal, row.tangent[0], row.tangent[1]};
      // The responses, and from them the effective masses of EffectiveMass
      // and TangentMass: 1/Ma + 1/Mb + sum over A, B of (r x d).I^-1 (r x d).
      std::array<double, 3> inverse_mass_along{};
      for (int k = 0; k < 3; ++k) {
        const Vec3 ra_x_d = point.r_a.cross(directions[k]);
        const Vec3 rb_x_d = point.r_b.cross(directions[k]);
        row.angular_a[k] = a.inverse_inertia_world * ra_x_d;
        row.angular_b[k] = b.inverse_inertia_world * rb_x_d;
        inverse_mass_along[k] = a.inverse_mass + b.inverse_mass + ra_x_d.dot(row.angular_a[k]) +
                                rb_x_d.dot(row.angular_b[k]);
      }
      row.normal_mass = inverse_mass_along[0] > 0.0 ? 1.0 / inverse_mass_along[0] : 0.0;
      const double trace = inverse_mass_along[1] + inverse_mass_along[2];
      row.tangent_mass = trace > 0.0 ? 2.0 / trace : 0.0;
      // K t_k . n: the tangential velocity a unit normal impulse adds, with
      // K = (1/Ma + 1/Mb) 1 - [ra]x Ia^-1 [ra]x - [rb]x Ib^-1 [rb]x. The
      // normal part is 1/Ma + 1/Mb times t.n = 0.
      for (int k = 0; k < 2; ++k) {
        row.normal_coupling[k] = point.r_a.cross(row.tangent[k]).dot(row.angular_a[0]) +
                                 point.r_b.cross(row.tangent[k]).dot(row.angular_b[0]);
      }
      // The trapezoidal drift dt/2 (v_start + v_end) must not close the gap.
      const double gap = std::max(point.separation, 0.0);
      row.target = std::min(0.0, -2.0 * gap * inverse_dt - point.normal_velocity_start);
      row.depth = -point.separation - settings_.penetration_slop;
      row.normal_impulse = point.normal_impulse;
      row.tangent_impulse = point.tangent_impulse;
      row.point = &point;
    }
  }
}

// One sweep over the schedule, the two runs of a task alternately: the
// resting rows' Gauss-Seidel update on the real velocities, which skips the
// runs of converged islands and records each island's largest
// |v - v_previous sweep|^2, or with kPseudo the split impulse's on the
// pseudo velocities, over every island. Flattened: with any update left a
// call, a run's velocities stay in memory and the sweep takes 30 % longer.
template <bool kPseudo>
[[gnu::flatten]] void ContactSolver::SweepSchedule(const std::vector<SweepTask>& schedule) {
  const double correction = settings_.position_correction;
  const double inverse_dt = 1.0 / time_step_;
  for (const SweepTask& task : schedule) {
    std::uint32_t first_begin = task.first_begin;
    std::uint32_t first_end = task.first_end;
    std::uint32_t first_island = task.first_island;
    std::uint32_t second_begin = task.second_begin;
    std::uint32_t second_end = task.second_end;
    std::uint8_t moving = task.moving;
    if constexpr (!kPseudo) {
      if (islands_[task.second_island].converged) second_end = second_begin;
      if (islands_[first_island].converged) {
        first_begin = second_begin;
        first_end = second_end;
        first_island = task.second_island;
        second_end = second_begin;
        moving >>= 2;
      }
      if (first_begin == first_end) continue;
    }
    const bool paired = second_begin != second_end;
    SolverBody& first_a = bodies_[rows_[first_begin].body_a];
    SolverBody& first_b = bodies_[rows_[first_begin].body_b];
    // An unpaired task loads its first run's bodies as the second run's too;
    // the empty second run never updates or stores them.
    const std::uint32_t second_row = paired ? second_begin : first_begin;
    SolverBody& second_a = bodies_[rows_[second_row].body_a];
    SolverBody& second_b = bodies_[rows_[second_row].body_b];
    RunVelocities first = LoadRun<kPseudo>(first_a, first_b);
    RunVelocities second = LoadRun<kPseudo>(second_a, second_b);
    double first_change_squared = 0.0;
    double second_change_squared = 0.0;
    std::uint32_t r = first_begin;
    std::uint32_t s = second_begin;
    while (r < first_end || s < second_end) {
      if (r < first_end) {
        first_change_squared = std::max(
            first_change_squared, UpdateRow<kPseudo>(correction, inverse_dt, &rows_[r++], &first));
      }
      if (s < second_end) {
        second_change_squared =
            std::max(second_change_squared,
                     UpdateRow<kPseudo>(correction, inverse_dt, &rows_[s++], &second));
      }
    }
    // A body the solve does not move keeps its velocity (its inverse mass
    // and inertia are zero), so it is not stored.
    if (paired) {
      StoreRun<kPseudo>(second, (moving & SweepTask::kSecondA) ? &second_a : nullptr,
                        (moving & SweepTask::kSecondB) ? &second_b : nullptr);
    }
    StoreRun<kPseudo>(first, (moving & SweepTask::kFirstA) ? &first_a : nullptr,
                      (moving & SweepTask::kFirstB) ? &first_b : nullptr);
    if constexpr (!kPseudo) {
      double& first_largest = islands_[first_island].largest_change_squared;
      first_largest = std::max(first_largest, first_change_squared);
      if (paired) {
        double& second_largest = islands_[task.second_island].largest_change_squared;
        second_largest = std::max(second_largest, second_change_squared);
      }
    }
  }
}

// Projected Gauss-Seidel, one block per point (UpdateRestingRow), in the
// schedule's order, over the islands not marked converged. An island stops
// sweeping once none of its points' relative velocities changed by more
// than velocity_tolerance since the previous sweep: its motion has
// converged, even where the impulses of redundant points (four corners where
// three would carry the load) still trade load between them. Each group of
// islands sweeps on its own thread; an island's sweeps are the same in any
// group, so the count of the slowest is the same as with one.
void ContactSolver::SweepUntilConverged() {
  const std::size_t group_count = schedules_.size();
  if (group_count == 0 || rows_.empty()) return;
  std::vector<int> sweeps(group_count, 0);
  std::vector<std::size_t> row_updates(group_count, 0);
  RunGroups(pool_, group_count, [&](std::size_t group) {
    sweeps[group] = SweepGroupUntilConverged(group, &row_updates[group]);
  });
  velocity_sweeps_ += *std::max_element(sweeps.begin(), sweeps.end());
  for (const std::size_t updates : row_updates) velocity_row_updates_ += updates;
}

void ContactSolver::StoreBatchStates() {
  if (!settings_.batch_independent_runs) return;
  for (const RestingBatches& group : batches_) StoreBatchState(group, &rows_);
}

void ContactSolver::LoadBatchStates() {
  if (!settings_.batch_independent_runs) return;
  for (RestingBatches& group : batches_) LoadBatchState(rows_, &group);
}

int ContactSolver::SweepGroupUntilConverged(std::size_t group, std::size_t* row_updates) {
  const double tolerance_squared = settings_.velocity_tolerance * settings_.velocity_tolerance;
  std::size_t sweeping = 0;
  for (std::uint32_t island = 0; island < islands_.size(); ++island) {
    sweeping += island_group_[island] == group && !islands_[island].converged;
  }
  int sweeps = 0;
  while (sweeping > 0 && sweeps < settings_.velocity_iterations) {
    if (settings_.batch_independent_runs) {
      SweepBatches(&batches_[group], &bodies_, &islands_);
    } else {
      SweepSchedule</*kPseudo=*/false>(schedules_[group]);
    }
    ++sweeps;
    for (std::uint32_t index = 0; index < islands_.size(); ++index) {
      RestingIsland& island = islands_[index];
      if (island_group_[index] != group || island.converged) continue;
      *row_updates += island.row_count;
      // The first sweep has no sweep before it to compare with.
      if (sweeps > 1 && island.largest_change_squared <= tolerance_squared) {
        island.converged = true;
        --sweeping;
      }
      island.largest_change_squared = 0.0;
    }
  }
  return sweeps;
}

}  // namespace rigid_body_sim::physics
