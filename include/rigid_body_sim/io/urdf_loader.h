// Rigid bodies from URDF models (urdfdom): links joined by fixed joints merge
// into one body made of spheres, cylinders, convex polyhedra and, on static
// models, triangle meshes.
#ifndef RIGID_BODY_SIM_IO_URDF_LOADER_H_
#define RIGID_BODY_SIM_IO_URDF_LOADER_H_

#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "rigid_body_sim/io/convex_decomposition.h"
#include "rigid_body_sim/io/convex_hull.h"
#include "rigid_body_sim/io/gazebo_plugins.h"
#include "rigid_body_sim/io/mesh_loader.h"
#include "rigid_body_sim/physics/articulation.h"
#include "rigid_body_sim/physics/mass_properties.h"
#include "rigid_body_sim/physics/result.h"
#include "rigid_body_sim/physics/shape.h"
#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::io {

// Movable joints of one articulated model by default (~max_joints_per_model):
// a free step costs about n (the articulated-body algorithm, its parts
// capped by a budget), a constrained one about n per contact point; the
// largest chain ~max_links_per_model admits (999 joints) steps free in
// 6 ms at worst, and a 999-joint rope lying on the ground in 60 ms
// (130 ms in the steps where it lands) on the reference machine
// (docs/limits.md).
inline constexpr int kDefaultMaxJointsPerModel = 999;

// Limits on collision geometry: every size of a box, cylinder, sphere or
// mesh hull (m), and a shape's largest size over its smallest. Outside them
// the convex-polyhedron builder degenerates or the solver's scales part by
// more than a double can carry.
inline constexpr double kMinShapeSize = 1e-4;
inline constexpr double kMaxShapeSize = 1e4;
inline constexpr double kMaxShapeAspectRatio = 1e3;

// Limits on joints. The first two match the node's (request_validation.h,
// which this ROS-free library does not include): kMaxJointPosition, the
// |position| every joint request is held to (rad or m; a continuous joint
// wound further has lost its angle's precision below 1e-12 rad), and the
// default ~max_angular_speed and ~max_linear_speed (rad/s or m/s).
inline constexpr double kMaxJointPosition = 1e4;
inline constexpr double kMaxJointSpeed = 1e4;
// |<mimic multiplier>|: each mimic adds its multiplier squared to its
// leader's effort scale and joint-space inertia, so 1e3 keeps them within
// 1e6 of the leader's own. A multiplier of 0 (a joint held at its offset)
// is legal, as in urdfdom and Gazebo.
inline constexpr double kMaxMimicMultiplier = 1e3;
// <gazebo><mu1> above this (the node's bound on a spawn request's friction)
// is read as this: descriptions write 1e5 to 1e15 for "never slides", which
// 1e3 (a cone of 89.94 degrees) already is.
inline constexpr double kMaxFrictionCoefficient = 1e3;

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

// The convex pieces of the mesh file at a resolved local `path`, scaled per
// axis (ConvexPieces); e.g. CachedMeshPieces (mesh_process.h), out of
// process.
using MeshPiecesLoader =
    std::function<physics::Result<std::shared_ptr<const std::vector<physics::ConvexPolyhedron>>>(
        const std::string& path, const physics::Vec3& scale, const DecompositionOptions& options,
        PiecesRule rule)>;
// Expands a xacro description: the file at `path`, or `text` when `path` is
// empty (xacro_process.h runs the package's expander out of process).
using XacroExpander =
    std::function<physics::Result<std::string>(const std::string& path, const std::string& text)>;

struct UrdfLoadOptions {
  // kg/m^3: density of links without <inertial>, whose mass properties are
  // computed from their collision geometry.
  double default_density = 1000.0;
  // An <inertia> that is not positive definite or whose principal moments
  // miss I1 + I2 >= I3 by more than 10 % is refused by default (as MuJoCo
  // and Drake refuse it); when true it is repaired with a warning, keeping
  // its principal axes (as Gazebo and Bullet load it; see ReadInertial).
  bool balance_inertia = false;
  HullOptions hull;      // for <mesh> collisions
  int max_links = 1000;  // count, >= 1: a model with more <link>s is refused
  // count, >= 1: an articulated model with more movable joints is refused;
  // the default is the largest whose worst step stays within tens of
  // milliseconds (docs/limits.md).
  int max_joints = kDefaultMaxJointsPerModel;
  // Bytes; a URDF or mesh file larger than this, or not a regular file
  // (/dev/zero, a FIFO), is refused before it is read.
  std::uintmax_t max_file_bytes = std::uintmax_t{256} << 20;
  // When set, mesh hulls come from it; when empty, meshes are imported and
  // hulled in this process (LoadMesh, ComputeConvexHull).
  MeshHullLoader mesh_hull_loader;
  // When set, the triangles of static meshes come from it; when empty, they
  // are imported in this process (LoadMesh).
  MeshTrianglesLoader mesh_triangles_loader;
  // A moving model's meshes: by default a closed mesh whose volume is below
  // decomposition.convex_ratio of its hull's collides as convex pieces,
  // others as their hull; <mesh_collision>decomposition asks for pieces,
  // `hull` for the hull. The pieces come from mesh_pieces_loader when set,
  // else are built in this process.
  DecompositionOptions decomposition;
  MeshPiecesLoader mesh_pieces_loader;
  // A description that is xacro (LooksLikeXacro) is expanded by it first;
  // without one it is refused, saying so.
  XacroExpander xacro_expander;
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
  // Revolute, continuous and prismatic joints: simulated (LoadedModel's
  // `articulated`, see MakeArticulationDef) when `articulate` is true;
  // otherwise welded at their position in `joint_positions` (rad or m; 0
  // for joints not listed), each with a warning, when `weld_movable_joints`
  // is true; otherwise refused. Floating and planar joints between links are
  // always refused.
  bool articulate = false;
  bool weld_movable_joints = false;
  // By joint name, the initial position of each movable joint (0 when not
  // listed, brought within the joint's limits); every name must be a
  // movable joint of the model that mimics none, and every value within the
  // joint's limits and within kMaxJointPosition, or the load fails. A mimic
  // joint starts at multiplier * its leader's initial position + offset.
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
  physics::Pose root_from_link;  // with every movable joint at its initial position
  double mass = 0.0;  // kg: the <inertial> mass, else from geometry at the default density
  physics::MassProperties mass_in_link;  // link frame; mass 0 for a massless link
};

