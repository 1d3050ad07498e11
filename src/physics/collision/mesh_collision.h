// Convex shapes (spheres, cylinders, polyhedra) against static triangle
// meshes: per-triangle contacts, internal-edge filtering, and the grouping of
// the contacts into up to StaticMesh::kContactSlots manifolds.
#ifndef RIGID_BODY_SIM_PHYSICS_COLLISION_MESH_COLLISION_H_
#define RIGID_BODY_SIM_PHYSICS_COLLISION_MESH_COLLISION_H_

#include <array>
#include <limits>
#include <vector>

#include "physics/contact/contact_manifold.h"
#include "rigid_body_sim/physics/collision_mesh.h"
#include "rigid_body_sim/physics/shape.h"
#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::physics {

struct ConvexMeshPair {
  const ShapeGeometry* convex = nullptr;  // a sphere, cylinder or polyhedron
  Pose world_from_convex = Pose::Identity();
  const CollisionMesh* mesh = nullptr;
  Pose world_from_mesh = Pose::Identity();
  double contact_distance = 0.0;  // m
  // m; the most the shapes can close within the step (the contact distance
  // less the margin): a group's support is taken from its points closer
  // than this (CollideConvexMesh).
  double reach = std::numeric_limits<double>::infinity();
};

struct MeshContacts {
  // Slot s holds the s-th group of contacts (normals within about 9 degrees
  // of each other): slot 0 the group with the deepest point, the others
  // ordered by their first triangle so that a group keeps its slot from step
  // to step; empty slots have no points. Normals from the mesh to the
  // convex shape.
  std::array<ContactManifold, StaticMesh::kContactSlots> manifolds;
  // m; with no points in any slot, a lower bound on the distance
  // (-infinity when not known).
  double gap = -std::numeric_limits<double>::infinity();
};

// The contacts of a convex shape with a static mesh, see mesh_collision.cc.
void CollideConvexMesh(const ConvexMeshPair& pair, MeshContacts* contacts);

// Only the manifold of the deepest triangle contact (any group), for
// callers that want the least separation: the time-of-impact search and the
// overlap query. False with no points; `gap` as MeshContacts::gap.
bool CollideConvexMeshDeepest(const ConvexMeshPair& pair, ContactManifold* manifold, double* gap);

// The prism of a triangle, extruded by `depth` behind its front face, as a
// polyhedron (reusing `prism`'s storage): the convex piece of the mesh's
// solid that the narrow phase tests a convex shape against.
void MakeTrianglePrism(const std::array<Vec3, 3>& front_ccw, double depth, ConvexPolyhedron* prism);

// Slot bookkeeping of bodies with static meshes. The world appends, after
// the caller's shapes, StaticMesh::kContactSlots - 1 copies of each static
// mesh shape (slots 1, 2, ...), mesh by mesh.
void AddMeshSlots(std::vector<ShapeDef>* shapes);
// The index of slot `slot` of the mesh shape at `owner` (a caller's shape).
int MeshSlotShape(const std::vector<ShapeDef>& shapes, int owner, int slot);
// The caller's index of shape `shape`: the mesh shape a slot copy belongs
// to, or `shape` itself.
int CallerShape(const std::vector<ShapeDef>& shapes, int shape);

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_COLLISION_MESH_COLLISION_H_
