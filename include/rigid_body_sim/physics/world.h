// The simulated world: bodies, settings and the time step. Its step runs
// five stages (docs/design.md): broad phase, narrow phase, contact cache,
// contact solver and integrator.
#ifndef RIGID_BODY_SIM_PHYSICS_WORLD_H_
#define RIGID_BODY_SIM_PHYSICS_WORLD_H_

#include <cstddef>
#include <memory>
#include <vector>

#include "rigid_body_sim/physics/articulation.h"
#include "rigid_body_sim/physics/body.h"
#include "rigid_body_sim/physics/contact.h"
#include "rigid_body_sim/physics/ray.h"
#include "rigid_body_sim/physics/result.h"
#include "rigid_body_sim/physics/types.h"
#include "rigid_body_sim/physics/world_settings.h"

namespace rigid_body_sim::physics {

class WorldImpl;

class World {
 public:
  explicit World(const WorldSettings& settings = WorldSettings());
  ~World();
  World(World&&) noexcept;
  World& operator=(World&&) noexcept;
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  const WorldSettings& settings() const;
  // Refuses invalid settings and keeps the old ones.
  Status SetSettings(const WorldSettings& settings);

  // Refuses bad input (non-finite pose or velocity, zero or non-unit
  // quaternion, bad mass properties, bad shapes) and leaves the world unchanged.
  Result<BodyId> CreateBody(const BodyDef& def);
  Status DestroyBody(BodyId id);
  bool IsValid(BodyId id) const;
  std::size_t BodyCount() const;
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
  // The enabled bodies that `id` interpenetrates now, deepest first, each by
  // its deepest point (an invalid id has none). The step separates such
  // bodies by moving their positions only (the split impulse), so spawning
  // into an overlap gives no launch speed.
  std::vector<BodyOverlap> FindOverlaps(BodyId id) const;

  // Casts each ray against the shapes of every enabled body but those in
  // `ignore`: its first hit within its length (ray.h), through a tree of
  // the shapes' boxes, on the world's threads for large batches. Refused
  // whole, naming the ray, for a non-finite origin, a direction not of unit
  // length, a max_distance below 0 or NaN, or more than kMaxRaysPerCast
  // rays.
  Result<std::vector<RayHit>> CastRays(const std::vector<Ray>& rays,
                                       const std::vector<BodyId>& ignore = {}) const;
  double time() const;  // s since creation or the last Restart
  const StepProfile& last_step_profile() const;

  // Sets the time to 0 and forgets everything carried between steps (contact
  // caches, warm starts, sleep timers); bodies keep their state.
  void Restart();

  // Bodies frozen in the last step, each listed once: a state that became
  // non-finite (e.g. forces that overflowed), or a position, velocity or
  // pending force beyond 1e100 in SI units, where a step's products could
  // overflow. A frozen body is held at its last finite pose with zero
  // velocity, out of the simulation (no contacts), so no NaN reaches its
  // neighbours, until SetState gives it a state again.
  const std::vector<BodyId>& non_finite_bodies() const;

  // Articulations (articulation.h). Creating one validates the whole
  // definition and creates one body per link (links[i] is the i-th id of
  // ArticulationLinks); a refused one leaves the world unchanged. A link's
  // body is read like any other; SetState on it moves the whole
  // articulation rigidly (its joints stop), forces on it act through the
  // joints, and DestroyBody refuses it.
  Result<ArticulationId> CreateArticulation(const ArticulationDef& def);
  Status DestroyArticulation(ArticulationId id);
  bool IsValid(ArticulationId id) const;
  std::vector<BodyId> ArticulationLinks(ArticulationId id) const;
  // Per joint, in the definition's order.
  std::vector<JointState> GetJointStates(ArticulationId id) const;
  // Positions and velocities of every joint (mimic joints' are ignored);
  // refuses non-finite values and positions outside the limits.
  Status SetJointStates(ArticulationId id, const std::vector<double>& positions,
                        const std::vector<double>& velocities);
  Status SetJointCommand(ArticulationId id, int joint, const JointCommand& command);
  Status SetServoGains(ArticulationId id, const ServoGains& gains);

  // The contact points of the last step. They are written by the first
  // call after the step, so a step whose reports nobody reads does not
  // write them; that call, though const, must not race another call.
  const std::vector<ContactReport>& contacts() const;
  // The colliding contacts of every step since the last call, so that short
  // impacts are not lost between two reads.
  std::vector<ContactReport> TakeCollisionLog();

 private:
  std::unique_ptr<WorldImpl> impl_;
};

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_WORLD_H_