// A joint of the model, as URDF states it.
struct JointInfo {
  std::string name;
  std::string type;  // URDF type: fixed, revolute, continuous or prismatic
  std::string parent_link;
  std::string child_link;
  double position = 0.0;  // rad or m, the initial (or welded) position; 0 for fixed joints
  physics::Pose parent_from_joint;                          // <origin>, parent link frame
  physics::Vec3 axis = physics::Vec3::UnitX();              // unit, joint frame
  double lower = -std::numeric_limits<double>::infinity();  // rad or m
  double upper = std::numeric_limits<double>::infinity();
  double effort = std::numeric_limits<double>::infinity();    // N m or N
  double velocity = std::numeric_limits<double>::infinity();  // rad/s or m/s
  double damping = 0.0;                                       // <dynamics damping>
  double friction = 0.0;                                      // <dynamics friction>
  std::string mimic_joint;                                    // <mimic joint>, or empty
  double mimic_multiplier = 1.0;
  double mimic_offset = 0.0;
};

// One rigid body made of all links of a URDF model joined by fixed joints.
// The body frame is the root link frame (the child of `world` for a static
// model); the centre of mass is expressed in it.
struct LoadedModel {
  std::string name;                         // <robot name>
  std::string root_link;                    // body frame
  bool is_static = false;                   // fixed to a link named `world`
  physics::Pose world_from_root;            // origin of the joint to `world`; identity if none
  bool world_link = false;                  // the URDF's root is a link named `world`
  physics::MassProperties mass_properties;  // root-link frame; validated unless static
  std::vector<LoadedShape> shapes;          // root-link frame
  std::vector<LinkFrame> links;             // every link of the body, root first
  std::vector<JointInfo> joints;            // every joint but the one to `world`, tree order
  // Movable joints are simulated (UrdfLoadOptions::articulate and at least
  // one movable joint): the model becomes an articulation.
  bool articulated = false;
  std::vector<std::string> warnings;  // e.g. inertia computed from geometry
  // The sensors and ROS plugins of its <gazebo> elements that the node
  // runs (ReadGazeboPlugins), their links and joints checked.
  GazeboPlugins plugins;
  // What the description asks for that is not simulated, one entry each:
  // <transmission> elements and the <gazebo> plugins and sensors that
  // `plugins` does not hold (IgnoredElements, then plugins.ignored).
  std::vector<std::string> ignored;
};

// Parses a URDF document. Fails, naming the element, on malformed XML,
// unsupported or (unless welded, see UrdfLoadOptions) movable joints, bad
// joint positions, invalid <inertial>, unreadable or degenerate meshes, sizes
// or other numbers outside the limits above (or their own, urdf_checks.h),
// mimic joints that would move beyond kMaxJointPosition or kMaxJointSpeed,
// more links than options.max_links, or a model without collision geometry.
// Relative mesh paths are taken relative to the working directory.
physics::Result<LoadedModel> LoadUrdfString(const std::string& xml,
                                            const UrdfLoadOptions& options = {});

// The articulation of an articulated model: one link per group of URDF
// links joined by fixed joints (its frame the group's first link), one
// joint per movable joint, in tree order. A group without mass gets 1 g
// (a warning in `warnings`). Shapes, materials and user data are the
// caller's to adjust.
physics::Result<physics::ArticulationDef> MakeArticulationDef(const LoadedModel& model,
                                                              std::vector<std::string>* warnings);

// As LoadUrdfString, reading the file at `path`; relative mesh paths are
// taken relative to the directory of the URDF file.
physics::Result<LoadedModel> LoadUrdfFile(const std::string& path,
                                          const UrdfLoadOptions& options = {});

}  // namespace rigid_body_sim::io

#endif  // RIGID_BODY_SIM_IO_URDF_LOADER_H_
