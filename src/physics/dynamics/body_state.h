// Setting a body's state from a pose and a twist, and checking them first.
#ifndef RIGID_BODY_SIM_PHYSICS_DYNAMICS_BODY_STATE_H_
#define RIGID_BODY_SIM_PHYSICS_DYNAMICS_BODY_STATE_H_

#include <string>

#include "rigid_body_sim/physics/body.h"
#include "rigid_body_sim/physics/result.h"
#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::physics {

// "[x, y, z]", for error messages.
std::string FormatVector(const Vec3& v);

// Refuses a non-finite pose or velocity, or a quaternion not of unit length.
Status ValidateState(const Pose& world_from_body, const Vec3& linear_velocity,
                     const Vec3& angular_velocity);

// Sets a body's state (x, q, P, L) from the pose of its body frame and the
// twist of that frame's origin, and restarts its sleep and step records.
void SetBodyState(const Pose& world_from_body, const Vec3& linear_velocity,
                  const Vec3& angular_velocity, Body* body);

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_DYNAMICS_BODY_STATE_H_
