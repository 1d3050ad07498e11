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

// The entry and exit of a ray through a box [lower, upper], as t within
// [0, max_distance]; empty when exit < entry.
struct SlabInterval {
  double entry = 0.0;
  double exit = 0.0;
};

// 1/d per axis, a zero component taken as +-1e-300: its planes then give
// t = +-1e300 (or 0 on the plane), never 0 * inf = NaN.
inline Vec3 SlabInverse(const Vec3& direction) {
  Vec3 inverse;
  for (int axis = 0; axis < 3; ++axis) {
    const double d = direction[axis];
    inverse[axis] = 1.0 / (d != 0.0 ? d : std::copysign(1e-300, d));
  }
  return inverse;
}

// Kay and Kajiya 1986, "Ray Tracing Complex Scenes", section 3 (slabs): the
// ray is inside the box for t in the intersection of the three intervals
// between the planes of each axis. `inverse_direction` is SlabInverse's.
inline SlabInterval RaySlabs(const Vec3& origin, const Vec3& inverse_direction, const Vec3& lower,
                             const Vec3& upper, double max_distance) {
  SlabInterval interval{0.0, max_distance};
  for (int axis = 0; axis < 3; ++axis) {
    const double t1 = (lower[axis] - origin[axis]) * inverse_direction[axis];
    const double t2 = (upper[axis] - origin[axis]) * inverse_direction[axis];
    interval.entry = std::max(interval.entry, std::min(t1, t2));
    interval.exit = std::min(interval.exit, std::max(t1, t2));
  }
  return interval;
}

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
