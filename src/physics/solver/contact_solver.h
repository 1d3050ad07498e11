// Stage 4 of a step: contact dynamics.
//
// Baraff's order (Baraff 2001, "Collision and Contact" course slides,
// "Outline"; Baraff 1997, "Rigid Body Simulation II", section 8, then 9): colliding contacts are
// resolved first by impulses, on the velocities the step starts with; then the forces act and
// resting contacts get the forces that keep them from penetrating. Both are solved for all the
// contacts at once, as linear complementarity problems at the velocity level (impulses over the
// step).
#ifndef RIGID_BODY_SIM_PHYSICS_SOLVER_CONTACT_SOLVER_H_
#define RIGID_BODY_SIM_PHYSICS_SOLVER_CONTACT_SOLVER_H_

#include <array>
#include <cstdint>
#include <vector>

#include "physics/contact/contact_cache.h"
#include "physics/contact/contact_frame.h"
#include "physics/contact/contact_manifold.h"
#include "physics/solver/resting_batches.h"
#include "physics/world/task_pool.h"
#include "physics/world/union_find.h"
#include "rigid_body_sim/physics/body.h"
#include "rigid_body_sim/physics/types.h"
#include "rigid_body_sim/physics/world_settings.h"

namespace rigid_body_sim::physics {

// Velocities and inverse inertia of one body during the solve. Static and
// sleeping bodies have zero inverse mass and inertia.
struct SolverBody {
  Vec3 linear_velocity = Vec3::Zero();          // m/s, of the centre of mass
  Vec3 angular_velocity = Vec3::Zero();         // rad/s
  Vec3 pseudo_linear_velocity = Vec3::Zero();   // m/s, split-impulse correction
  Vec3 pseudo_angular_velocity = Vec3::Zero();  // rad/s
  double inverse_mass = 0.0;
  Mat3 inverse_inertia_world = Mat3::Zero();
};

struct SolverPoint {
  Vec3 r_a = Vec3::Zero();  // m, from A's centre of mass to the contact point
  Vec3 r_b = Vec3::Zero();
  double separation = 0.0;                  // m
  double normal_mass = 0.0;                 // 1 / (n . K n), kg; set for collision rounds only
  double tangent_mass = 0.0;                // kg, the same along both tangents; likewise
  double normal_velocity_before = 0.0;      // m/s, v_r at the start of the step
  double normal_velocity_start = 0.0;       // m/s, v_r after the collisions, before the forces
  double collision_impulse = 0.0;           // N s, from the collision phase
  double normal_impulse = 0.0;              // N s, resting phase (warm-started)
  std::array<double, 2> tangent_impulse{};  // N s, resting phase (warm-started)
  double pseudo_impulse = 0.0;
  double preload = 0.0;           // N s per step, the soft step's (CachedImpulse::preload)
  double carried_approach = 0.0;  // m/s, likewise (CachedImpulse::approach_velocity)
  ContactType type = ContactType::kSeparating;
  FeatureId feature;
};

// One manifold: up to four points sharing a normal and a tangent basis.
struct SolverManifold {
  std::uint32_t body_a = 0;  // indices into the solver bodies
  std::uint32_t body_b = 0;
  Vec3 normal_world = Vec3::UnitZ();  // unit, from B to A
  std::array<Vec3, 2> tangent_world{Vec3::UnitX(), Vec3::UnitY()};
  double friction = 0.0;     // mu, combined
  double restitution = 0.0;  // e, combined
  int point_count = 0;
  bool new_pair = false;  // its pair had no point last step
  std::array<SolverPoint, ContactManifold::kMaxPoints> points;
};

// One touching point as the resting solve sweeps it: the manifold's frame
// and the point's lever arms and masses copied next to its impulses.
struct RestingRow {
  std::uint32_t body_a = 0;
  std::uint32_t body_b = 0;
  Vec3 normal = Vec3::UnitZ();  // unit, world, from B to A
  std::array<Vec3, 2> tangent{Vec3::UnitX(), Vec3::UnitY()};
  Vec3 r_a = Vec3::Zero();  // m
  Vec3 r_b = Vec3::Zero();
  double inverse_mass_a = 0.0;  // 1/kg
  double inverse_mass_b = 0.0;
  // rad/s per N s: I^-1 (r x d) for d = n, t_0, t_1, the angular velocity a
  // unit impulse along d adds to each body.
  std::array<Vec3, 3> angular_a{Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
  std::array<Vec3, 3> angular_b{Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
  double normal_mass = 0.0;                 // kg
  double tangent_mass = 0.0;                // kg
  double friction = 0.0;                    // mu
  std::array<double, 2> normal_coupling{};  // 1/kg, t_k . K n
  double target = 0.0;                      // m/s, lowest v_r+ allowed
  double depth = 0.0;                       // m, penetration beyond the slop
  double normal_impulse = 0.0;              // N s
  std::array<double, 2> tangent_impulse{};  // N s
  double pseudo_impulse = 0.0;              // N s, split impulse
  Vec3 last_velocity = Vec3::Zero();        // m/s, v_r at the previous sweep
  SolverPoint* point = nullptr;             // where the impulses go back
};

// Two runs of resting rows, each the adjacent rows of one body pair, that a
// sweep updates side by side: [first_begin, first_end) and
// [second_begin, second_end), the second empty when no run could join the
// first; with the islands the two runs belong to (a run's two bodies are in
// one island).
struct SweepTask {
  std::uint32_t first_begin = 0;
  std::uint32_t first_end = 0;
  std::uint32_t second_begin = 0;
  std::uint32_t second_end = 0;
  std::uint32_t first_island = 0;
  std::uint32_t second_island = 0;
  // Which of the four bodies the solve moves (kFirstA ...): only those are
  // stored back, so that two threads sweeping rows on the same static body
  // never write it.
  std::uint8_t moving = 0;
  static constexpr std::uint8_t kFirstA = 1;
  static constexpr std::uint8_t kFirstB = 2;
  static constexpr std::uint8_t kSecondA = 4;
  static constexpr std::uint8_t kSecondB = 8;
};

// One island of the resting solve, a connected component of its rows
// through bodies the solve moves, while its sweeps go on.
struct RestingIsland {
  std::uint32_t row_count = 0;
  bool converged = false;
  // m^2/s^2; the largest |v - v_previous sweep|^2 of its points in the
  // current sweep.
  double largest_change_squared = 0.0;
};

class ContactSolver {
 public:
  // Starts a new step: keeps the arrays' memory, clears their contents.
  void Reset(const SolverSettings& settings, double time_step, std::size_t body_count);
  // The threads the resting solve shares its islands among (none: one).
  void set_pool(TaskPool* pool) { pool_ = pool; }

  std::vector<SolverBody>& bodies() { return bodies_; }
  std::vector<SolverManifold>& manifolds() { return manifolds_; }
  const std::vector<SolverManifold>& manifolds() const { return manifolds_; }
  // Each manifold's (body_a, body_b), beside them: a walk over the bodies
  // loads 8 bytes a manifold instead of its line (BuildManifolds writes
  // both).
  std::vector<std::array<std::uint32_t, 2>>& manifold_bodies() { return manifold_bodies_; }

  // One solver manifold per touching pair of `pairs`, with its points'
  // lever arms from `bodies` (the world's slots), combined materials and
  // last step's impulses, built on `pool`.
  void BuildManifolds(const std::vector<ShapePairContact*>& pairs, const std::vector<Body>& bodies,
                      TaskPool* pool);

  // Computes the tangent basis of every manifold (r_a and r_b are set by
  // the caller), and classifies each point by v_r before anything acts.
  void Prepare();

  // Colliding contact. Each round takes the points with v_r < -epsilon and
  // finds compression impulses j_c >= 0 that stop them all at once
  // (v_r+ >= 0, j_c v_r+ = 0, with Coulomb friction), then adds the
  // restitution impulses e j_c (Poisson's hypothesis). For one point this is
  // Baraff's impulse j = -(1+e) v_r- / (1/Ma + 1/Mb + n.(Ia^-1(ra x n)) x ra
  // + n.(Ib^-1(rb x n)) x rb) (Baraff 1997, "Rigid Body Simulation II", eq. (8-18));
  // for several it never adds
  // energy: dE = -(1 - e^2)/2 j_c.A j_c. Points that a round made colliding
  // (a row of balls) are resolved in the next round. Rounds stop once no
  // colliding point has e > 0: a perfectly inelastic collision needs only
  // v_r+ >= 0 with j >= 0 and j v_r+ = 0, which the resting solve imposes on
  // those points (their target is 0) at the same time as on the rest.
  void ResolveCollisions();

  // Records v_r after the collisions and before the forces, which the
  // resting contacts need for the trapezoidal drift.
  void RecordStartVelocities();

  // Resting contact at the velocity level, for the touching points:
  // impulses f >= 0 with v_r+ >= target and f (v_r+ - target) = 0, with
  // Coulomb friction |f_t| <= mu f_n in a circular cone, by projected
  // Gauss-Seidel warm-started from last step's impulses. The target keeps the
  // drift x += dt/2 (v_start + v_end) from entering the other body,
  // target = min(0, -2 max(separation, 0)/dt - v_r,start), so a body that
  // leaves the surface within the step flies free, and one held at rest is
  // not pushed out (that is the split impulse's job). Points still apart are
  // left to the time-of-impact search. Then the split-impulse pseudo velocities that push
  // penetrating contacts apart. Each island of the contact graph stops sweeping on its own
  // (FindIslands); a small one still unconverged is finished by pivoting
  // (FinishIslandsExactly).
  void SolveRestingContacts();

  double time_step() const { return time_step_; }
  // Velocity sweeps the last SolveRestingContacts ran on its slowest
  // island to converge.
  int velocity_sweeps() const { return velocity_sweeps_; }
  // Row updates of those sweeps: each island's rows times its sweeps.
  std::size_t velocity_row_updates() const { return velocity_row_updates_; }
  // Groups of islands the last SolveRestingContacts swept, one per thread.
  int island_groups() const { return static_cast<int>(schedules_.size()); }

 private:
  void ApplyImpulse(const SolverManifold& manifold, const SolverPoint& point,
                    const Vec3& impulse_world);
  double NormalVelocity(const SolverManifold& manifold, const SolverPoint& point) const;
  Vec3 RelativeVelocity(const SolverManifold& manifold, const SolverPoint& point) const;
  void BuildRestingRows();
  void FindIslands();
  // Shares the islands among the threads (island_group_), fewest rows first.
  void GroupIslands();
  void ScheduleRuns();
  template <bool kPseudo>
  void SweepSchedule(const std::vector<SweepTask>& schedule);
  void SweepUntilConverged();
  // With batch_independent_runs, copies the rows' impulses from the batches
  // to rows_, or back.
  void StoreBatchStates();
  void LoadBatchStates();
  // SweepUntilConverged for one group's islands; returns its sweeps and adds
  // its row updates to *row_updates.
  int SweepGroupUntilConverged(std::size_t group, std::size_t* row_updates);
  // Whether an island is unconverged and small enough to finish exactly
  // (max_pivoting_points), and whether any is.
  bool FinishesExactly(const RestingIsland& island) const;
  bool AnyIslandToFinish() const;
  // Finishes those islands, which it then marks unconverged, the others
  // converged.
  void FinishIslandsExactly();
  void ComputeMasses();
  // Applies a collision round's restitution impulses, scaled so that they
  // add no kinetic energy; returns the scale (collision_impulses.cc).
  double ApplyRestitution(const std::vector<std::pair<int, int>>& active,
                          const std::vector<double>& normal, bool last_round, double energy_before);
  bool SolveCompressionExactly(const std::vector<std::pair<int, int>>& active,
                               std::vector<double>* normal);
  // One PGS pass over the rows of the given points; returns the largest
  // impulse change.
  double CollisionSweep(const std::vector<std::pair<int, int>>& active, std::vector<double>* normal,
                        std::vector<std::array<double, 2>>* tangent);

  SolverSettings settings_;
  double time_step_ = 1.0;
  int velocity_sweeps_ = 0;
  std::size_t velocity_row_updates_ = 0;
  // Whether ResolveCollisions applied impulses, so that v_r may differ from
  // Prepare's.
  bool velocities_changed_ = false;
  std::vector<SolverBody> bodies_;
  std::vector<SolverManifold> manifolds_;
  std::vector<std::array<std::uint32_t, 2>> manifold_bodies_;
  std::vector<RestingRow> rows_;
  // The bodies of the current collision round's points, each once.
  std::vector<std::uint32_t> collision_bodies_;
  TaskPool* pool_ = nullptr;
  // One schedule per group of islands, each swept by one thread; a single
  // group (one thread, or one island) is the reference order.
  std::vector<std::vector<SweepTask>> schedules_;
  // Per group, its schedule's runs in batches of independent runs, swept
  // lane by lane (batch_independent_runs).
  std::vector<RestingBatches> batches_;
  std::vector<std::uint32_t> island_group_;  // per island, its group
  // Per group, the tasks of its schedule with a row penetrating beyond the
  // slop: the only ones the split impulse's sweeps change anything in.
  std::vector<std::vector<SweepTask>> pseudo_schedules_;
  std::vector<RestingIsland> islands_;
  // Each row's island; with the rest, scratch of FindIslands kept for its
  // memory.
  std::vector<std::uint32_t> row_island_;
  UnionFind island_sets_;
  std::vector<std::uint32_t> island_of_root_;
  // Scratch of FinishIslandsExactly, kept for its memory.
  std::vector<std::uint32_t> exact_rows_;
  std::vector<std::uint32_t> exact_begin_;
};

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_SOLVER_CONTACT_SOLVER_H_
