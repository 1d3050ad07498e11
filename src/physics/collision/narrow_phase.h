// Narrow phase: contact manifolds between two collision shapes.
#ifndef RIGID_BODY_SIM_PHYSICS_COLLISION_NARROW_PHASE_H_
#define RIGID_BODY_SIM_PHYSICS_COLLISION_NARROW_PHASE_H_

#include "physics/collision/cylinder_collision.h"
#include "physics/collision/polyhedron_collision.h"
#include "physics/contact/contact_manifold.h"
#include "rigid_body_sim/physics/shape.h"
#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::physics {

struct CollideInput {
  const ShapeGeometry* a = nullptr;
  Pose world_from_a = Pose::Identity();
  const ShapeGeometry* b = nullptr;
  Pose world_from_b = Pose::Identity();
  double contact_distance = 0.0;  // m: points with separation below this are contacts
};

// Contact manifold between shapes a and b, normal from b to a. Returns false
// with manifold->point_count = 0 when they are separated by at least
// contact_distance. `witness` is the per-pair cache of the separating or
// contact-defining feature, owned by the caller (may be null; only used for
// polyhedron pairs); `stats` (may be null) reports whether it was used.
// Two half-spaces or static meshes never collide (both are static); such a
// pair is a programmer error. A static mesh gives the manifold of its slot;
// called without `stats`, only its deepest contact, in slot 0.
bool Collide(const CollideInput& input, SeparatingWitness* witness, ContactManifold* manifold,
             CollideStats* stats = nullptr);

// The shapes' gap, m: the least separation of their manifold's points, or
// contact_distance when they are apart by at least that much (what the
// time-of-impact searches bracket).
double Gap(const CollideInput& input);

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_COLLISION_NARROW_PHASE_H_
