// How a URDF <mesh> collides: the <gazebo reference="LINK"> extension
// <mesh_collision>triangles|hull|decomposition</mesh_collision>, for every mesh of the
// link or, inside <collision name="NAME">, for one collision element.
#ifndef RIGID_BODY_SIM_IO_MESH_COLLISION_MODES_H_
#define RIGID_BODY_SIM_IO_MESH_COLLISION_MODES_H_

#include <map>
#include <string>
#include <utility>

#include <tinyxml.h>

#include "rigid_body_sim/physics/result.h"

namespace rigid_body_sim::io {

enum class MeshCollision {
  kDefault,        // triangles on a static model; on a moving one the convex
                   // hull, or convex pieces when the mesh is clearly concave
  kTriangles,      // the triangles themselves (static models only)
  kHull,           // the convex hull
  kDecomposition,  // convex pieces (a closed mesh)
};

// Keyed by (link, collision name); the empty collision name is the link's.
using MeshCollisionModes = std::map<std::pair<std::string, std::string>, MeshCollision>;

// Reads every <mesh_collision> of the <gazebo reference> elements. Fails,
// naming the element, on an empty or unknown value or a <collision> without
// a name.
physics::Result<MeshCollisionModes> ReadMeshCollisionModes(const TiXmlElement& robot);

// The mode of one collision element: its own, else its link's, else kDefault.
MeshCollision ModeOf(const MeshCollisionModes& modes, const std::string& link,
                     const std::string& collision);

}  // namespace rigid_body_sim::io

#endif  // RIGID_BODY_SIM_IO_MESH_COLLISION_MODES_H_
