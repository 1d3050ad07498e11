// Mesh hulls built out of process: assimp and qhull run on untrusted files in
// a helper executable (rigid_body_sim_mesh_helper) started per mesh with
// posix_spawn, under limits on address space, CPU time and input size. An
// abort, an exhausted memory limit or a timeout in the helper is an error
// message here; whatever the importer leaks or crashes on stays in the
// child. The caller's process keeps a cache by path, scale, size and
// modification time, so a repeated mesh costs no process. ROS-free.
#ifndef RIGID_BODY_SIM_IO_MESH_PROCESS_H_
#define RIGID_BODY_SIM_IO_MESH_PROCESS_H_

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "rigid_body_sim/io/convex_decomposition.h"
#include "rigid_body_sim/io/convex_hull.h"
#include "rigid_body_sim/physics/collision_mesh.h"
#include "rigid_body_sim/physics/convex_polyhedron.h"
#include "rigid_body_sim/physics/result.h"
#include "rigid_body_sim/physics/types.h"

namespace rigid_body_sim::io {

struct MeshProcessLimits {
  std::string helper_path;                                  // the helper executable
  std::uint64_t memory_bytes = std::uint64_t{1} << 30;      // RLIMIT_AS of the helper
  double cpu_seconds = 10.0;                                // RLIMIT_CPU; wall time 2x + 1 s
  std::uint64_t max_file_bytes = std::uint64_t{256} << 20;  // larger files are not opened
};

// The hull of the mesh file at `path` (a local path, already resolved),
// scaled per axis, built by the helper. Fails naming the file on a file that
// is missing, not regular or too large (checked before any process starts),
// on the helper's refusal (its message), or on its death (the signal or the
// limit it hit).
physics::Result<physics::ConvexPolyhedron> LoadMeshHullOutOfProcess(
    const std::string& path, const physics::Vec3& scale, const HullOptions& hull,
    const MeshProcessLimits& limits);

// As above, through a process-wide cache keyed by path, scale, hull options,
// file size and modification time: a cached mesh starts no process. Failures
// are not cached. Thread-safe.
physics::Result<std::shared_ptr<const physics::ConvexPolyhedron>> CachedMeshHull(
    const std::string& path, const physics::Vec3& scale, const HullOptions& hull,
    const MeshProcessLimits& limits);

// The triangles of the mesh file at `path`, scaled per axis, read by the
// helper (for static meshes that collide as their triangles); fails as
// LoadMeshHullOutOfProcess does.
physics::Result<physics::TriangleMesh> LoadMeshTrianglesOutOfProcess(
    const std::string& path, const physics::Vec3& scale, const MeshProcessLimits& limits);

// As above, built into a CollisionMesh (its tree made here), through a
// process-wide cache keyed by path, scale, file size and modification time.
// Thread-safe.
physics::Result<std::shared_ptr<const physics::CollisionMesh>> CachedMeshTriangles(
    const std::string& path, const physics::Vec3& scale, const MeshProcessLimits& limits);

// A moving mesh's convex pieces (convex_decomposition.h), decomposed by
// the helper.
struct MeshPiecesRequest {
  std::string path;  // a local path, already resolved
  physics::Vec3 scale = physics::Vec3::Ones();
  DecompositionOptions options;
  PiecesRule rule = PiecesRule::kAuto;
  // Where results are kept on disk, keyed by a hash of the file's bytes and
  // every setting above, so a mesh decomposed once (by any run) costs no
  // process again; empty: no disk cache. A cache file that cannot be read
  // or written is ignored (the helper runs); one that does not parse is
  // replaced.
  std::string cache_directory;
};
using ConvexPieceList = std::vector<physics::ConvexPolyhedron>;

// The pieces of the mesh at request.path: from the disk cache, else built
// by the helper (and then stored in the cache). Fails as
// LoadMeshHullOutOfProcess does.
physics::Result<ConvexPieceList> LoadMeshPiecesOutOfProcess(const MeshPiecesRequest& request,
                                                            const MeshProcessLimits& limits);

// As above, through a process-wide cache keyed by the request, the file's
// size and modification time. Thread-safe.
physics::Result<std::shared_ptr<const ConvexPieceList>> CachedMeshPieces(
    const MeshPiecesRequest& request, const MeshProcessLimits& limits);

// $ROS_HOME/rigid_body_sim/decomposition, else
// $HOME/.ros/rigid_body_sim/decomposition, else "" (no disk cache).
std::string DefaultDecompositionCacheDirectory();

// The helper's first argument that asks for triangles instead of a hull.
inline constexpr char kTrianglesFlag[] = "--triangles";
// The helper's first argument that asks for convex pieces.
inline constexpr char kPiecesFlag[] = "--pieces";
// The pieces reply: "pieces N" and N hull replies.
std::string FormatPiecesReply(const ConvexPieceList& pieces);
// Parses a pieces reply of 1 to kMaxPieces hulls of at most `max_vertices`
// vertices each, or returns the helper's error.
physics::Result<ConvexPieceList> ParsePiecesReply(const std::string& reply, int max_vertices);
inline constexpr int kMaxPieces = 64;

// The helper's side, shared with it and with the fuzzer: the reply that
// carries a hull through the pipe, and its parsing. The text holds
// hexadecimal floats, so the parent gets the child's doubles exactly.
std::string FormatHullReply(const physics::ConvexPolyhedron& hull);
std::string FormatErrorReply(const std::string& message);
std::string FormatTrianglesReply(const physics::TriangleMesh& mesh);
// Parses a triangles reply (counts within CollisionMesh::kMaxTriangles,
// indices in range, finite coordinates), or returns the helper's error.
physics::Result<physics::TriangleMesh> ParseTrianglesReply(const std::string& reply);
// Parses a reply of at most `max_vertices` vertices into a polyhedron
// (MakeConvexPolyhedron checks it is closed and convex), or returns the
// helper's error message as the error.
physics::Result<physics::ConvexPolyhedron> ParseHullReply(const std::string& reply,
                                                          int max_vertices);

}  // namespace rigid_body_sim::io

#endif  // RIGID_BODY_SIM_IO_MESH_PROCESS_H_
