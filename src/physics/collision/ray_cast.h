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

// A shape's pose with its rotation as a matrix, made once for the many rays
// of a batch: each ray is turned into the shape and each hit's normal out
// by a matrix product, cheaper than the quaternion's (ray_bench's 100,000
// rays, one thread: 50.4 -> 47.7 ms). The two round differently, by a few
// units in the last place.
struct ShapeFrame {
  ShapeFrame() = default;
  explicit ShapeFrame(const Pose& world_from_shape)
      : shape_from_world(world_from_shape.rotation.conjugate().toRotationMatrix()),
        translation(world_from_shape.translation) {}
  Mat3 shape_from_world = Mat3::Identity();
  Vec3 translation = Vec3::Zero();  // m, the shape's origin in the world
};

// The ray, given in the frame the shape is posed in, against one shape.
RayHit RayCastShape(const ShapeGeometry& geometry, const ShapeFrame& frame, const Ray& ray);
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
