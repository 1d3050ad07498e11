// The simulated world: bodies, settings and the time step.
#ifndef RIGID_BODY_SIM_PHYSICS_WORLD_H_
#define RIGID_BODY_SIM_PHYSICS_WORLD_H_

#include <cstddef>
#include <vector>

#include "rigid_body_sim/physics/body.h"
#include "rigid_body_sim/physics/result.h"
#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::physics {

struct WorldSettings {
  Vec3 gravity = Vec3(0.0, 0.0, -9.81);  // m/s^2, world frame (REP 103: z up)
  double time_step = 1.0 / 240.0;         // s, > 0
};

Status ValidateWorldSettings(const WorldSettings& settings);

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
  double time() const { return time_; }  // s since creation

 private:
  Body& MutableBody(BodyId id);

  WorldSettings settings_;
  std::vector<Body> bodies_;       // slots; a destroyed body's slot is reused
  std::vector<std::uint32_t> free_slots_;
  std::size_t body_count_ = 0;
  double time_ = 0.0;
};

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_WORLD_H_
