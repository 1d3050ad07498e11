// Rigid bodies from URDF models (urdfdom): links joined by fixed joints merge
// into one body made of spheres, cylinders, convex polyhedra and, on static
// models, triangle meshes.
#ifndef RIGID_BODY_SIM_IO_URDF_LOADER_H_
#define RIGID_BODY_SIM_IO_URDF_LOADER_H_

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "rigid_body_sim/io/convex_hull.h"
#include "rigid_body_sim/io/mesh_loader.h"
#include "rigid_body_sim/physics/mass_properties.h"
#include "rigid_body_sim/physics/result.h"
#include "rigid_body_sim/physics/shape.h"
#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::io {

// Limits on collision geometry: every size of a box, cylinder, sphere or
// mesh hull (m), and a shape's largest size over its smallest. Outside them
// the convex-polyhedron builder degenerates or the solver's scales part by
// more than a double can carry.
inline constexpr double kMinShapeSize = 1e-4;
inline constexpr double kMaxShapeSize = 1e4;
inline constexpr double kMaxShapeAspectRatio = 1e3;

// Builds the hull of the mesh file at a resolved local `path`, scaled per
// axis; e.g. CachedMeshHull (mesh_process.h), out of process.
using MeshHullLoader =
    std::function<physics::Result<std::shared_ptr<const physics::ConvexPolyhedron>>(
        const std::string& path, const physics::Vec3& scale, const HullOptions& hull)>;

// Reads the triangles of the mesh file at a resolved local `path`, scaled
// per axis, into a static collision mesh; e.g. CachedMeshTriangles
// (mesh_process.h), out of process.
using MeshTrianglesLoader =
    std::function<physics::Result<std::shared_ptr<const physics::CollisionMesh>>(
        const std::string& path, const physics::Vec3& scale)>;

struct UrdfLoadOptions {
  // kg/m^3: density of links without <inertial>, whose mass properties are
  // computed from their collision geometry.
  double default_density = 1000.0;
  HullOptions hull;      // for <mesh> collisions
  int max_links = 1000;  // count, >= 1: a model with more <link>s is refused
  // Bytes; a URDF or mesh file larger than this, or not a regular file
  // (/dev/zero, a FIFO), is refused before it is read.
  std::uintmax_t max_file_bytes = std::uintmax_t{256} << 20;
  // When set, mesh hulls come from it; when empty, meshes are imported and
  // hulled in this process (LoadMesh, ComputeConvexHull).
  MeshHullLoader mesh_hull_loader;
  // When set, the triangles of static meshes come from it; when empty, they
  // are imported in this process (LoadMesh).
  MeshTrianglesLoader mesh_triangles_loader;
  // The caller spawns the model static whatever its URDF says (a spawn
  // request's is_static): its meshes then keep their triangles by default,
  // as those of a model fixed to `world` do. A <gazebo reference="LINK">
  // <mesh_collision>hull</mesh_collision> (for the link, or inside
  // <collision name="NAME"> for one element) asks for the convex hull
  // instead, and `triangles` asks for the triangles, which only a static
  // model may have.
  bool spawn_static = false;
  // Maps package:// and file:// URIs of meshes to local paths. When empty,
  // ResolveFileUri is used, so package:// URIs are an error.
  UriResolver resolver;
  // Movable joints are not simulated yet. When true, revolute, continuous and
  // prismatic joints are welded at their position in `joint_positions` (rad
  // or m; 0 for joints not listed), each with a warning; when false they are
  // refused. Floating and planar joints are always refused.
  bool weld_movable_joints = false;
  // By joint name; every name must be a weldable movable joint of the model
  // and every value within the joint's limits, or the load fails.
  std::map<std::string, double> joint_positions;
};

// One collision element of the model.
struct LoadedShape {
  physics::ShapeDef shape;          // body_from_shape is in the root-link frame
  std::string link_name;            // the link the <collision> belongs to
  bool friction_from_urdf = false;  // material.friction came from <gazebo><mu1>
};

// A link merged into the body and where it sits in it.
struct LinkFrame {
  std::string link_name;
  physics::Pose root_from_link;
  double mass = 0.0;  // kg: the <inertial> mass, else from geometry at the default density
};

// A joint of the model, all of them welded into the one body.
struct JointInfo {
  std::string name;
  std::string type;  // URDF type: fixed, revolute, continuous or prismatic
  std::string parent_link;
  std::string child_link;
  double position = 0.0;  // rad or m, the welded position; 0 for fixed joints
};

// One rigid body made of all links of a URDF model joined by fixed joints.
// The body frame is the root link frame (the child of `world` for a static
// model); the centre of mass is expressed in it.
struct LoadedModel {
  std::string name;                         // <robot name>
  std::string root_link;                    // body frame
  bool is_static = false;                   // fixed to a link named `world`
  physics::Pose world_from_root;            // origin of the joint to `world`; identity if none
  physics::MassProperties mass_properties;  // root-link frame; validated unless static
  std::vector<LoadedShape> shapes;          // root-link frame
  std::vector<LinkFrame> links;             // every link of the body, root first
  std::vector<JointInfo> joints;            // every joint but the one to `world`, tree order
  std::vector<std::string> warnings;        // e.g. inertia computed from geometry
};

// Parses a URDF document. Fails, naming the element, on malformed XML,
// unsupported or (unless welded, see UrdfLoadOptions) movable joints, bad
// joint positions, invalid <inertial>, unreadable or degenerate meshes, sizes
// outside the limits above, more links than options.max_links, or a model
// without collision geometry. Relative mesh paths are
// taken relative to the working directory.
physics::Result<LoadedModel> LoadUrdfString(const std::string& xml,
                                            const UrdfLoadOptions& options = {});

// As LoadUrdfString, reading the file at `path`; relative mesh paths are
// taken relative to the directory of the URDF file.
physics::Result<LoadedModel> LoadUrdfFile(const std::string& path,
                                          const UrdfLoadOptions& options = {});

}  // namespace rigid_body_sim::io

#endif  // RIGID_BODY_SIM_IO_URDF_LOADER_H_
