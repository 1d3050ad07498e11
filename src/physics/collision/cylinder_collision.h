// Contact manifolds of an exact solid cylinder against the other shapes.
// The cylinder is its own shape, not a prism: its support function and its
// closest point are closed forms, so it rolls on its side without bumps and
// stands on its cap on a disc's worth of support.
#ifndef RIGID_BODY_SIM_PHYSICS_COLLISION_CYLINDER_COLLISION_H_
#define RIGID_BODY_SIM_PHYSICS_COLLISION_CYLINDER_COLLISION_H_

#include "physics/contact/contact_manifold.h"
#include "rigid_body_sim/physics/convex_polyhedron.h"
#include "rigid_body_sim/physics/shape.h"
#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::physics {

// The cylinder is shape A; the other shape is B. Manifold normals point
// from B to A, as everywhere in the narrow phase.
struct CylinderPair {
  const Cylinder* cylinder = nullptr;
  Pose world_from_cylinder = Pose::Identity();
  Pose world_from_other = Pose::Identity();
  double contact_distance = 0.0;  // m: points with separation below this are contacts
};

// Support point of the cylinder (shape frame, axis z) furthest along
// `direction`: (r u, h sign(d_z)) with u the unit radial part of d.
Vec3 CylinderSupport(const Cylinder& cylinder, const Vec3& direction);

// Closest point of the solid cylinder to `point` (both in the shape frame):
// the radial distance clamped to r and the height clamped to [-h, h]. A point
// inside is its own closest point.
Vec3 ClosestPointOnCylinder(const Cylinder& cylinder, const Vec3& point);

// Against the half-space z <= 0 of B.
bool CollideCylinderHalfSpace(const CylinderPair& pair, ContactManifold* manifold);

// Against a sphere centred at B's origin.
bool CollideCylinderSphere(const CylinderPair& pair, const Sphere& sphere,
                           ContactManifold* manifold);

// Against a convex polyhedron.
bool CollideCylinderPolyhedron(const CylinderPair& pair, const ConvexPolyhedron& polyhedron,
                               ContactManifold* manifold);

// Against a second cylinder, which is taken as its inscribed 64-sided prism:
// the first cylinder stays exact; the second deviates from its circle by at
// most r (1 - cos(pi / 64)) = 1.2e-3 r.
bool CollideCylinders(const CylinderPair& pair, const Cylinder& other, ContactManifold* manifold);

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_COLLISION_CYLINDER_COLLISION_H_
