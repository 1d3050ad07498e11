// The simulated world: bodies, settings and the time step.
#ifndef RIGID_BODY_SIM_PHYSICS_WORLD_H_
#define RIGID_BODY_SIM_PHYSICS_WORLD_H_

#include <array>
#include <cstddef>
#include <vector>

#include "rigid_body_sim/physics/body.h"
#include "rigid_body_sim/physics/broad_phase.h"
#include "rigid_body_sim/physics/contact.h"
#include "rigid_body_sim/physics/contact_cache.h"
#include "rigid_body_sim/physics/contact_solver.h"
#include "rigid_body_sim/physics/integrator.h"
#include "rigid_body_sim/physics/result.h"
#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::physics {

struct SleepSettings {
  bool enabled = true;
  double linear_velocity = 0.05;  // m/s; slower bodies may sleep
  double angular_velocity = 0.1;  // rad/s
  double time_to_sleep = 0.5;     // s an island must stay slow before it sleeps
  // s; a body whose speed or angular speed has grown at every step for this
  // long is getting under way, not settling, and keeps its island awake
  // however slow it still is: a box on a slope just steeper than its
  // friction angle, a ball on a gentle slope, a box tipping off an edge.
  // Speeds below 2 % of the thresholds above do not count. Long enough that
  // the slow sway of a large stack settling is not taken for it (in the
  // benchmark's 4,095-box pyramid a box's speed rises for up to 0.11 s).
  // 0 disables it.
  double speeding_up_time = 0.2;
};

struct WorldSettings {
  Vec3 gravity = Vec3(0.0, 0.0, -9.81);  // m/s^2, world frame (REP 103: z up)
  double time_step = 1.0 / 240.0;        // s, > 0
  // m; bounding boxes are fattened by this, and contact points are reported
  // while the surfaces are closer than this plus the pair's motion in a step.
  double contact_margin = 0.005;
  // A body moving more than this fraction of its thickness in one step is
  // sampled along its path, so it cannot pass through anything (0, 1].
  double continuous_fraction = 0.25;
  // m; a manifold between two polyhedra is carried along with the bodies
  // instead of clipped again while their relative motion since it was
  // clipped moves no point by more than this (0: clip every step).
  double contact_reuse_distance = 1e-3;
  SolverSettings solver;
  SleepSettings sleep;
};

Status ValidateWorldSettings(const WorldSettings& settings);

// Wall-clock time of each stage of the last World::Step, for profiling; the
// stages are the ones listed in World's private section.
struct StepProfile {
  double broad_phase_ms = 0.0;    // ms, stage 1
  double narrow_phase_ms = 0.0;   // ms, stage 2
  double contact_cache_ms = 0.0;  // ms, stage 3
  double solver_ms = 0.0;         // ms, stage 4 (collisions, forces, resting contact)
  double integrator_ms = 0.0;     // ms, stage 5
  std::size_t solver_points = 0;  // contact points handed to the solver
  int velocity_sweeps = 0;        // Gauss-Seidel sweeps of the resting solve's slowest island
  std::size_t velocity_row_updates = 0;  // row updates of those sweeps, all islands
  // Manifolds carried to the new poses (contact_reuse_distance) instead of
  // clipped, in stage 2.
  std::size_t reused_manifolds = 0;
};

class World {
 public:
  explicit World(const WorldSettings& settings = WorldSettings());

  const WorldSettings& settings() const { return settings_; }
  // Refuses invalid settings and keeps the old ones.
  Status SetSettings(const WorldSettings& settings);

  // Refuses bad input (non-finite pose or velocity, zero or non-unit
  // quaternion, bad mass properties, bad shapes) and leaves the world unchanged.
  Result<BodyId> CreateBody(const BodyDef& def);
  Status DestroyBody(BodyId id);
  bool IsValid(BodyId id) const;
  std::size_t BodyCount() const { return body_count_; }
  std::size_t AwakeBodyCount() const;

  // Pose of the body frame and the velocity of its origin, world frame.
  Pose GetPose(BodyId id) const;
  Vec3 GetLinearVelocity(BodyId id) const;
  Vec3 GetAngularVelocity(BodyId id) const;
  // Teleports the body; refuses non-finite input.
  Status SetState(BodyId id, const Pose& world_from_body, const Vec3& linear_velocity,
                  const Vec3& angular_velocity);
  const Body& GetBody(BodyId id) const;

