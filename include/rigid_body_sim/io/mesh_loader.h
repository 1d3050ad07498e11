// Triangle meshes from mesh files (STL, OBJ, DAE, PLY) through assimp; OBJ
// and ASCII STL are read in double precision first.
#ifndef RIGID_BODY_SIM_IO_MESH_LOADER_H_
#define RIGID_BODY_SIM_IO_MESH_LOADER_H_

#include <cstdint>
#include <functional>
#include <string>

#include "rigid_body_sim/physics/mass_properties.h"
#include "rigid_body_sim/physics/result.h"
#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::io {

// Maps a resource URI (package://, file://, or a plain path) to a local file
// path. The caller supplies package:// support (e.g. from ROS), which keeps
// this library ROS-free.
using UriResolver = std::function<physics::Result<std::string>(const std::string& uri)>;

// Resolves file:// URIs and plain paths; any other scheme, package://
// included, is an error naming the URI.
physics::Result<std::string> ResolveFileUri(const std::string& uri);

// Loads every sub-mesh of a mesh file, places it with its node transforms,
// applies `scale` (per axis, dimensionless) and joins identical vertices.
// Supported: .stl (ASCII and binary), .obj, .dae, .ply. OBJ and ASCII STL
// coordinates are the nearest doubles to the file's decimals (assimp's are
// floats: 0.1 would come back 1.5e-9 off); a file of those formats that the
// double-precision reader does not know is left to assimp. A DAE file's
// <unit meter> and <up_axis> are honoured: the result is in metres with +z up.
// Triangles keep the file's orientation (corrected for a mirroring scale);
// no closedness is required.
// Fails, naming the file, when the file is missing or unreadable, its format
// is unsupported, it has no triangles, or a vertex is not finite.
// Files that are not regular (/dev/zero, a FIFO) or larger than
// `max_file_bytes` are refused before assimp opens them.
physics::Result<physics::TriangleMesh> LoadMesh(const std::string& uri,
                                                const physics::Vec3& scale = physics::Vec3::Ones(),
                                                const UriResolver& resolver = ResolveFileUri,
                                                std::uintmax_t max_file_bytes = std::uintmax_t{256}
                                                                                << 20);

}  // namespace rigid_body_sim::io

#endif  // RIGID_BODY_SIM_IO_MESH_LOADER_H_
