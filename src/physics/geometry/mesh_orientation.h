// Consistent winding of a static mesh's connected components, found once
// when the mesh is built (CollisionMesh::Make): mesh files of tables,
// shelves and floors often hold faces wound the wrong way.
#ifndef RIGID_BODY_SIM_PHYSICS_GEOMETRY_MESH_ORIENTATION_H_
#define RIGID_BODY_SIM_PHYSICS_GEOMETRY_MESH_ORIENTATION_H_

#include <array>
#include <cstdint>
#include <vector>

#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::physics {

struct MeshOrientation {
  // Per triangle: 1 when its winding is to be reversed.
  std::vector<std::uint8_t> flip;
  // Per triangle: 1 when its component is open, i.e. some edge of the
  // component is not shared by exactly two of the component's triangles (a
  // sheet, a terrain, a table top of one layer).
  std::vector<std::uint8_t> open;
  int components = 0;
};

// The windings that make each connected component (triangles joined across
// edges of exactly two triangles) consistent: a closed component with its
// normals outward, an open one wound as the larger part of its area was.
// `triangles` index `vertices` (every index valid) and have non-zero area.
MeshOrientation OrientComponents(const std::vector<Vec3>& vertices,
                                 const std::vector<std::array<int, 3>>& triangles);

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_GEOMETRY_MESH_ORIENTATION_H_