  // Adds a force (N, world) acting at a world point (m) during the next step.
  Status ApplyForceAtPoint(BodyId id, const Vec3& force_world, const Vec3& point_world);
  // Adds a torque (N m, world) acting during the next step.
  Status ApplyTorque(BodyId id, const Vec3& torque_world);

  // Advances the world by settings().time_step.
  void Step();
  double time() const { return time_; }  // s since creation or the last Restart
  const StepProfile& last_step_profile() const { return last_step_profile_; }

  // Sets the time to 0 and forgets everything carried between steps (contact
  // caches, warm starts, sleep timers); bodies keep their state.
  void Restart();

  // Bodies whose state became non-finite in the last step (e.g. forces that
  // overflowed). They are taken out of the simulation, so no NaN reaches
  // their neighbours, until SetState gives them a finite state again.
  const std::vector<BodyId>& non_finite_bodies() const { return non_finite_bodies_; }

  // The contact points of the last step.
  const std::vector<ContactReport>& contacts() const { return contacts_; }
  // The colliding contacts of every step since the last call, so that short
  // impacts are not lost between two reads.
  std::vector<ContactReport> TakeCollisionLog();

 private:
  Body& MutableBody(BodyId id);
  void Wake(std::uint32_t body);
  // Wakes every body that touched `body` in the last step.
  void WakeTouching(std::uint32_t body);

  // The stages of Step, in order, one file each (step_*.cc).
  void UpdateBroadPhase(double dt);   // 1. broad phase: swept boxes, candidate pairs
  void UpdateNarrowPhase(double dt);  // 2. narrow phase: manifolds per shape pair
  void UpdateContactCache();          // 3. contact cache: witnesses, warm starts
  void SolveContacts(double dt);      // 4. solver: collisions, forces, resting contact
  void IntegrateBodies(double dt);    // 5. integrator: drift, time of impact, sleep
  void CollideBodies(std::uint32_t body_a, std::uint32_t body_b, double dt);
  double ContactDistance(const Body& a, const Body& b, double dt) const;
  bool ReuseManifold(const Pose& b_from_a, double reach_a, const Pose& world_from_shape_a,
                     const Pose& world_from_shape_b, ShapePairContact* entry) const;
  void AnchorManifold(const Pose& b_from_a, const Pose& world_from_shape_a,
                      const Pose& world_from_shape_b, ShapePairContact* entry) const;
  void UpdateSleep(double dt);
  bool UpdateSpeedingUp(double dt, Body* body) const;
  void DisableNonFiniteBodies();
  // `pairs` are the touching pairs, one per solver manifold.
  void SeedNewSupportLoads(const std::vector<ShapePairContact*>& pairs, double dt);
  ContactReport MakeReport(const ShapePairContact& pair, int point,
                           const std::array<Vec3, 2>& tangent, double dt) const;

  WorldSettings settings_;
  std::vector<Body> bodies_;  // slots; a destroyed body's slot is reused
  std::vector<std::uint32_t> free_slots_;
  std::size_t body_count_ = 0;
  double time_ = 0.0;
  std::uint64_t step_count_ = 0;
  SweepAndSortBroadPhase broad_phase_;
  std::vector<std::uint32_t> half_space_bodies_;  // static bodies whose one shape is a HalfSpace
  ContactCache contact_cache_;
  bool woke_since_prune_ = false;  // a sleeping body woke or was disabled since the last stage 3
  // contacts_ begins with the reports of the sleeping pairs, made when
  // their list last changed (its version is kept here).
  std::uint64_t sleeping_reports_version_ = ~std::uint64_t{0};
  std::size_t sleeping_report_count_ = 0;
  ContactSolver solver_;
  std::vector<std::uint32_t> moving_bodies_;  // awake and enabled at stage 4 of this step
  std::vector<BodyPath> paths_;               // stage 5's, per body slot (IntegrateBodies)
  std::vector<Pose> start_poses_;             // world_from_principal at the start of the step
  std::vector<ContactReport> contacts_;
  std::vector<ContactReport> collision_log_;
  std::vector<BodyId> non_finite_bodies_;
  StepProfile last_step_profile_;
};

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_WORLD_H_
