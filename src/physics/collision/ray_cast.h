// Rays against the shapes of the narrow phase, exactly: the first surface a
// ray enters within its length (ray.h). A ray that starts inside a solid
// does not hit it, as Bullet's ray tests do; a static mesh's closed
// components are hit on their outer side only, its open ones on either
// side, as they collide. The hits leave RayHit::body and shape unset.
#ifndef RIGID_BODY_SIM_PHYSICS_COLLISION_RAY_CAST_H_
#define RIGID_BODY_SIM_PHYSICS_COLLISION_RAY_CAST_H_

#include <algorithm>
#include <cmath>

#include "rigid_body_sim/physics/collision_mesh.h"
#include "rigid_body_sim/physics/ray.h"
#include "rigid_body_sim/physics/shape.h"
#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::physics {

// The ray, given in the frame the shape is posed in, against one shape.
RayHit RayCastShape(const ShapeGeometry& geometry, const Pose& world_from_shape, const Ray& ray);

// Shape-frame casts, each for a ray in the shape's own frame.
RayHit RayCastSphere(double radius, const Ray& ray);
RayHit RayCastCylinder(const Cylinder& cylinder, const Ray& ray);
RayHit RayCastPolyhedron(const ConvexPolyhedron& polyhedron, const Ray& ray);
RayHit RayCastHalfSpace(const Ray& ray);
RayHit RayCastMesh(const CollisionMesh& mesh, const Ray& ray);
// The same, testing every triangle: the reference for RayCastMesh.
RayHit RayCastMeshBruteForce(const CollisionMesh& mesh, const Ray& ray);

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_COLLISION_RAY_CAST_H_
