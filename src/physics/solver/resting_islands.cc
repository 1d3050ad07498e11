// Islands of the resting solve: the order a sweep updates its rows in, the
// connected components that stop sweeping on their own, and the exact
// finish of small islands the sweeps leave unconverged.
#include "physics/solver/contact_solver.h"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <vector>

#include <Eigen/Core>

#include "physics/solver/lcp.h"
#include "physics/solver/resting_row.h"

namespace rigid_body_sim::physics {
namespace {

// A run partners with one of at most this many runs after it that are not
// scheduled yet.
constexpr int kPartnerWindow = 4;
// Marks a body the solve cannot move (static or asleep): rows that share
// only such bodies are independent.
constexpr std::uint32_t kFixedBody = std::numeric_limits<std::uint32_t>::max();

// Whether the solve can move a body: static and sleeping ones have zero
// inverse mass and inertia.
bool Moves(const SolverBody& body) {
  return body.inverse_mass != 0.0 || (body.inverse_inertia_world.array() != 0.0).any();
}

// n_i . (change of v_r at row i per unit normal impulse at row k): A_ik of
// the resting LCP, J_i M^-1 J_k^T, from row k's responses I^-1 (r x n).
double NormalResponse(const RestingRow& row_i, const RestingRow& row_k) {
  Vec3 relative = Vec3::Zero();
  auto add = [&](std::uint32_t body, const Vec3& r, double sign) {
    if (body == row_k.body_a) {
      relative += sign * (row_k.inverse_mass_a * row_k.normal + row_k.angular_a[0].cross(r));
    }
    if (body == row_k.body_b) {
      relative -= sign * (row_k.inverse_mass_b * row_k.normal + row_k.angular_b[0].cross(r));
    }
  };
  add(row_i.body_a, row_i.r_a, 1.0);
  add(row_i.body_b, row_i.r_b, -1.0);
  return row_i.normal.dot(relative);
}

}  // namespace

// Gauss-Seidel updates of rows that share no body the solve can move commute
// exactly, in floating point too: each reads and writes only its own
// bodies' velocities. So a run of rows (one body pair's) may move forward
// past runs it shares no moving body with, to be updated side by side with
// the run it then follows. A sweep in this order gives bit for bit the
// sweep in manifold order, while the processor overlaps two independent
// chains of updates, where one chain leaves it waiting on each update's
// result (a third chain measured no faster). Greedy, in manifold order: each
// run not yet scheduled takes the first of the next kPartnerWindow such runs
// that shares no moving body with it nor with the runs it would pass.
// Each group of islands (GroupIslands) gets its own schedule of its own
// runs, in the same manifold order; with one group this is the whole sweep.
void ContactSolver::ScheduleRuns() {
  struct Run {
    std::uint32_t begin;
    std::uint32_t end;
    std::array<std::uint32_t, 2> moving;  // kFixedBody for a body that does not move
    bool scheduled;
  };
  if (rows_.empty()) {
    // Nothing to schedule, and nothing allocated for it.
    for (std::vector<SweepTask>& schedule : schedules_) schedule.clear();
    return;
  }
  auto moving = [&](std::uint32_t index) { return Moves(bodies_[index]) ? index : kFixedBody; };
  std::vector<Run> runs;
  for (std::uint32_t r = 0; r < rows_.size();) {
    const std::uint32_t begin = r;
    const std::uint32_t a = rows_[r].body_a;
    const std::uint32_t b = rows_[r].body_b;
    while (r < rows_.size() && rows_[r].body_a == a && rows_[r].body_b == b) ++r;
    runs.push_back({begin, r, {moving(a), moving(b)}, false});
  }
  const std::size_t group_count = schedules_.size();
  std::vector<std::vector<std::uint32_t>> group_runs(group_count);
  for (std::uint32_t i = 0; i < runs.size(); ++i) {
    group_runs[island_group_[row_island_[runs[i].begin]]].push_back(i);
  }
  std::vector<std::uint32_t> blocked;
  auto is_blocked = [&](const Run& run) {
    for (const std::uint32_t body : run.moving) {
      if (body != kFixedBody && std::find(blocked.begin(), blocked.end(), body) != blocked.end()) {
        return true;
      }
    }
    return false;
  };
  auto moving_bits = [](const Run& run, std::uint8_t bit_a, std::uint8_t bit_b) {
    return static_cast<std::uint8_t>((run.moving[0] != kFixedBody ? bit_a : 0) |
                                     (run.moving[1] != kFixedBody ? bit_b : 0));
  };
  for (std::size_t group = 0; group < group_count; ++group) {
    const std::vector<std::uint32_t>& order = group_runs[group];
    std::vector<SweepTask>& schedule = schedules_[group];
    schedule.clear();
    for (std::size_t n = 0; n < order.size(); ++n) {
      Run& run = runs[order[n]];
      if (run.scheduled) continue;
      run.scheduled = true;
      SweepTask& task = schedule.emplace_back();
      task.first_begin = run.begin;
      task.first_end = run.end;
      task.second_begin = task.second_end = run.end;
      task.first_island = task.second_island = row_island_[run.begin];
      task.moving = moving_bits(run, SweepTask::kFirstA, SweepTask::kFirstB);
      blocked.assign(run.moving.begin(), run.moving.end());
      const int window = settings_.interleave_independent_runs ? kPartnerWindow : 0;
      int looked = 0;
      for (std::size_t m = n + 1; m < order.size() && looked < window; ++m) {
        Run& partner = runs[order[m]];
        if (partner.scheduled) continue;
        ++looked;
        if (!is_blocked(partner)) {
          partner.scheduled = true;
          task.second_begin = partner.begin;
          task.second_end = partner.end;
          task.second_island = row_island_[partner.begin];
          task.moving |= moving_bits(partner, SweepTask::kSecondA, SweepTask::kSecondB);
          break;
        }
        blocked.insert(blocked.end(), partner.moving.begin(), partner.moving.end());
      }
    }
  }
}

// Islands share no body the solve moves, so each may be swept by its own
// thread: a group of islands per thread, the islands in order each to the
// group with the fewest rows so far (ties to the lowest group), which
// depends on the rows only. One group unless there are threads, two islands
// and rows enough to pay for waking the threads.
void ContactSolver::GroupIslands() {
  constexpr std::size_t kMinRowsToShare = 256;
  std::size_t group_count = 1;
  if (pool_ != nullptr && islands_.size() > 1 && rows_.size() >= kMinRowsToShare) {
    group_count = std::min(static_cast<std::size_t>(pool_->threads()), islands_.size());
  }
  schedules_.resize(group_count);
  island_group_.assign(islands_.size(), 0);
  if (group_count == 1) return;
  std::vector<std::size_t> rows_in_group(group_count, 0);
  for (std::uint32_t island = 0; island < islands_.size(); ++island) {
    const std::size_t group = static_cast<std::size_t>(
        std::min_element(rows_in_group.begin(), rows_in_group.end()) - rows_in_group.begin());
    island_group_[island] = static_cast<std::uint32_t>(group);
    rows_in_group[group] += islands_[island].row_count;
  }
}

// Rows of different islands share no body the solve moves, so a sweep's
// updates of one island never read another's results, and an island can
// stop sweeping once it alone has converged: a quiet island stops early
// while a busy one goes on, and each island's rows are updated in the same
// order as if it were alone in the world. Islands by union-find over the
// rows' moving bodies, numbered in the order of their first row.
void ContactSolver::FindIslands() {
  constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
  island_sets_.Reset(bodies_.size());
  for (const RestingRow& row : rows_) {
    if (Moves(bodies_[row.body_a]) && Moves(bodies_[row.body_b])) {
      island_sets_.Join(row.body_a, row.body_b);
    }
  }
  island_of_root_.assign(bodies_.size(), kNone);
  row_island_.resize(rows_.size());
  islands_.clear();
  for (std::size_t r = 0; r < rows_.size(); ++r) {
    // A row between two bodies that do not move changes nothing; it takes
    // body B's set, which no row joins, so it is an island of its own rows.
    const std::uint32_t body = Moves(bodies_[rows_[r].body_a]) ? rows_[r].body_a : rows_[r].body_b;
    std::uint32_t& island = island_of_root_[island_sets_.Find(body)];
    if (island == kNone) {
      island = static_cast<std::uint32_t>(islands_.size());
      islands_.emplace_back();
    }
    row_island_[r] = island;
    ++islands_[island].row_count;
  }
}

// An island the sweeps left unconverged, with at most max_pivoting_points
// rows, has its normal impulses solved again by pivoting (lcp.h), all at
// once and exactly, with its friction impulses held: f >= 0,
// w = A f + b >= 0, f . w = 0, where w_i = n_i . v_r,i - target_i and
// A_ik = J_i M^-1 J_k^T (Baraff 1997, "Rigid Body Simulation II",
// section 9, eq. (9-8) and appendix D), so
// b = w(now) - A f(now). Gauss-Seidel gains about m/M of the way per sweep
// where a light body carries a heavy one; pivoting does not depend on the
// masses. Friction that the new normal impulses leave outside its cone is
// projected back onto it.
bool ContactSolver::FinishesExactly(const RestingIsland& island) const {
  return !island.converged && static_cast<int>(island.row_count) <= settings_.max_pivoting_points;
}

bool ContactSolver::AnyIslandToFinish() const {
  return std::any_of(islands_.begin(), islands_.end(),
                     [this](const RestingIsland& island) { return FinishesExactly(island); });
}

void ContactSolver::FinishIslandsExactly() {
  // The rows of the islands to finish, grouped by island (a counting sort):
  // island i's are exact_rows_[exact_begin_[i], exact_begin_[i + 1]).
  auto finishes = [this](const RestingIsland& island) { return FinishesExactly(island); };
  exact_begin_.assign(islands_.size() + 1, 0);
  for (std::uint32_t island = 0; island < islands_.size(); ++island) {
    const std::uint32_t count = finishes(islands_[island]) ? islands_[island].row_count : 0;
    exact_begin_[island + 1] = exact_begin_[island] + count;
  }
  exact_rows_.resize(exact_begin_.back());
  std::vector<std::uint32_t> next(exact_begin_.begin(), exact_begin_.end() - 1);
  for (std::uint32_t r = 0; r < rows_.size(); ++r) {
    const std::uint32_t island = row_island_[r];
    if (finishes(islands_[island])) exact_rows_[next[island]++] = r;
  }
  for (std::uint32_t island = 0; island < islands_.size(); ++island) {
    const int n = static_cast<int>(exact_begin_[island + 1] - exact_begin_[island]);
    if (n == 0) continue;
    const std::uint32_t* island_rows = exact_rows_.data() + exact_begin_[island];
    Eigen::MatrixXd a(n, n);
    Eigen::VectorXd b(n);
    for (int i = 0; i < n; ++i) {
      const RestingRow& row_i = rows_[island_rows[i]];
      for (int k = 0; k < n; ++k) a(i, k) = NormalResponse(row_i, rows_[island_rows[k]]);
    }
    for (int i = 0; i < n; ++i) {
      const RestingRow& row = rows_[island_rows[i]];
      b[i] = row.normal.dot(RowVelocity(row, bodies_)) - row.target;
      for (int k = 0; k < n; ++k) b[i] -= a(i, k) * rows_[island_rows[k]].normal_impulse;
    }
    const Result<LcpSolution> solution = SolveLcpLemke(a, b);
    if (!solution.ok()) continue;
    for (int k = 0; k < n; ++k) {
      RestingRow& row = rows_[island_rows[k]];
      const double change = solution->f[k] - row.normal_impulse;
      row.normal_impulse = solution->f[k];
      ApplyRowImpulse(row, Vec3(change, 0.0, 0.0), &bodies_);
    }
    for (int k = 0; k < n; ++k) {
      RestingRow& row = rows_[island_rows[k]];
      const std::array<double, 2> old_tangent = row.tangent_impulse;
      ClampToDisc(row.friction * row.normal_impulse, &row.tangent_impulse);
      const Vec3 change(0.0, row.tangent_impulse[0] - old_tangent[0],
                        row.tangent_impulse[1] - old_tangent[1]);
      if (change[1] != 0.0 || change[2] != 0.0) ApplyRowImpulse(row, change, &bodies_);
    }
  }
  // Only the finished islands sweep again.
  for (std::uint32_t island = 0; island < islands_.size(); ++island) {
    islands_[island].converged = exact_begin_[island + 1] == exact_begin_[island];
  }
}

}  // namespace rigid_body_sim::physics
