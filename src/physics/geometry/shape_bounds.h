// Bounds of shapes: world boxes for the broad phase, and the sizes that
// limit how far a body may move between two collision checks.
#ifndef RIGID_BODY_SIM_PHYSICS_GEOMETRY_SHAPE_BOUNDS_H_
#define RIGID_BODY_SIM_PHYSICS_GEOMETRY_SHAPE_BOUNDS_H_

#include <array>

#include "physics/geometry/aabb.h"
#include "rigid_body_sim/physics/shape.h"
#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::physics {

// World box of a sphere, cylinder, polyhedron or static mesh (not a half-space,
// which is unbounded). A polyhedron's support climbs start from
// `support_seeds` (Body::box_support) when given, and leave their answers
// there; from its axis_support vertices otherwise.
Aabb ShapeAabb(const ShapeGeometry& geometry, const Pose& world_from_shape,
               std::array<int, 6>* support_seeds = nullptr);

// Smallest width of the shape over all directions (m): 2r for a sphere; for a
// polyhedron the smallest extent along a face normal, which is the minimum
// width of a convex polyhedron; infinite for a half-space or static mesh, whose
// bodies never move.
double ShapeThickness(const ShapeGeometry& geometry);

// Largest distance (m) of a point of the shape from `center_shape`.
double ShapeBoundingRadius(const ShapeGeometry& geometry, const Vec3& center_shape);

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_GEOMETRY_SHAPE_BOUNDS_H_
