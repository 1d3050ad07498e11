// A shape's pose in the world, composed from its body's frames without the
// factors that are the identity.
#ifndef RIGID_BODY_SIM_PHYSICS_DYNAMICS_BODY_FRAMES_H_
#define RIGID_BODY_SIM_PHYSICS_DYNAMICS_BODY_FRAMES_H_

#include "rigid_body_sim/physics/body.h"
#include "rigid_body_sim/physics/shape.h"
#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::physics {

// Whether `pose` is exactly the identity, with no tolerance.
inline bool IsIdentity(const Pose& pose) {
  return pose.translation.x() == 0.0 && pose.translation.y() == 0.0 &&
         pose.translation.z() == 0.0 && pose.rotation.w() == 1.0 && pose.rotation.x() == 0.0 &&
         pose.rotation.y() == 0.0 && pose.rotation.z() == 0.0;
}

// a b, or a itself when b is exactly the identity. The product would give a's
// values again: each component adds zeros to a's own, so only the sign of a
// zero component could differ, and no later operation reads it (the
// determinism hashes are the same either way). A box or a sphere has both
// its principal frame and its shape frame at its body frame, and the narrow
// phase composes them for every pair it tests.
inline Pose ComposeUnlessIdentity(const Pose& a, const Pose& b) {
  return IsIdentity(b) ? a : a * b;
}

// world_from_shape = world_from_principal principal_from_body body_from_shape,
// composed in that order, as Body::WorldFromBody() * body_from_shape is.
inline Pose WorldFromShape(const Body& body, const ShapeDef& shape) {
  return ComposeUnlessIdentity(
      ComposeUnlessIdentity(body.WorldFromPrincipal(), body.principal_from_body),
      shape.body_from_shape);
}

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_DYNAMICS_BODY_FRAMES_H_
