// The implementation behind World (world.h), which forwards every call here,
// so that the public header shows none of the stages' state. It orders the
// stages and owns the bodies; stages 1 and 2 are collision_'s
// (collision/collision_system.h), the articulations' part is
// articulations_'s. Its methods are defined in world_impl.cc (bodies and
// state) and in the files of the stages it runs itself (step_*.cc).
#ifndef RIGID_BODY_SIM_PHYSICS_WORLD_WORLD_IMPL_H_
#define RIGID_BODY_SIM_PHYSICS_WORLD_WORLD_IMPL_H_

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "physics/articulation/articulation_system.h"
#include "physics/collision/collision_system.h"
#include "physics/contact/contact_cache.h"
#include "physics/dynamics/integrator.h"
#include "physics/dynamics/sleep_system.h"
#include "physics/solver/contact_reports.h"
#include "physics/solver/contact_solver.h"
#include "physics/solver/motion_solver.h"
#include "physics/world/step_context.h"
#include "physics/world/task_pool.h"
#include "rigid_body_sim/physics/articulation.h"
#include "rigid_body_sim/physics/body.h"
#include "rigid_body_sim/physics/contact.h"
#include "rigid_body_sim/physics/ray.h"
#include "rigid_body_sim/physics/result.h"
#include "rigid_body_sim/physics/types.h"
#include "rigid_body_sim/physics/world_settings.h"

namespace rigid_body_sim::physics {

// The public methods do what World's of the same name are documented to do.
class WorldImpl final : public LinkBodies {
 public:
  explicit WorldImpl(const WorldSettings& settings);

  const WorldSettings& settings() const { return settings_; }
  Status SetSettings(const WorldSettings& settings);
  Result<BodyId> CreateBody(const BodyDef& def) override;
  Status DestroyBody(BodyId id) override;
  bool IsValid(BodyId id) const;
  std::size_t BodyCount() const { return body_count_; }
  std::size_t AwakeBodyCount() const;
  Pose GetPose(BodyId id) const;
  Vec3 GetLinearVelocity(BodyId id) const;
  Vec3 GetAngularVelocity(BodyId id) const;
  Status SetState(BodyId id, const Pose& world_from_body, const Vec3& linear_velocity,
                  const Vec3& angular_velocity);
  const Body& GetBody(BodyId id) const;
  Status ApplyForceAtPoint(BodyId id, const Vec3& force_world, const Vec3& point_world);
  Status ApplyTorque(BodyId id, const Vec3& torque_world);
  void Step();
  std::vector<BodyOverlap> FindOverlaps(BodyId id) const;  // world_queries.cc
  Result<std::vector<RayHit>> CastRays(
      const std::vector<Ray>& rays,
      const std::vector<BodyId>& ignore) const;  // world_ray_cast.cc
  double time() const { return time_; }
  const StepProfile& last_step_profile() const { return last_step_profile_; }
  void Restart();
  const std::vector<BodyId>& non_finite_bodies() const { return non_finite_bodies_; }
  // The last step's reports, written first if they are not yet
  // (solver/contact_reports.h).
  const std::vector<ContactReport>& contacts() { return reports_.contacts(pool_.get()); }
  // Writes the reports the step left to be written when read: before a call
  // changes the pairs or the bodies' slots they are made of.
  void FlushReports() { reports_.Flush(pool_.get()); }
  std::vector<ContactReport> TakeCollisionLog() { return reports_.TakeCollisionLog(); }

  // Articulations (articulation/articulation_system.h).
  Result<ArticulationId> CreateArticulation(const ArticulationDef& def) {
    return articulations_.Create(def);
  }
  Status DestroyArticulation(ArticulationId id) { return articulations_.Destroy(id); }
  bool IsValid(ArticulationId id) const { return articulations_.IsValid(id); }
  std::vector<BodyId> ArticulationLinks(ArticulationId id) const {
    return articulations_.Links(id);
  }
  std::vector<JointState> GetJointStates(ArticulationId id) const {
    return articulations_.GetJointStates(id);
  }
  Status SetJointStates(ArticulationId id, const std::vector<double>& positions,
                        const std::vector<double>& velocities) {
    return articulations_.SetJointStates(id, positions, velocities);
  }
  Status SetJointCommand(ArticulationId id, int joint, const JointCommand& command) {
    return articulations_.SetJointCommand(id, joint, command);
  }
  Status SetServoGains(ArticulationId id, const ServoGains& gains) {
    return articulations_.SetServoGains(id, gains);
  }

