// Wavefront OBJ and ASCII STL read in double precision. Assimp stores
// coordinates as float, so a vertex written as 0.12345678 comes back 1e-9
// relative off; a static mesh (a terrain, a room) whose ray casts and
// contacts are checked against the file's own numbers needs them as written.
#ifndef RIGID_BODY_SIM_IO_TEXT_MESH_READER_H_
#define RIGID_BODY_SIM_IO_TEXT_MESH_READER_H_

#include <optional>
#include <string>

#include "rigid_body_sim/physics/mass_properties.h"

namespace rigid_body_sim::io {

// The triangles of an OBJ file's faces (convex polygons as fans from their
// first corner, points and lines dropped) over the vertices they use, in
// file order; nullopt when the text is not an OBJ this reader knows, or has
// a concave face (then assimp reads it). Faces index with 1-based or negative (relative) numbers,
// with or without /vt/vn parts; other statements are ignored.
std::optional<physics::TriangleMesh> ReadObjText(const std::string& text);

// The facets of an ASCII STL file ("solid ... facet ... outer loop, three
// vertex lines ... endsolid"), nullopt when it is not one (a binary STL may
// also begin with "solid").
std::optional<physics::TriangleMesh> ReadAsciiStlText(const std::string& text);

}  // namespace rigid_body_sim::io

#endif  // RIGID_BODY_SIM_IO_TEXT_MESH_READER_H_
