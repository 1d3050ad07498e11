// Collision shapes attached to bodies.
#ifndef RIGID_BODY_SIM_PHYSICS_SHAPE_H_
#define RIGID_BODY_SIM_PHYSICS_SHAPE_H_

#include <memory>
#include <variant>

#include "rigid_body_sim/physics/collision_mesh.h"
#include "rigid_body_sim/physics/convex_polyhedron.h"
#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::physics {

struct Sphere {
  double radius = 0.0;  // m
};

// The half-space z <= 0 of the shape frame; only static bodies may carry it.
struct HalfSpace {};

// A solid cylinder around the shape frame's z axis, centred at its origin
// (URDF's convention), exact in the narrow phase.
struct Cylinder {
  double radius = 0.0;       // m
  double half_length = 0.0;  // m, half the length along z
};

// A triangle mesh that collides as its triangles (concave environments);
// only static bodies may carry it. A convex shape touching it gets up to
// kContactSlots manifolds, one per group of contacts with similar normals
// (the floor and two walls of a bin corner): the world gives the body one
// hidden copy of the shape per extra slot, after the caller's shapes, so
// each slot has a contact-cache entry of its own. Callers leave `slot` 0.
struct StaticMesh {
  static constexpr int kContactSlots = 4;
  std::shared_ptr<const CollisionMesh> mesh;
  int slot = 0;
};

// Polyhedra are immutable and shared, so many bodies can use one hull. The
// order of the alternatives is the narrow phase's dispatch order.
using ShapeGeometry =
    std::variant<Sphere, std::shared_ptr<const ConvexPolyhedron>, HalfSpace, Cylinder, StaticMesh>;

struct Material {
  double friction = 0.5;     // Coulomb coefficient mu, dimensionless, >= 0
  double restitution = 0.0;  // coefficient of restitution e, in [0, 1]
};

struct ShapeDef {
  ShapeGeometry geometry = Sphere{};
  Pose body_from_shape = Pose::Identity();
  Material material;
};

// Checks a shape definition: finite pose, positive radius and length, non-empty polyhedron,
// a mesh with slot 0, material in range.
Status ValidateShapeDef(const ShapeDef& shape);

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_SHAPE_H_