 private:
  friend class ExactSolver;     // runs stages 4 and 5 (solver/exact_solver.h)
  friend class SoftStepSolver;  // likewise, with its own sub-steps

  Body& MutableBody(BodyId id);
  // LinkBodies, for the articulation system.
  BodyId BodyIdOf(std::uint32_t index) const override;
  void RestartContacts(std::uint32_t body) override;
  void Wake(std::uint32_t body);
  // Wakes every body that touched `body` in the last step.
  void WakeTouching(std::uint32_t body);

  // The stages of Step, in order: 1 and 2 are collision_'s
  // (collision/collision_system.h), 3 is here (contact/step_contact_cache.cc).
  void UpdateContactCache();  // 3. contact cache: pruned, touching pairs listed
  // 4 and 5, from velocities to poses, are motion_solver_'s (solver/).
  // The awake, enabled bodies that are not links into moving_bodies_.
  void ListMovingBodies();
  // Whether ListMovingBodies lists `body`: the solve moves it this step.
  static bool MovesThisStep(const Body& body) {
    return body.in_use && !body.is_static && body.awake && !body.disabled && body.articulation < 0;
  }
  // Stage 5's end, both solvers' (step_guard.cc): bodies whose state is
  // not finite are disabled.
  void DisableNonFiniteBodies();
  void DisableBody(std::uint32_t index);
  // The step guard (step_guard.cc), around stages 1-5: bodies whose state
  // or pending force would overflow a step are frozen before it, bodies
  // whose state is not finite after it go back to their pose at its start.
  void GuardBeforeStep(const StepContext& step);
  void GuardAfterStep();
  void FreezeBody(std::uint32_t index, const Pose& world_from_principal);

  WorldSettings settings_;
  std::unique_ptr<TaskPool> pool_;               // settings_.threads threads
  std::unique_ptr<MotionSolver> motion_solver_;  // settings_.motion_solver
  std::vector<Body> bodies_;                     // slots; a destroyed body's slot is reused
  std::vector<std::uint32_t> free_slots_;
  std::size_t body_count_ = 0;
  double time_ = 0.0;
  ContactCache contact_cache_;
  bool woke_since_prune_ = false;  // a sleeping body woke or was disabled since the last stage 3
  ContactSolver solver_;
  ContactReports reports_{{&bodies_, &solver_, &contact_cache_, &settings_}};
  std::vector<std::uint32_t> moving_bodies_;  // awake and enabled at stage 4 of this step
  // UpdateContactCache's scratch: per touching pair, whether a body sleeps.
  std::vector<std::uint8_t> has_sleeper_;
  std::vector<BodyId> non_finite_bodies_;
  std::vector<Pose> guard_start_poses_;     // world_from_principal at the guard's start, per slot
  std::vector<std::uint8_t> guard_failed_;  // the guards' scratch, per slot
  std::vector<std::uint8_t> non_finite_;    // DisableNonFiniteBodies', per moving body
  static constexpr std::size_t kBodiesPerGuardChunk = 256;
  StepProfile last_step_profile_;
  std::vector<ShapePairContact*> rigid_pairs_;  // the touching pairs without a link
  ArticulationSystem articulations_{&bodies_, this};
  CollisionSystem collision_{{&bodies_, &contact_cache_, &settings_, &articulations_}};
  SleepSystem sleep_{{&bodies_, &contact_cache_, &settings_, &articulations_}};
};

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_WORLD_WORLD_IMPL_H_
